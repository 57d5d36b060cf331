"""GPR vendors' files through impdar: a line of time-domain traces as a line scan.

impdar (on PyPI) reads the formats of the ground-penetrating radar vendors: GSSI
``.DZT``, Sensors & Software ``.DT1`` (with its ``.HD``), MALA ``.RD3``/``.RAD`` and
SEG-Y. Each file is one line of traces; its traces become the line scan's frequency
samples (:meth:`holoradar.Hologram.from_traces`: the band the antenna radiates, the
sign of ``exp(-i omega t)``), its positions the header's distance along the line
(impdar's ``dist``, km) or, where the header has none, the trace spacing given as
``pitch`` (metres). impdar is GPL-3: it is the extra ``holoradar[gpr]``
(``pip install "holoradar[gpr]"``), imported only when such a file is read.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Any

import numpy as np

from ..data.hologram import Hologram

__all__ = ["GPR_SUFFIXES", "read_gpr"]

#: File suffixes (lower case) read through impdar, and impdar's name of the format.
GPR_SUFFIXES = {".dzt": "gssi", ".dt1": "pe", ".rd3": "ramac", ".rad": "ramac",
                ".sgy": "segy", ".segy": "segy"}


def read_gpr(path: str | Path, *, pitch: float | None = None,
             band: tuple[float, float] | None = None, time_zero: float = 0.0) -> Hologram:
    """A GPR vendor's line of traces as a line scan.

    Parameters
    ----------
    path : str or path-like
        A ``.DZT``, ``.DT1``, ``.RD3``/``.RAD`` or SEG-Y file (:data:`GPR_SUFFIXES`).
    pitch : float, optional
        The trace spacing, metres, where the header has no distance along the line
        (it wins over the header's when given).
    band : (float, float), optional
        ``(f_min, f_max)`` in Hz; default the antenna's (within 10 dB of the traces'
        spectral peak).
    time_zero : float
        When the pulse leaves the antenna, seconds from the first sample.

    Returns
    -------
    Hologram
        A line scan (a transceiver's), one row, over the band's frequencies.

    Raises
    ------
    ValueError
        Not a GPR file impdar reads (its message, with the file's name), no positions
        (give ``pitch``), or a bad band or time zero.

    Examples
    --------
    >>> sorted(set(GPR_SUFFIXES.values()))
    ['gssi', 'pe', 'ramac', 'segy']
    """
    src = Path(path)
    kind = GPR_SUFFIXES.get(src.suffix.lower())
    if kind is None:
        raise ValueError(f"{src.name}: not a GPR file holoradar reads (suffixes "
                         f"{', '.join(sorted(GPR_SUFFIXES))})")
    try:
        from impdar.lib.load import load as impdar_load
    except ImportError:  # GPL-3: an extra of holoradar's, not a dependency
        raise ValueError(f"{src.name}: reading GPR files needs impdar: pip install "
                         "'holoradar[gpr]' (or pip install impdar segyio)") from None
    try:
        # impdar prints as it reads: kept off the user's terminal
        with contextlib.redirect_stdout(io.StringIO()):
            data = impdar_load(kind, [str(src)])[0]
    except Exception as exc:  # impdar's own errors name no file: ours does
        raise ValueError(f"{src.name}: impdar cannot read it as {kind} "
                         f"({type(exc).__name__}: {exc})") from exc
    traces = np.asarray(data.data)
    x = _positions(data, traces.shape[1], pitch, src.name)
    try:
        return Hologram.from_traces(traces, float(data.dt), x, band=band,
                                    time_zero=time_zero)
    except ValueError as exc:
        raise ValueError(f"{src.name}: {exc}") from None


def _positions(data: Any, n: int, pitch: float | None, what: str) -> np.ndarray:
    """The traces' positions along the line, metres, from 0."""
    if pitch is not None:
        if not (np.isfinite(pitch) and pitch > 0):
            raise ValueError(f"{what}: pitch must be the trace spacing in metres (> 0), got "
                             f"{pitch!r}")
        return np.arange(n) * float(pitch)
    dist = getattr(data, "dist", None)
    if dist is not None:
        d = np.asarray(dist, dtype=float).ravel() * 1000.0   # impdar keeps km
        if d.size == n and np.all(np.isfinite(d)) and np.all(np.diff(d) > 0):
            return d - d[0]
    raise ValueError(f"{what}: its header holds no distance along the line (or one that "
                     "does not increase trace by trace): give the trace spacing, "
                     "layout pitch=... (metres, or in the layout's units)")
