"""A calibration: everything needed to turn one device's raw I and Q into a Hologram.

Applying it inverts the receiver model (:mod:`.faults`) step by step::

    I, Q  -> I - dc_i, Q - dc_q                       (DC offset, per element)
          -> z = I + i*(Q/g - I*sin(phi))/cos(phi)     (I/Q imbalance, per frequency)
          -> conj(z) if the device delivers I - iQ     (I/Q sign)
          -> z / (response[f] * gain[f, iy, ix])       (frequencies equalised, elements)
          -> 0 on dead and noisy elements              (mask)

A calibration belongs to one device (its identity string, e.g. a serial number),
one array (element coordinates) and one set of frequencies; frames from any other
are refused. It is saved to a file of its own (:meth:`Calibration.save`, NetCDF-4)
and applied by name: ``apply(raw, "device-cal.nc")``.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._validate import as_axis
from ..data.hologram import Hologram, frequency_axis
from ..io.netcdf import source_to_json
from ._format import read_file, write_file
from .iq import correct_iq
from .raw import RawFrames, check_device

__all__ = ["SIGNS", "Calibration", "apply"]

SIGNS = ("I+iQ", "I-iQ")
COORD_ATOL = 1e-9
"""Element coordinates of frames and calibration must agree to this, metres."""
FREQ_RTOL = 1e-9
"""Frequencies of frames and calibration must agree to this fraction."""


def _array(values: Any, name: str, shape: tuple[int, ...], *, kind: type = float,
           broadcast: bool = False) -> np.ndarray:
    try:
        arr = np.array(values, dtype=kind)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numbers of shape {shape}") from None
    if arr.shape != shape:
        if broadcast and (arr.ndim == 0 or arr.shape == shape[1:]):
            arr = np.broadcast_to(arr, shape).copy()
        else:
            raise ValueError(f"{name} must have shape {shape}, got {arr.shape}")
    if kind is not bool and not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite")
    arr.setflags(write=False)
    return arr


def _canonical(a: np.ndarray) -> bytes:
    if a.dtype == bool:
        return np.ascontiguousarray(a, dtype=np.uint8).tobytes()
    if np.iscomplexobj(a):
        return np.ascontiguousarray(a, dtype="<c16").tobytes()
    return np.ascontiguousarray(a, dtype="<f8").tobytes()


@dataclass(frozen=True, eq=False)
class Calibration:
    """One device's calibration (module text); every array is read-only.

    Parameters
    ----------
    device : str
        The device's identity (serial number).
    x, y : array_like
        Element coordinates, metres.
    frequency : float or array_like of shape (nf,)
        Hz (as in :class:`holoradar.Hologram`).
    dc_i, dc_q : array_like, shape (nf, ny, nx)
        Offsets of the raw I and Q channels, device units ((ny, nx): the same at
        every frequency; one number: the same everywhere).
    iq_gain, iq_phase : float or array_like of shape (nf,)
        The Q channel's gain relative to I and its phase error (radians), as
        delivered (:mod:`.iq`).
    iq_sign : {"I+iQ", "I-iQ"}
        ``"I-iQ"``: the device delivers the conjugate.
    response : array_like, complex, shape (nf,)
        The frequencies' common complex response (:mod:`.equalize`).
    gains : array_like, complex, shape (nf, ny, nx)
        Each element's complex gain relative to ``response`` (:mod:`.gains`);
        (ny, nx): the same at every frequency.
    dead, noisy : array_like of bool, shape (ny, nx)
        Flagged elements (:mod:`.mask`); default none.
    source : PointSource, PlaneWave or GaussianBeam, optional
        The horn during the reference measurement (given to calibrated holograms
        whose frames name none).
    provenance : dict, optional
        How it was made (references, dates, versions, accuracies): JSON values.

    Examples
    --------
    >>> x = (np.arange(2) - 0.5) * 0.025
    >>> cal = Calibration("HSR-7", x, x, 9.9e9, iq_gain=1.0, iq_phase=0.0, iq_sign="I-iQ",
    ...                   response=[2.0], gains=np.ones((2, 2)))
    >>> raw = RawFrames(np.ones((2, 2)), np.ones((2, 2)), x, x, 9.9e9, "HSR-7")
    >>> cal.apply(raw).data[0, 0]
    np.complex128(0.5-0.5j)
    """

    device: str
    x: np.ndarray
    y: np.ndarray
    frequency: float | np.ndarray
    dc_i: np.ndarray
    dc_q: np.ndarray
    iq_gain: np.ndarray
    iq_phase: np.ndarray
    iq_sign: str
    response: np.ndarray
    gains: np.ndarray
    dead: np.ndarray
    noisy: np.ndarray
    source: Any
    provenance: dict[str, Any]

    def __init__(self, device: str, x: Any, y: Any, frequency: Any, *, iq_sign: str,
                 response: Any, gains: Any, dc_i: Any = 0.0, dc_q: Any = 0.0,
                 iq_gain: Any = 1.0, iq_phase: Any = 0.0, dead: Any = None,
                 noisy: Any = None, source: Any = None,
                 provenance: dict[str, Any] | None = None) -> None:
        xa, ya = as_axis(x, "x"), as_axis(y, "y")
        xa.setflags(write=False)
        ya.setflags(write=False)
        ny, nx = ya.size, xa.size
        nf = int(np.size(frequency))
        f = frequency_axis(frequency, (nf, ny, nx))
        grid, per_f = (nf, ny, nx), (nf,)
        put = object.__setattr__
        put(self, "device", check_device(device))
        put(self, "x", xa)
        put(self, "y", ya)
        put(self, "frequency", f)
        for name, v in (("dc_i", dc_i), ("dc_q", dc_q)):
            put(self, name, _array(v, name, grid, broadcast=True))
        g = _array(iq_gain, "iq_gain", per_f, broadcast=True)
        if np.any(g <= 0):
            raise ValueError("iq_gain must be > 0 (the Q channel's gain relative to I)")
        p = _array(iq_phase, "iq_phase", per_f, broadcast=True)
        if np.any(np.abs(p) >= np.pi / 2):
            raise ValueError("iq_phase must lie within (-pi/2, pi/2) radians")
        put(self, "iq_gain", g)
        put(self, "iq_phase", p)
        if iq_sign not in SIGNS:
            raise ValueError(f"iq_sign must be one of {SIGNS}, got {iq_sign!r}")
        put(self, "iq_sign", str(iq_sign))
        r = _array(response, "response", per_f, kind=complex, broadcast=True)
        if np.any(r == 0):
            raise ValueError("response must be non-zero at every frequency")
        put(self, "response", r)
        put(self, "gains", _array(gains, "gains", grid, kind=complex, broadcast=True))
        flags = []
        for name, v in (("dead", dead), ("noisy", noisy)):
            if v is not None and np.asarray(v).dtype != bool:
                raise ValueError(f"{name} must be a boolean array (True = flagged), got dtype "
                                 f"{np.asarray(v).dtype}")
            flag = np.zeros((ny, nx), bool) if v is None else _array(v, name, (ny, nx),
                                                                      kind=bool)
            flag.setflags(write=False)
            flags.append(flag)
        put(self, "dead", flags[0])
        put(self, "noisy", flags[1])
        mask = flags[0] | flags[1]
        if mask.all():
            raise ValueError("every element is flagged dead or noisy: nothing to calibrate")
        if np.any((self.gains == 0) & ~mask):
            raise ValueError("gains must be non-zero on every element that is not flagged")
        if source is not None:
            source_to_json(source)  # refuses what cannot be saved
        put(self, "source", source)
        prov = dict(provenance or {})
        try:
            json.dumps(prov, sort_keys=True, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"provenance must hold JSON values (str, numbers, lists, dicts): "
                             f"{exc}") from None
        put(self, "provenance", prov)

    # --- what it is -----------------------------------------------------------------
    @property
    def frequencies(self) -> np.ndarray:
        """The frequencies, Hz, 1-D."""
        return np.atleast_1d(np.asarray(self.frequency, dtype=float))

    @property
    def is_wideband(self) -> bool:
        """True when ``frequency`` is an axis (frames (..., nf, ny, nx))."""
        return isinstance(self.frequency, np.ndarray)

    @property
    def shape(self) -> tuple[int, int]:
        """``(ny, nx)``: the array's shape."""
        return self.y.size, self.x.size

    @property
    def mask(self) -> np.ndarray:
        """True on dead or noisy elements (set to 0 by :meth:`apply`), shape (ny, nx)."""
        return self.dead | self.noisy

    @property
    def total_gain(self) -> np.ndarray:
        """``response[f] * gains[f, iy, ix]``: what :meth:`apply` divides by, (nf, ny, nx)."""
        return self.response[:, None, None] * self.gains

    @property
    def checksum(self) -> str:
        """SHA-256 (hex) of the calibration's content: its identity, kept in its file."""
        h = hashlib.sha256()
        for text in (self.device, self.iq_sign, source_to_json(self.source) or "",
                     json.dumps(self.provenance, sort_keys=True)):
            h.update(text.encode())
            h.update(b"\0")
        for a in (self.x, self.y, self.frequencies, self.dc_i, self.dc_q, self.iq_gain,
                  self.iq_phase, self.response, self.gains, self.dead, self.noisy):
            h.update(_canonical(a))
        return h.hexdigest()

    def history_step(self) -> dict[str, Any]:
        """A processing step naming this calibration, for :func:`holoradar.save`'s history.

        Examples
        --------
        >>> x = np.arange(2) * 0.025
        >>> cal = Calibration("HSR-7", x, x, 9.9e9, iq_sign="I+iQ", response=[1.0],
        ...                   gains=np.ones((2, 2)))
        >>> sorted(cal.history_step()["parameters"])
        ['calibration_sha256', 'device', 'flagged_elements', 'iq_sign']
        """
        return {"step": "calibrate",
                "parameters": {"device": self.device, "calibration_sha256": self.checksum,
                               "iq_sign": self.iq_sign,
                               "flagged_elements": int(self.mask.sum())}}

    # --- using it ------------------------------------------------------------------
    def check(self, raw: RawFrames) -> None:
        """Raise ``ValueError`` unless ``raw`` comes from this device, array and frequencies."""
        if not isinstance(raw, RawFrames):
            raise ValueError(f"raw must be holoradar.calibrate.RawFrames, got "
                             f"{type(raw).__name__}")
        if raw.device != self.device:
            raise ValueError(f"this calibration is for device {self.device!r}; the frames come "
                             f"from device {raw.device!r}: refusing to apply another device's "
                             "calibration")
        if raw.element_shape != self.shape:
            raise ValueError(f"this calibration is for a {self.shape[0]} x {self.shape[1]} "
                             f"array (ny x nx) of device {self.device!r}; the frames have "
                             f"{raw.element_shape[0]} x {raw.element_shape[1]} elements")
        for name, a, b in (("x", raw.x, self.x), ("y", raw.y, self.y)):
            if not np.allclose(a, b, rtol=0, atol=COORD_ATOL):
                raise ValueError(f"the frames' element coordinates {name} differ from the "
                                 f"calibration's (largest difference "
                                 f"{np.abs(a - b).max():.3g} m): another array layout")
        fr, fc = raw.frequencies, self.frequencies
        if (raw.is_wideband != self.is_wideband or fr.shape != fc.shape
                or not np.allclose(fr, fc, rtol=FREQ_RTOL, atol=0)):
            raise ValueError(f"this calibration holds the frequencies "
                             f"{np.round(fc / 1e9, 6).tolist()} GHz; the frames have "
                             f"{np.round(fr / 1e9, 6).tolist()} GHz: calibrate at the "
                             "frames' frequencies")

    def apply(self, raw: RawFrames) -> Hologram:
        """The calibrated Hologram of raw frames (module text); flagged elements are 0.

        Parameters
        ----------
        raw : RawFrames
            Frames of this device at this calibration's frequencies.

        Returns
        -------
        Hologram
            Same leading axes as the frames, the field in the reference model's
            units; ``source`` the frames' (or this calibration's), ``pose`` the
            frames'.

        Raises
        ------
        ValueError
            Frames of another device, array shape, layout or frequencies.
        """
        self.check(raw)
        nf = self.frequencies.size
        lead = raw.i.shape[:raw.i.ndim - len(raw.core_shape)]
        shape = (*lead, nf, *self.shape)
        i = raw.i.reshape(shape) - self.dc_i
        q = raw.q.reshape(shape) - self.dc_q
        z = correct_iq(i, q, self.iq_gain[:, None, None], self.iq_phase[:, None, None])
        if self.iq_sign == "I-iQ":
            z = np.conj(z)
        mask = self.mask
        total = np.where(mask, 1.0, self.total_gain)
        data = np.where(mask, 0.0, z / total).reshape(raw.i.shape)
        return Hologram(data, raw.x, raw.y, raw.frequency,
                        source=raw.source if raw.source is not None else self.source,
                        pose=None if raw.pose.is_identity else raw.pose)

    # --- its file ------------------------------------------------------------------
    def save(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
        """Write this calibration to its own NetCDF-4 file (``.nc``).

        An existing file is refused unless ``overwrite=True``; the folder and
        suffix are checked first; the file is written atomically with the user's
        umask. Layout: :mod:`holoradar.calibrate.store`.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> x = np.arange(2) * 0.025
        >>> cal = Calibration("HSR-7", x, x, 9.9e9, iq_sign="I+iQ", response=[1.0],
        ...                   gains=np.ones((2, 2)))
        >>> p = cal.save(pathlib.Path(tempfile.mkdtemp()) / "HSR-7.nc")
        >>> Calibration.load(p).checksum == cal.checksum
        True
        """
        return write_file(self, path, overwrite=overwrite)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Calibration:
        """Read a calibration file written by :meth:`save`.

        Raises
        ------
        ValueError
            Missing, empty, damaged (checksum) or foreign file; nothing is
            unpickled or evaluated.
        """
        return read_file(Calibration, path)


def apply(raw: RawFrames, calibration: Calibration | str | os.PathLike[str]) -> Hologram:
    """Calibrate raw frames with a calibration, or with the calibration file of that name.

    Parameters
    ----------
    raw : RawFrames
    calibration : Calibration or path
        A :class:`Calibration` or the path of its file.

    Returns
    -------
    Hologram

    Raises
    ------
    ValueError
        The file is not a calibration, or it belongs to another device, array or
        set of frequencies (the message names both).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> x = np.arange(2) * 0.025
    >>> cal = Calibration("HSR-7", x, x, 9.9e9, iq_sign="I+iQ", response=[2.0],
    ...                   gains=np.ones((2, 2)))
    >>> p = cal.save(pathlib.Path(tempfile.mkdtemp()) / "HSR-7.nc")
    >>> raw = RawFrames(np.ones((3, 2, 2)), np.zeros((3, 2, 2)), x, x, 9.9e9, "HSR-7")
    >>> apply(raw, p).data[:, 0, 0]
    array([0.5+0.j, 0.5+0.j, 0.5+0.j])
    >>> apply(RawFrames(np.ones((2, 2)), np.ones((2, 2)), x, x, 9.9e9, "HSR-8"), p)
    Traceback (most recent call last):
    ...
    ValueError: this calibration is for device 'HSR-7'; the frames come from device ...
    """
    cal = calibration if isinstance(calibration, Calibration) else Calibration.load(calibration)
    return cal.apply(raw)
