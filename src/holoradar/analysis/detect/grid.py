"""The image as a (nz, ny, nx) volume with checked coordinates, and sub-pixel peaks."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Volume", "as_volume", "refine_peak"]


@dataclass(frozen=True)
class Volume:
    """Complex image data (nz, ny, nx) with uniform x, y (metres) and ranges z."""

    data: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    frequency: Any
    planar: bool
    method: str = ""       # the image's ``method`` (":ground": a tilted array's ground frame)

    @property
    def dx(self) -> float:
        return float(self.x[1] - self.x[0]) if self.x.size > 1 else np.inf

    @property
    def dy(self) -> float:
        return float(self.y[1] - self.y[0]) if self.y.size > 1 else np.inf

    def coords(self, iz: float, iy: float, ix: float) -> tuple[float, float, float]:
        """Metres at fractional indices (range interpolated between planes)."""
        z = float(np.interp(iz, np.arange(self.z.size), self.z))
        return (float(self.x[0] + ix * self.dx), float(self.y[0] + iy * self.dy), z)


def _uniform(a: np.ndarray, name: str) -> None:
    if a.ndim != 1 or a.size < 2 or not np.all(np.isfinite(a)):
        raise ValueError(f"image.{name} must be a 1-D array of at least 2 finite coordinates "
                         f"(metres), got {a!r}")
    d = np.diff(a)
    if np.any(d <= 0) or np.ptp(d) > 1e-6 * abs(d[0]):
        raise ValueError(f"image.{name} must be uniformly spaced and increasing (metres)")


def as_volume(image: Any) -> Volume:
    """Check an :class:`~holoradar.Image` (or anything with ``data``, ``x``, ``y``, ``z``)
    and return its data as a (nz, ny, nx) volume.

    Raises
    ------
    ValueError
        Missing or non-uniform coordinates, or leading frame axes in ``data``.

    Examples
    --------
    >>> import holoradar as hr
    >>> img = hr.Image(np.zeros((3, 4)), np.arange(4.0) / 100, np.arange(3.0) / 100,
    ...                np.array([0.3]), 9.9e9, has_z_axis=False)
    >>> as_volume(img).data.shape
    (1, 3, 4)
    """
    missing = [a for a in ("data", "x", "y", "z") if getattr(image, a, None) is None]
    if missing:
        raise ValueError("image must be a holoradar.Image with coordinates (data, x, y, z in "
                         f"metres); {', '.join(missing)} missing")
    data = np.asarray(image.data)
    if not np.iscomplexobj(data) and not np.issubdtype(data.dtype, np.floating):
        raise ValueError("image.data must be a complex (or real) array")
    x = np.asarray(image.x, float)
    y = np.asarray(image.y, float)
    z = np.atleast_1d(np.asarray(image.z, float))
    _uniform(x, "x")
    if y.size != 1:   # one y: a line scan's x-z section
        _uniform(y, "y")
    has_z = bool(getattr(image, "has_z_axis", data.ndim >= 3))
    vol = data[None] if not has_z else data
    if vol.ndim != 3 or vol.shape != (z.size, y.size, x.size):
        raise ValueError("image.data must have shape (ny, nx) for one plane or (nz, ny, nx) for "
                         f"a volume matching x, y, z; got {data.shape} for nz={z.size}, "
                         f"ny={y.size}, nx={x.size} (select one frame or frequency first)")
    if not np.all(np.isfinite(vol)):
        raise ValueError("image.data must be finite")
    if z.size > 1 and np.any(np.diff(z) <= 0):
        raise ValueError("image.z must be increasing (metres)")
    return Volume(vol.astype(complex), x, y, z, getattr(image, "frequency", None), not has_z,
                  str(getattr(image, "method", "") or ""))


def refine_peak(p: np.ndarray, index: tuple[int, int, int]) -> tuple[np.ndarray, float]:
    """Sub-pixel maximum of a positive volume ``p`` (nz, ny, nx) near ``index``.

    A parabola through the logarithm of the three samples along each axis (exact
    for a Gaussian peak; near a band-limited maximum sampled at several pixels per
    cell its error is a small fraction of a pixel).

    Returns
    -------
    position : ndarray, shape (3,)
        Fractional (iz, iy, ix).
    value : float
        The interpolated maximum of ``p``.

    Examples
    --------
    >>> g = np.exp(-((np.arange(9) - 4.3) ** 2))[None, None, :] * np.ones((1, 1, 1))
    >>> pos, v = refine_peak(g, (0, 0, 4))
    >>> round(float(pos[2]), 6), round(v, 6)
    (4.3, 1.0)
    """
    pos = np.array(index, float)
    logv = np.log(max(float(p[index]), 1e-300))
    total = logv
    for ax in range(3):
        i = index[ax]
        if i == 0 or i == p.shape[ax] - 1:
            continue
        lo = list(index)
        hi = list(index)
        lo[ax] -= 1
        hi[ax] += 1
        a = np.log(max(float(p[tuple(lo)]), 1e-300))
        b = np.log(max(float(p[tuple(hi)]), 1e-300))
        curv = a - 2 * logv + b
        if curv >= 0:
            continue
        d = 0.5 * (a - b) / curv
        d = float(np.clip(d, -0.5, 0.5))
        pos[ax] += d
        total += -0.25 * (a - b) * d   # the parabola's rise at its vertex
    return pos, float(np.exp(total))
