"""Hologram and Image: complex fields with their coordinates attached.

Sample positions: ``data[..., iy, ix]`` is the field at ``(x[ix], y[iy])`` in
metres on the aperture plane z = 0 (element centres). An array of n elements at
pitch s covers the full width ``A = n*s`` (each element stands for one pitch),
so the paper's 16 x 16 array at 2.5 cm spans A = B = 40 cm.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .._validate import as_axis, as_finite_complex, check_frequency, uniform_step

__all__ = ["C0", "Hologram", "Image"]

C0 = 299_792_458.0
"""Speed of light in vacuum, m/s."""


@dataclass(frozen=True, eq=False)
class Hologram:
    """A complex field sampled on the aperture plane.

    Parameters
    ----------
    data : array_like, complex, shape (..., ny, nx)
        Field (the I + iQ of each element). Leading axes are frames (views,
        frequencies, time) processed together.
    x : array_like, shape (nx,)
        Element x coordinates, metres, strictly increasing.
    y : array_like, shape (ny,)
        Element y coordinates, metres, strictly increasing.
    frequency : float
        Frequency in Hz (> 0).
    source : PlaneWave, PointSource or GaussianBeam, optional
        The illumination that produced the hologram (needed by multi-view
        synthesis and glare suppression).

    Examples
    --------
    >>> import numpy as np
    >>> x = (np.arange(16) - 7.5) * 0.025
    >>> h = Hologram(np.zeros((16, 16), complex), x, x, 9.9e9)
    >>> round(h.aperture_size[0], 3), round(h.wavelength, 5)
    (0.4, 0.03028)
    """

    data: np.ndarray
    x: np.ndarray
    y: np.ndarray
    frequency: float
    source: Any = None

    def __init__(self, data: Any, x: Any, y: Any, frequency: float, *,
                 source: Any = None) -> None:
        arr = as_finite_complex(data, "data", min_ndim=2)
        xa = as_axis(x, "x", length=arr.shape[-1])
        ya = as_axis(y, "y", length=arr.shape[-2])
        f = check_frequency(frequency)
        if source is not None and not (hasattr(source, "field") and hasattr(source, "reflected")):
            raise ValueError("source must be a PlaneWave, PointSource, GaussianBeam or None, got "
                             f"{type(source).__name__}")
        arr = arr.copy()  # the hologram owns its data: the caller's array is never shared
        arr.setflags(write=False)
        xa.setflags(write=False)
        ya.setflags(write=False)
        object.__setattr__(self, "data", arr)
        object.__setattr__(self, "x", xa)
        object.__setattr__(self, "y", ya)
        object.__setattr__(self, "frequency", f)
        object.__setattr__(self, "source", source)

    @property
    def wavelength(self) -> float:
        """Wavelength in air, metres."""
        return C0 / self.frequency

    @property
    def k(self) -> float:
        """Wavenumber in air, rad/m."""
        return 2 * np.pi * self.frequency / C0

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of ``data``."""
        return self.data.shape

    @property
    def pitch(self) -> tuple[float, float]:
        """``(dx, dy)`` in metres; raises if the grid is not uniform."""
        return uniform_step(self.x, "x"), uniform_step(self.y, "y")

    @property
    def aperture_size(self) -> tuple[float, float]:
        """Full widths ``(A, B)`` = n * pitch, metres."""
        dx, dy = self.pitch
        return self.x.size * dx, self.y.size * dy

    @property
    def points(self) -> np.ndarray:
        """Element positions (N, 3) on the plane z = 0, row-major over (y, x) like ``data``."""
        X, Y = np.meshgrid(self.x, self.y)
        return np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)

    def with_data(self, data: Any) -> Hologram:
        """A copy with new ``data`` of the same trailing shape (coordinates kept).

        Examples
        --------
        >>> x = np.arange(4) * 0.01
        >>> Hologram(np.ones((4, 4)), x, x, 1e10).with_data(np.zeros((2, 4, 4))).shape
        (2, 4, 4)
        """
        return Hologram(data, self.x, self.y, self.frequency, source=self.source)

    def replace(self, **changes: Any) -> Hologram:
        """A copy with some fields replaced (``dataclasses.replace`` semantics)."""
        kw = {"data": self.data, "x": self.x, "y": self.y, "frequency": self.frequency,
              "source": self.source}
        kw.update(changes)
        src = kw.pop("source")
        return Hologram(**kw, source=src)


@dataclass(frozen=True, eq=False)
class Image:
    """A complex image (reconstructed field) on planes at range ``z``.

    Attributes
    ----------
    data : ndarray, complex
        Shape ``(..., nz, ny, nx)`` for a sequence of ranges, ``(..., ny, nx)``
        for a scalar range.
    x, y : ndarray
        Pixel coordinates, metres.
    z : ndarray
        Ranges of the planes from the aperture, metres (always 1-D).
    frequency : float
        Frequency in Hz.
    method : str
        How the image was formed (e.g. ``"angular"``).
    has_z_axis : bool
        True when ``data`` has the ``nz`` axis (a sequence of ranges was asked).

    Examples
    --------
    >>> img = Image(np.zeros((2, 3, 4)), np.arange(4.0), np.arange(3.0), np.array([0.1, 0.2]),
    ...             9.9e9, "angular")
    >>> img.intensity.shape
    (2, 3, 4)
    """

    data: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    frequency: float
    method: str = "angular"
    has_z_axis: bool = True

    @property
    def intensity(self) -> np.ndarray:
        """``|data|^2``."""
        return np.abs(self.data) ** 2

    def peak(self) -> tuple[float, float, float]:
        """``(x, y, z)`` of the brightest pixel, metres (over all planes)."""
        a = np.abs(self.data)
        if not self.has_z_axis:
            a = a[..., None, :, :]
        a = a.reshape((-1, *a.shape[-3:])).max(axis=0)
        iz, iy, ix = np.unravel_index(np.argmax(a), a.shape)
        return float(self.x[ix]), float(self.y[iy]), float(self.z[iz])

    def plane(self, z: float) -> Image:
        """The plane nearest to range ``z`` as a 2-D image.

        Examples
        --------
        >>> img = Image(np.zeros((2, 3, 4)), np.arange(4.0), np.arange(3.0),
        ...             np.array([0.1, 0.2]), 9.9e9)
        >>> img.plane(0.19).data.shape, float(img.plane(0.19).z[0])
        ((3, 4), 0.2)
        """
        if not self.has_z_axis:
            return self
        i = int(np.argmin(np.abs(self.z - z)))
        return replace(self, data=self.data[..., i, :, :], z=self.z[i:i + 1], has_z_axis=False)
