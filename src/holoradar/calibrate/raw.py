"""Raw frames: the real I and Q numbers a receiver array delivers, with its identity.

Shapes follow :class:`holoradar.Hologram`: ``i[..., iy, ix]`` (one frequency) or
``i[..., f, iy, ix]`` (several), leading axes being frames (repeats of one scene,
or the frames of a survey). The numbers are in the device's own units (ADC
counts, volts): nothing is calibrated yet.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validate import as_axis
from ..data.band import Band
from ..data.hologram import frequency_axis
from ..data.pose import IDENTITY, Pose

__all__ = ["RawFrames"]


def _real_array(values: Any, name: str) -> np.ndarray:
    arr = np.array(values)  # a copy: the frames own their numbers
    if not (np.issubdtype(arr.dtype, np.integer) or np.issubdtype(arr.dtype, np.floating)):
        raise ValueError(f"{name} must hold real numbers (the raw {name.upper()} channel), got "
                         f"dtype {arr.dtype}")
    arr = arr.astype(np.float64)
    if arr.ndim < 2:
        raise ValueError(f"{name} must have at least 2 dimensions (..., ny, nx), got shape "
                         f"{arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite: it contains NaN or inf values")
    arr.setflags(write=False)
    return arr


def check_device(device: Any) -> str:
    """The device identity as a non-empty, printable string (e.g. a serial number)."""
    if not isinstance(device, str) or not device.strip() or not device.isprintable():
        raise ValueError(f"device must be a non-empty printable string naming the device "
                         f"(e.g. its serial number), got {device!r}")
    return device


@dataclass(frozen=True, eq=False)
class RawFrames(Band):
    """Raw I and Q of a receiver array, before any calibration.

    Parameters
    ----------
    i, q : array_like, real, shape (..., ny, nx) or (..., nf, ny, nx)
        The in-phase and quadrature channels of every element, device units.
        Leading axes are frames (repeats, or a survey's frames).
    x, y : array_like
        Element coordinates, metres, strictly increasing (``x[ix]``, ``y[iy]``).
    frequency : float or array_like of shape (nf,)
        Hz; an axis of nf strictly increasing frequencies for wideband frames
        (``i.shape[-3] == nf``).
    device : str
        The identity of the device that recorded them (serial number): a
        calibration is applied only to frames of its own device.
    source : PlaneWave, PointSource or GaussianBeam, optional
        The illumination of these frames (passed on to the calibrated
        :class:`holoradar.Hologram`; default: the calibration's reference source).
    pose : Pose, optional
        Where the array stood (passed on to the Hologram).

    Examples
    --------
    >>> x = (np.arange(4) - 1.5) * 0.025
    >>> raw = RawFrames(np.zeros((8, 4, 4)), np.ones((8, 4, 4)), x, x, 9.9e9, "HSR-0001")
    >>> raw.element_shape, raw.n_frames, raw.is_wideband
    ((4, 4), 8, False)
    """

    i: np.ndarray
    q: np.ndarray
    x: np.ndarray
    y: np.ndarray
    frequency: float | np.ndarray
    device: str
    source: Any = None
    pose: Pose = IDENTITY

    def __init__(self, i: Any, q: Any, x: Any, y: Any, frequency: Any, device: str, *,
                 source: Any = None, pose: Pose | None = None) -> None:
        ia, qa = _real_array(i, "i"), _real_array(q, "q")
        if ia.shape != qa.shape:
            raise ValueError(f"i and q must have one shape, got {ia.shape} and {qa.shape}")
        xa = as_axis(x, "x", length=ia.shape[-1])
        ya = as_axis(y, "y", length=ia.shape[-2])
        f = frequency_axis(frequency, ia.shape)
        if source is not None and not (hasattr(source, "field") and hasattr(source, "reflected")):
            raise ValueError("source must be a PlaneWave, PointSource, GaussianBeam or None, got "
                             f"{type(source).__name__}")
        if pose is not None and not isinstance(pose, Pose):
            raise ValueError(f"pose must be a holoradar.Pose or None, got {type(pose).__name__}")
        for a in (xa, ya):
            a.setflags(write=False)
        object.__setattr__(self, "i", ia)
        object.__setattr__(self, "q", qa)
        object.__setattr__(self, "x", xa)
        object.__setattr__(self, "y", ya)
        object.__setattr__(self, "frequency", f)
        object.__setattr__(self, "device", check_device(device))
        object.__setattr__(self, "source", source)
        object.__setattr__(self, "pose", IDENTITY if pose is None else pose)

    @property
    def element_shape(self) -> tuple[int, int]:
        """``(ny, nx)``: the array's shape."""
        return self.i.shape[-2], self.i.shape[-1]

    @property
    def core_shape(self) -> tuple[int, ...]:
        """``(nf, ny, nx)`` for wideband frames, ``(ny, nx)`` otherwise."""
        return self.i.shape[-3:] if self.is_wideband else self.i.shape[-2:]

    @property
    def n_frames(self) -> int:
        """Number of frames (product of the leading axes; 1 if there are none)."""
        return int(np.prod(self.i.shape[:self.i.ndim - len(self.core_shape)], dtype=int))

    def stacked(self) -> tuple[np.ndarray, np.ndarray]:
        """``(i, q)`` with the leading axes flattened into one: ``(n_frames, nf, ny, nx)``.

        A single-frequency device gets ``nf = 1``.
        """
        shape = (self.n_frames, self.frequencies.size, *self.element_shape)
        return self.i.reshape(shape), self.q.reshape(shape)
