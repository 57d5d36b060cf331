"""The point radiator (horn, dipole): :class:`PointSource`, and :func:`ray_direction`.

``ray_direction`` traces the refracted ray from a point in the air to each point
of the layered medium (Snell's law); the radiator's pattern is applied along it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import as_complex_scalar, as_polarization, as_position, as_real
from ._geometry import _points
from .dipole import Dipole
from .green import free_space_green, layered_green
from .medium import Medium

__all__ = ["PointSource", "ray_direction"]


def ray_direction(k: float, medium: Medium, src: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Unit direction, leaving ``src`` in the air, of the refracted ray to each point.

    Snell's law: the ray keeps one transverse wavenumber kappa through the stack,
    and its lateral offset ``sum_j h_j * kappa/kz_j`` grows monotonically with
    kappa; bisection finds the kappa that lands on each point.

    Returns
    -------
    ndarray, shape (N, 3)
    """
    src = np.asarray(src, float)
    pts = _points(pts)
    d = pts - src
    rho = np.hypot(d[:, 0], d[:, 1])
    down = d[:, 2] >= 0
    if medium.is_free_space:
        return d / np.linalg.norm(d, axis=1, keepdims=True)
    # Thickness crossed in each region, per point.
    hs = []
    for m in range(medium.n_regions):
        top = -np.inf if m == 0 else medium.top_of(m)  # the air extends behind the array
        bottom = medium.z_interfaces[m] if m < len(medium.z_interfaces) else np.inf
        lo = np.minimum(src[2], pts[:, 2])
        hi = np.maximum(src[2], pts[:, 2])
        hs.append(np.clip(np.minimum(hi, bottom) - np.maximum(lo, top), 0, None))
    n = [medium.n(m).real for m in range(medium.n_regions)]

    def offset(s: np.ndarray) -> np.ndarray:
        # s = sin of the angle in air; lateral offset of the ray.
        return sum(h * s / np.sqrt(nm * nm - s * s) for h, nm in zip(hs, n, strict=True))

    lo_s, hi_s = np.zeros_like(rho), np.full_like(rho, 1 - 1e-12)
    for _ in range(60):
        mid = 0.5 * (lo_s + hi_s)
        too_far = offset(mid) > rho
        hi_s = np.where(too_far, mid, hi_s)
        lo_s = np.where(too_far, lo_s, mid)
    s = 0.5 * (lo_s + hi_s)
    phi = np.arctan2(d[:, 1], d[:, 0])
    cz = np.sqrt(1 - s * s) * np.where(down, 1.0, -1.0)
    return np.stack([s * np.cos(phi), s * np.sin(phi), cz], axis=1)


@dataclass(frozen=True)
class PointSource:
    """A point radiator (the horn) in the air: ``exp(i*k*R)/R`` times a pattern.

    Parameters
    ----------
    position : (float, float, float)
        (x, y, z) in metres; z is its range from the aperture plane (it may be
        negative: behind the array) and must lie above the ground surface.
    pattern_exponent : float, optional
        Horn pattern ``max(cos(psi), 0)**m`` with psi the angle between the ray
        leaving the source and ``axis``; 0 (default) is isotropic.
    axis : (float, float, float), optional
        Direction of the horn's boresight (normalised here); default +z.
    amplitude : complex, optional
        Complex amplitude: the field is ``amplitude * exp(i*k*R)/R`` on axis.
    dipole : bool, optional
        A short dipole along ``axis`` instead of a horn: the field component along
        the dipole, ``1 - (d . axis)^2`` for a ray direction d (0 along the wire),
        replaces the cosine pattern (a gprMax ``hertzian_dipole`` seen through
        its parallel field component; the exact vector dipole is
        :class:`~holoradar.Dipole`).
    polarization : (float, float, float), optional
        Direction of the horn's electric field (world axes, normalised): the
        vector model. The horn is then a short electric dipole along
        ``polarization`` (the probe that feeds a rectangular horn) whose field,
        exact near and far and split into TE and TM waves at the ground
        (:mod:`holoradar.physics.dyadic`), is tapered by the horn's pattern
        ``max(cos(psi), 0)**m`` along each ray. Why a dipole: its far field is
        transverse and its TE/TM split through the ground is exact, so the
        polarisation-dependent part of the glare and of the transmission is
        right; the horn's aperture only narrows the beam, a far-field amplitude
        taper (a Huygens source would add a magnetic dipole, turning the dipole's
        own ``sin`` pattern into a cardioid; at the angles a horn lights, within
        its beam, the two differ by a smooth amplitude the taper absorbs).
        Default ``None``: the scalar model.

    Notes
    -----
    The pattern is applied along the refracted ray to each point (a far-field
    approximation of the horn); the spherical wave itself is exact
    (:func:`holoradar.physics.green.layered_green`).

    Examples
    --------
    >>> horn = PointSource((0.0, -0.25, 0.0), pattern_exponent=2, axis=(0, 0.5, 1))
    >>> horn.position
    array([ 0.  , -0.25,  0.  ])
    """

    position: np.ndarray
    pattern_exponent: float = 0.0
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    amplitude: complex = 1.0
    dipole: bool = False
    polarization: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        pol = as_polarization(self.polarization, "polarization")
        if pol is not None:
            if self.dipole:
                raise ValueError("dipole=True is the scalar stand-in for a dipole; with a "
                                 "polarization the horn is already a vector dipole: drop "
                                 "dipole=True, or use holoradar.Dipole")
            object.__setattr__(self, "polarization", tuple(float(v) for v in pol))
        object.__setattr__(self, "position", as_position(self.position, "position"))
        ax = as_position(self.axis, "axis")
        nrm = np.linalg.norm(ax)
        if nrm == 0:
            raise ValueError("axis must be a non-zero direction (x, y, z)")
        object.__setattr__(self, "axis", ax / nrm)
        object.__setattr__(self, "pattern_exponent",
                           as_real(self.pattern_exponent, "pattern_exponent", nonnegative=True))
        object.__setattr__(self, "amplitude", as_complex_scalar(self.amplitude, "amplitude"))

    def _check_air(self, medium: Medium) -> None:
        if not medium.is_free_space and self.position[2] >= medium.z_interfaces[0]:
            raise ValueError(f"PointSource position z={self.position[2]} m must lie above the "
                             f"ground surface at z={medium.z_interfaces[0]} m")

    @property
    def has_pattern(self) -> bool:
        """True unless the source is isotropic."""
        return bool(self.pattern_exponent) or self.dipole

    def pattern(self, directions: np.ndarray) -> np.ndarray:
        """Amplitude pattern for unit ``directions`` (N, 3)."""
        if self.dipole:
            return 1 - (directions @ self.axis) ** 2
        if self.pattern_exponent == 0:
            return np.ones(len(directions))
        c = np.clip(directions @ self.axis, 0, None)
        return c**self.pattern_exponent

    def field(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Incident field at ``points`` (N, 3), through the stack where they are buried."""
        self._check_air(medium)
        pts = _points(points)
        g = (free_space_green(k, self.position, pts) if medium.is_free_space
             else layered_green(k, medium, self.position, pts))
        if self.has_pattern:
            g = g * self.pattern(ray_direction(k, medium, self.position, pts))
        return self.amplitude * g

    def mirror_position(self, medium: Medium) -> np.ndarray:
        """The mirror-image source in the surface: range ``2*z0 - z_s``."""
        self._check_air(medium)
        if medium.is_free_space:
            raise ValueError("a free-space medium has no surface and no mirror image")
        z0 = medium.z_interfaces[0]
        return np.array([self.position[0], self.position[1], 2 * z0 - self.position[2]])

    def _dipole(self) -> Dipole:
        if self.polarization is None:
            raise ValueError("this PointSource has no polarization: give PointSource(..., "
                             "polarization=(ux, uy, uz)) for the vector model")
        return Dipole(self.position, self.polarization, self.amplitude)

    def field_vector(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Incident electric field vectors (N, 3): the dipole's, tapered by the pattern."""
        self._check_air(medium)
        pts = _points(points)
        E = self._dipole().field_vector(k, medium, pts)
        if self.pattern_exponent:
            E = E * self.pattern(ray_direction(k, medium, self.position, pts))[:, None]
        return E

    def reflected_vector(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """The glare's electric field vectors (N, 3) at air points, tapered by the pattern
        along the ray that leaves the horn towards the mirror point."""
        self._check_air(medium)
        pts = _points(points)
        if medium.is_free_space:
            return np.zeros((len(pts), 3), complex)
        E = self._dipole().reflected_vector(k, medium, pts)
        if self.pattern_exponent:
            d = pts - self.mirror_position(medium)
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            d[:, 2] *= -1
            E = E * self.pattern(d)[:, None]
        return E

    def reflected(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Specular reflection from the ground at air points (N, 3): the glare."""
        self._check_air(medium)
        pts = _points(points)
        if medium.is_free_space:
            return np.zeros(len(pts), complex)
        g = layered_green(k, medium, self.position, pts, kind="reflected")
        if self.has_pattern:
            img = self.mirror_position(medium)
            d = pts - img
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            d[:, 2] *= -1  # unfold the reflection: the ray leaves the real source downwards
            g = g * self.pattern(d)
        return self.amplitude * g
