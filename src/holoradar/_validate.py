"""Argument checks shared by the public API.

Every check raises ``ValueError`` naming the argument and the expected form, so
that a user sees at once which input is wrong and what it should have been.
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from collections.abc import Sequence

import numpy as np

__all__ = [
    "AliasingWarning",
    "as_axis",
    "as_complex_scalar",
    "as_finite_complex",
    "as_position",
    "as_real",
    "check_frequency",
    "check_nonnegative_ranges",
    "uniform_step",
]


class AliasingWarning(UserWarning):
    """The element pitch exceeds half a wavelength: steep waves alias."""


def check_frequency(frequency: float, name: str = "frequency") -> float:
    """Return ``frequency`` as a float after checking it is finite and > 0 (Hz)."""
    try:
        f = float(frequency)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive number in Hz, got {frequency!r}") from None
    if not np.isfinite(f) or f <= 0:
        raise ValueError(f"{name} must be a positive finite number in Hz, got {frequency!r}")
    return f


def as_finite_complex(data: object, name: str, *, min_ndim: int = 0) -> np.ndarray:
    """Return a complex copy-free view of ``data``, refusing NaN and inf."""
    arr = np.asarray(data)
    if not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool):
        raise ValueError(f"{name} must be a numeric array, got dtype {arr.dtype}")
    if arr.ndim < min_ndim:
        raise ValueError(f"{name} must have at least {min_ndim} dimensions, got shape {arr.shape}")
    finite = np.isfinite(arr)
    if not np.all(finite):
        bad = np.argwhere(~finite)
        raise ValueError(f"{name} must be finite: {bad.shape[0]} of {arr.size} values are NaN "
                         f"or inf, the first at index {tuple(int(i) for i in bad[0])}")
    if not np.iscomplexobj(arr):
        arr = arr.astype(np.complex128)
    return arr


def as_axis(values: object, name: str, *, length: int | None = None) -> np.ndarray:
    """Return a strictly increasing, finite 1-D float axis (metres)."""
    try:
        arr = np.array(values, dtype=float)  # a copy: the caller's array stays theirs
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a 1-D sequence of coordinates in metres") from None
    if arr.ndim != 1 or arr.size < 1:
        raise ValueError(f"{name} must be a 1-D sequence of coordinates in metres, got shape "
                         f"{arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite coordinates in metres")
    if length is not None and arr.size != length:
        raise ValueError(f"{name} must have {length} values to match the data, got {arr.size}")
    if arr.size > 1 and np.any(np.diff(arr) <= 0):
        raise ValueError(f"{name} must be strictly increasing (sort the samples by it; a "
                         "hologram reverses an axis written from its high end with its data)")
    return arr


def uniform_step(axis: np.ndarray, name: str, *, rtol: float = 1e-6) -> float:
    """Return the step of a uniform axis, or raise if it is not uniform.

    A single-sample axis has no step; it is reported as ``nan`` and callers
    that need a step must refuse it.
    """
    if axis.size < 2:
        raise ValueError(f"{name} must hold at least 2 uniformly spaced samples, got {axis.size}")
    d = np.diff(axis)
    step = float(np.mean(d))
    if np.max(np.abs(d - step)) > rtol * abs(step):
        raise ValueError(f"{name} must be uniformly spaced for FFT propagation; its steps range "
                         f"from {d.min():.6g} to {d.max():.6g} m")
    return step


def check_nonnegative_ranges(z: object, name: str = "z") -> np.ndarray:
    """Return ranges ``z`` (metres, from the aperture) as a 1-D float array, refusing z < 0."""
    if type(z) is float and 0.0 <= z < math.inf:   # one plane: the common call, fast
        return np.array([z])
    arr = np.atleast_1d(np.asarray(z, dtype=float))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"{name} must be a range in metres or a 1-D sequence of them")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite ranges in metres")
    if np.any(arr < 0):
        raise ValueError(f"{name} must be >= 0 (range from the aperture plane towards the scene, "
                         f"metres); got min {arr.min():.6g}")
    return arr


def as_position(position: Sequence[float] | np.ndarray, name: str = "position") -> np.ndarray:
    """Return an (x, y, z) position in metres as a float array of shape (3,)."""
    try:
        arr = np.array(position, dtype=float)  # a copy, read-only below
    except (TypeError, ValueError):
        arr = np.empty(0)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be three finite coordinates (x, y, z) in metres, got "
                         f"{position!r}")
    arr.setflags(write=False)
    return arr


def as_complex_scalar(value: object, name: str) -> complex:
    """Return a finite complex number, or raise naming the argument."""
    try:
        c = complex(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite complex number, got {value!r}") from None
    if not (np.isfinite(c.real) and np.isfinite(c.imag)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return c


def as_real(value: object, name: str, *, positive: bool = False,
            nonnegative: bool = False) -> float:
    """Return a finite float (optionally > 0 or >= 0), or raise naming the argument."""
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if positive and v <= 0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    if nonnegative and v < 0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return v


_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def outside_stacklevel() -> int:
    """The ``stacklevel`` that attributes a warning, issued by the function calling this
    one, to the first caller outside holoradar (the user's line, however deep inside
    the package the warning arises)."""
    frame = sys._getframe(1)
    level = 1
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame = frame.f_back
        level += 1
    return level


def warn_if_aliased(pitch: float, wavelength: float, what: str = "aperture", *,
                    round_trip: bool = False) -> None:
    """Warn (and go on) when a sampling pitch exceeds half a wavelength (a quarter for a
    transceiver's round trip, which doubles the transverse wavenumbers)."""
    div = 4 if round_trip else 2
    if pitch > wavelength / div * (1 + 1e-9):
        theta = np.degrees(np.arcsin(min(1.0, wavelength / (div * pitch))))
        label = "lambda/4 (a transceiver's round trip)" if round_trip else "lambda/2"
        warnings.warn(f"{what} pitch {pitch * 100:.3g} cm exceeds {label} = "
                      f"{wavelength * 100 / div:.3g} cm: waves arriving more than {theta:.1f} "
                      f"degrees off axis alias", AliasingWarning,
                      stacklevel=outside_stacklevel())


def as_polarization(value: object, name: str = "polarization") -> np.ndarray | None:
    """A field direction: a real 3-vector (x, y, z), normalised to unit length; None stays None.

    Examples
    --------
    >>> as_polarization((0, 2, 0)).tolist()
    [0.0, 1.0, 0.0]
    >>> as_polarization((0, 0, 0))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: polarization must be a non-zero direction (x, y, z) ...
    """
    if value is None:
        return None
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        arr = np.empty(0)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be a real unit vector (x, y, z) in the scene's axes, e.g. "
                         f"(0, 1, 0) for a field along y, got {value!r}")
    nrm = float(np.linalg.norm(arr))
    if nrm == 0:
        raise ValueError(f"{name} must be a non-zero direction (x, y, z) of the field "
                         f"component, got {value!r}")
    arr = arr / nrm
    arr.setflags(write=False)
    return arr
