"""Illuminating sources: plane wave, point radiator (horn) and Gaussian beam.

Every source gives its incident field at arbitrary points of a layered medium
(:meth:`field`, the down-going wave, transmitted into the layers) and the
specular reflection of that field from the ground as seen in the air
(:meth:`reflected`, the surface glare). Positions are (x, y, z) in metres, z the
range from the aperture plane; time dependence ``exp(-i*omega*t)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from .._validate import as_complex_scalar, as_position, as_real
from .green import free_space_green, layered_green
from .medium import Medium

__all__ = ["GaussianBeam", "PlaneWave", "PointSource", "Source", "ray_direction"]


class Source(Protocol):
    """What :func:`holoradar.simulate` and the imaging functions need of a source."""

    def field(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray: ...

    def reflected(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray: ...


def _points(points: np.ndarray) -> np.ndarray:
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (N, 3) (x, y, z in metres), got {pts.shape}")
    return pts


@dataclass(frozen=True)
class PlaneWave:
    """A plane wave of unit amplitude travelling into the scene (towards +z).

    Parameters
    ----------
    alpha, beta : float
        Angles from the z axis towards x and towards y, radians. The transverse
        wavenumbers are ``p0 = k*sin(alpha)``, ``q0 = k*sin(beta)``.

    Notes
    -----
    The field in the air is ``exp(i*(p0*x + q0*y + kz0*z))``: phase 0 at the
    aperture centre (0, 0, 0). In a layer it is multiplied by the Fresnel
    transmissions and the layer phases (:meth:`Medium.vertical_transfer`).

    Examples
    --------
    >>> [round(v, 3) for v in PlaneWave(np.radians(10), 0.0).wavenumbers(200.0)]
    [34.73, 0.0]
    """

    alpha: float = 0.0
    beta: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "alpha", as_real(self.alpha, "alpha"))
        object.__setattr__(self, "beta", as_real(self.beta, "beta"))
        if np.sin(self.alpha) ** 2 + np.sin(self.beta) ** 2 >= 1:
            raise ValueError("alpha, beta must satisfy sin(alpha)^2 + sin(beta)^2 < 1 (a "
                             f"propagating wave), got alpha={self.alpha}, beta={self.beta}")

    def wavenumbers(self, k: float) -> tuple[float, float]:
        """Transverse wavenumbers ``(p0, q0)`` in rad/m."""
        return float(k * np.sin(self.alpha)), float(k * np.sin(self.beta))

    def field(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Incident (down-going) field at ``points`` (N, 3)."""
        pts = _points(points)
        p0, q0 = self.wavenumbers(k)
        k2 = np.array(p0 * p0 + q0 * q0)
        lateral = np.exp(1j * (p0 * pts[:, 0] + q0 * pts[:, 1]))
        out = np.empty(len(pts), complex)
        kz0 = medium.kz(k, k2, 0)
        for z in np.unique(pts[:, 2]):
            sel = pts[:, 2] == z
            # Above the reference plane (z < 0, a raised or tilted aperture) the wave
            # has not reached z = 0 yet: its phase lags, exp(i*kz0*z) with z < 0.
            t = (np.exp(1j * kz0 * z) if z < 0
                 else medium.vertical_transfer(k, k2, 0.0, float(z)))
            out[sel] = lateral[sel] * t
        return out

    def reflected(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Specular reflection from the ground at air points (N, 3)."""
        pts = _points(points)
        if medium.is_free_space:
            return np.zeros(len(pts), complex)
        p0, q0 = self.wavenumbers(k)
        k2 = np.array(p0 * p0 + q0 * q0)
        z0 = medium.z_interfaces[0]
        kz0 = medium.kz(k, k2, 0)
        return (medium.reflection(k, k2) * np.exp(1j * kz0 * (2 * z0 - pts[:, 2]))
                * np.exp(1j * (p0 * pts[:, 0] + q0 * pts[:, 1])))


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
        its parallel field component).

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

    def __post_init__(self) -> None:
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


@dataclass(frozen=True)
class GaussianBeam:
    """A Gaussian beam travelling into the scene, defined at its waist.

    Parameters
    ----------
    waist : float
        1/e amplitude radius w0 at the waist, metres.
    center : (float, float, float), optional
        Waist centre (x, y, z) in metres; default the aperture centre.
    alpha, beta : float, optional
        Tilt of the beam axis from z towards x and y, radians.
    amplitude : complex, optional
        Field at the waist centre.

    Notes
    -----
    Its angular spectrum at the waist plane is
    ``A(p, q) = amplitude*pi*w0^2*exp(-((p - p0)^2 + (q - q0)^2)*w0^2/4)``, each
    component carried through the stack exactly; the field is the 2-D inverse
    transform evaluated by quadrature on a grid that resolves the Gaussian.
    Evanescent components are dropped.

    Examples
    --------
    >>> b = GaussianBeam(0.05, center=(0, 0, 0.2))
    >>> k = 2 * np.pi / 0.03
    >>> round(float(abs(b.field(k, Medium.free_space(), np.array([[0, 0, 0.2]]))[0])), 3)
    1.0
    """

    waist: float
    center: np.ndarray = field(default_factory=lambda: np.zeros(3))
    alpha: float = 0.0
    beta: float = 0.0
    amplitude: complex = 1.0

    def __post_init__(self) -> None:
        w = as_real(self.waist, "waist") if not isinstance(self.waist, str) else -1.0
        if w <= 0:
            raise ValueError(f"waist must be a positive radius in metres, got {self.waist!r}")
        object.__setattr__(self, "waist", w)
        object.__setattr__(self, "center", as_position(self.center, "center"))
        object.__setattr__(self, "alpha", as_real(self.alpha, "alpha"))
        object.__setattr__(self, "beta", as_real(self.beta, "beta"))
        if np.sin(self.alpha) ** 2 + np.sin(self.beta) ** 2 >= 1:
            raise ValueError("alpha, beta must satisfy sin(alpha)^2 + sin(beta)^2 < 1 (a "
                             f"propagating beam), got alpha={self.alpha}, beta={self.beta}")
        object.__setattr__(self, "amplitude", as_complex_scalar(self.amplitude, "amplitude"))

    def _spectrum(self, k: float, pts: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Angular spectrum on a grid fine enough that nothing wraps onto ``pts``.

        The quadrature makes the field periodic with period ``2*pi/dp``; the period
        is set larger than twice the farthest point's distance from the beam plus
        eight beam radii there, so the periodic copies of the beam are negligible
        (exp(-16)) at every point.
        """
        w = self.waist
        p0, q0 = k * np.sin(self.alpha), k * np.sin(self.beta)
        dz = np.abs(pts[:, 2] - self.center[2])
        zr = k * w * w / 2
        w_far = w * np.sqrt(1 + (dz.max(initial=0.0) / zr) ** 2)
        tilt = np.hypot(np.tan(np.arcsin(np.clip(np.sin(self.alpha), -0.99, 0.99))),
                        np.tan(np.arcsin(np.clip(np.sin(self.beta), -0.99, 0.99))))
        rho = np.hypot(pts[:, 0] - self.center[0], pts[:, 1] - self.center[1]) + dz * tilt
        period = 2 * (rho.max(initial=0.0) + 4 * w_far) + 8 * w
        dp = 2 * np.pi / period
        half = 8.0 / w  # exp(-16): the spectrum beyond is negligible
        m = int(np.ceil(half / dp))
        if 2 * m + 1 > 1025:
            raise ValueError("points lie too far from the GaussianBeam for its waist "
                             f"({w} m): the quadrature would need {2 * m + 1}^2 nodes")
        p = p0 + np.arange(-m, m + 1) * dp
        q = q0 + np.arange(-m, m + 1) * dp
        P, Q = np.meshgrid(p, q)
        A = self.amplitude * np.pi * w * w * np.exp(-((P - p0) ** 2 + (Q - q0) ** 2) * w * w / 4)
        A = np.where(P * P + Q * Q < k * k, A, 0)
        return P, Q, A, dp * dp

    def _sum(self, P: np.ndarray, Q: np.ndarray, S: np.ndarray, pts: np.ndarray) -> np.ndarray:
        x = pts[:, 0] - self.center[0]
        y = pts[:, 1] - self.center[1]
        keep = S != 0
        Pk, Qk, Sk = P[keep], Q[keep], S[keep]
        out = np.empty(len(pts), complex)
        step = max(1, int(2e7 // max(Pk.size, 1)))  # bound the phase matrix's memory
        for c0 in range(0, len(pts), step):
            sl = slice(c0, c0 + step)
            out[sl] = np.exp(1j * (np.outer(x[sl], Pk) + np.outer(y[sl], Qk))) @ Sk
        return out

    def field(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Incident field at ``points`` (N, 3)."""
        pts = _points(points)
        P, Q, A, dpq = self._spectrum(k, pts)
        k2 = P * P + Q * Q
        out = np.empty(len(pts), complex)
        for z in np.unique(pts[:, 2]):
            sel = pts[:, 2] == z
            if z >= self.center[2]:
                T = medium.vertical_transfer(k, k2, float(self.center[2]), float(z))
            else:  # before the waist, in the air: propagating components only
                T = np.exp(-1j * medium.kz(k, k2, 0).real * (self.center[2] - z))
            out[sel] = self._sum(P, Q, A * T, pts[sel]) * dpq / (4 * np.pi**2)
        return out

    @property
    def direction(self) -> np.ndarray:
        """Unit vector of the beam's axis (towards +z, into the scene)."""
        sa, sb = np.sin(self.alpha), np.sin(self.beta)
        return np.array([sa, sb, np.sqrt(1 - sa * sa - sb * sb)])

    def mirror_position(self, medium: Medium) -> np.ndarray:
        """The waist of the beam reflected by the surface: the mirror image of the
        incident waist, range ``2*z0 - z_w`` (a plane mirror images the whole beam;
        each of its plane waves keeps its own reflection coefficient, which shapes
        the reflected beam's amplitude, not where it focuses).

        Examples
        --------
        >>> GaussianBeam(0.05, center=(0.0, -0.1, 0.1)).mirror_position(
        ...     Medium.half_space(0.3, 2.5)).round(6).tolist()
        [0.0, -0.1, 0.5]
        """
        if medium.is_free_space:
            raise ValueError("a free-space medium has no surface and no mirror image")
        z0 = medium.z_interfaces[0]
        if self.center[2] > z0:
            raise ValueError(f"the beam's waist (range {float(self.center[2])} m) must not lie "
                             f"below the ground surface ({z0} m) for its glare to be modelled")
        return np.array([self.center[0], self.center[1], 2 * z0 - self.center[2]])

    def reflected(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Specular reflection from the ground at air points (N, 3)."""
        pts = _points(points)
        if medium.is_free_space:
            return np.zeros(len(pts), complex)
        z0 = medium.z_interfaces[0]
        # The reflected beam travels as far as from its mirror waist: size the grid for it.
        mirror = pts.copy()
        mirror[:, 2] = 2 * z0 - pts[:, 2]
        P, Q, A, dpq = self._spectrum(k, mirror)
        k2 = P * P + Q * Q
        kz0 = medium.kz(k, k2, 0)
        R = medium.reflection(k, k2)
        out = np.empty(len(pts), complex)
        for z in np.unique(pts[:, 2]):
            sel = pts[:, 2] == z
            T = R * np.exp(1j * kz0 * ((z0 - self.center[2]) + (z0 - z)))
            out[sel] = self._sum(P, Q, A * T, pts[sel]) * dpq / (4 * np.pi**2)
        return out
