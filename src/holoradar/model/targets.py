"""Scattering targets: point scatterers and planar (Kirchhoff) objects.

A :class:`PointTarget` of amplitude ``a`` at r_t re-radiates ``a * E0(r_t)`` as a
point source in the medium that holds it (Born). A :class:`PlanarTarget` at
range z with reflection coefficient ``f(x, y)`` replaces the incident field by the
reflected field ``f * E0`` just above its plane (Kirchhoff / physical optics,
the paper's Eq. 4), which then travels up to the aperture. Sign convention:
``f = +1`` is the paper's "1 on the object"; a perfect metal plate is ``f = -1``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._validate import as_axis, as_complex_scalar, as_finite_complex, as_position, uniform_step
from . import shapes

__all__ = ["PlanarTarget", "PointTarget"]


@dataclass(frozen=True)
class PointTarget:
    """An isotropic point scatterer.

    Parameters
    ----------
    position : (float, float, float)
        (x, y, z) in metres, z its range from the aperture.
    amplitude : complex
        Scattering amplitude (metres): the scattered field is
        ``amplitude * E0 * exp(i*k_n*R)/R`` in the target's medium.

    Examples
    --------
    >>> PointTarget((0.0, 0.05, 0.4)).position
    array([0.  , 0.05, 0.4 ])
    """

    position: np.ndarray
    amplitude: complex = 1.0

    def __post_init__(self) -> None:
        pos = as_position(self.position, "position")
        if pos[2] <= 0:
            raise ValueError(f"position z must be > 0 (range beyond the aperture), got {pos[2]}")
        object.__setattr__(self, "position", pos)
        object.__setattr__(self, "amplitude", as_complex_scalar(self.amplitude, "amplitude"))


@dataclass(frozen=True, eq=False)
class PlanarTarget:
    """A planar object parallel to the aperture with a reflection coefficient map.

    Parameters
    ----------
    reflectivity : array_like, shape (ny, nx)
        Reflection coefficient f(x, y) (complex allowed; 0 off the object).
    x, y : array_like
        Uniform pixel coordinates of ``reflectivity``, metres.
    z : float
        Range of the object's plane from the aperture, metres (> 0).

    Examples
    --------
    >>> t = PlanarTarget.from_shape("letter_r", z=0.42, width=0.10, height=0.15)
    >>> t.z, round(t.pixel, 6)
    (0.42, 0.002)
    """

    reflectivity: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: float

    def __post_init__(self) -> None:
        f = as_finite_complex(self.reflectivity, "reflectivity", min_ndim=2)
        if f.ndim != 2:
            raise ValueError(f"reflectivity must be 2-D (ny, nx), got shape {f.shape}")
        x = as_axis(self.x, "x", length=f.shape[1])
        y = as_axis(self.y, "y", length=f.shape[0])
        uniform_step(x, "x")
        uniform_step(y, "y")
        try:
            z = float(self.z)
        except (TypeError, ValueError):
            z = np.nan
        if not np.isfinite(z) or z <= 0:
            raise ValueError(f"z must be a range > 0 m, got {self.z!r}")
        f = f.copy()
        for a in (f, x, y):
            a.setflags(write=False)
        object.__setattr__(self, "reflectivity", f)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "z", z)

    @property
    def pixel(self) -> float:
        """Pixel pitch along x, metres (see :attr:`pitch` for both)."""
        return float(self.x[1] - self.x[0])

    @property
    def pitch(self) -> tuple[float, float]:
        """Pixel pitch ``(dx, dy)``, metres."""
        return float(self.x[1] - self.x[0]), float(self.y[1] - self.y[0])

    @classmethod
    def from_mask(cls, mask: np.ndarray, x: np.ndarray, y: np.ndarray, z: float, *,
                  reflection: complex = 1.0) -> PlanarTarget:
        """A planar target that reflects with ``reflection`` where ``mask`` is True.

        Examples
        --------
        >>> u = np.arange(-10, 11) * 0.005
        >>> t = PlanarTarget.from_mask(np.abs(u)[None, :] < 0.03 + 0 * u[:, None], u, u, 0.4,
        ...                            reflection=-1)
        >>> int((t.reflectivity == -1).sum())
        231
        """
        m = np.asarray(mask)
        if m.dtype != bool:
            raise ValueError(f"mask must be a boolean array, got dtype {m.dtype}")
        return cls(m * complex(reflection), x, y, z)

    @classmethod
    def from_shape(cls, shape: str | Callable[..., np.ndarray], z: float, *,
                   center: tuple[float, float] = (0.0, 0.0), reflection: complex = 1.0,
                   pixel: float = 0.002, extent: float | None = None,
                   **size: float) -> PlanarTarget:
        """A planar target from a named shape or a mask function.

        Parameters
        ----------
        shape : {"letter_r", "disk", "ring", "rectangle"} or callable
            Shape name from :mod:`holoradar.model.shapes` or ``f(X, Y, **size)``.
        z : float
            Range, metres.
        center : (float, float)
            Lateral centre (x, y), metres.
        reflection : complex
            Reflection coefficient on the object (+1 paper convention, -1 metal).
        pixel : float
            Pixel pitch, metres (default 2 mm: a sixth of the wavelength in sand
            at 9.9 GHz, so the edges are resolved beyond the imaging band).
        extent : float, optional
            Side of the square grid, metres (default: fits the shape, whose size
            is taken from ``size``; 0.3 m if unknown).
        **size
            Passed to the shape function, e.g. ``diameter=0.11``.
        """
        fn = getattr(shapes, shape) if isinstance(shape, str) else shape
        if not callable(fn):
            raise ValueError(f"shape must be one of {shapes.__all__} or a callable")
        if extent is None:
            dims = [v for v in size.values() if isinstance(v, int | float)]
            extent = 1.1 * max(dims) + 4 * pixel if dims else 0.18
        n = int(np.ceil(extent / pixel)) | 1
        u = (np.arange(n) - n // 2) * pixel
        mask = fn(u[None, :], u[:, None], **size)
        return cls(mask * complex(reflection), u + center[0], u + center[1], z)
