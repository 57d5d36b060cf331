"""Calibration files: NetCDF-4 (xarray + h5netcdf), readable by any NetCDF tool.

Layout:

* dimensions ``frequency`` (nf), ``y``, ``x`` and ``iq`` (2: index 0 the real
  part or the I channel, index 1 the imaginary part or the Q channel);
* coordinates ``x``, ``y`` (element coordinates, ``units = "m"``), ``frequency``
  (Hz, always 1-D; the attribute ``wideband`` says whether it is an axis);
* variables ``dc`` (frequency, y, x, iq: the I and Q channels' offsets, device
  units), ``iq_gain`` and ``iq_phase`` (frequency; radians), ``response``
  (frequency, iq: complex), ``element_gain`` (frequency, y, x, iq: complex),
  ``dead`` and ``noisy`` (y, x; 1 = flagged), all float64 or int8;
* attributes ``holoradar_kind = "Calibration"``, ``holoradar_calibration_format``,
  ``holoradar_version``, ``device``, ``iq_sign``, ``wideband``, ``source`` (JSON),
  ``provenance`` (JSON: the references, dates, accuracies) and ``sha256``, the
  :attr:`Calibration.checksum` of the content, verified on reading: a damaged
  file is refused rather than read as a slightly different calibration.

Reading parses numbers and JSON only: nothing is unpickled or evaluated.

The codec itself is in ``_format``, which does not import :class:`Calibration`:
:meth:`Calibration.save` and :meth:`Calibration.load` call it directly, and this
module (which imports :mod:`.calibration`, never the other way round) keeps the
functions named after the class.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from . import _format
from ._format import FORMAT
from ._format import SUFFIXES as SUFFIXES
from ._format import to_dataset as to_dataset
from .calibration import Calibration

__all__ = ["FORMAT", "read_calibration", "write_calibration"]


def from_dataset(ds: Any, what: str) -> Calibration:
    """Rebuild the :class:`Calibration` that :func:`to_dataset` stored, checking everything."""
    return _format.from_dataset(Calibration, ds, what)


def write_calibration(cal: Calibration, path: str | os.PathLike[str], *,
                      overwrite: bool = False) -> Path:
    """Write ``cal`` to ``path`` (see :meth:`Calibration.save`)."""
    if not isinstance(cal, Calibration):
        raise ValueError(f"cal must be a Calibration, got {type(cal).__name__}")
    return _format.write_file(cal, path, overwrite=overwrite)


def read_calibration(path: str | os.PathLike[str]) -> Calibration:
    """Read a calibration file (see :meth:`Calibration.load`)."""
    return _format.read_file(Calibration, path)
