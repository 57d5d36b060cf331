"""The Gaussian-beam source: :class:`GaussianBeam`.

A beam defined at its waist by its angular spectrum, each plane-wave component
carried through (or reflected by) the layered medium exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import as_complex_scalar, as_position, as_real
from ._geometry import _points
from .medium import Medium
from .vector_waves import vector_transfer, wave_polarization

__all__ = ["GaussianBeam"]


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
    polarization : (float, float, float), optional
        Direction of the electric field at the waist (world axes; its part across
        the beam's axis is kept, normalised): the vector model, each plane-wave
        component carrying ``E`` split into TE and TM parts
        (:mod:`holoradar.physics.vector_waves`). Default ``None``: scalar.

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
    polarization: tuple[float, float, float] | None = None

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
        object.__setattr__(self, "polarization",
                           wave_polarization(self.direction, self.polarization))

    def _vector(self, k: float, medium: Medium, points: np.ndarray, reflected: bool
                ) -> np.ndarray:
        if self.polarization is None:
            raise ValueError("this GaussianBeam has no polarization: give GaussianBeam(..., "
                             "polarization=(ux, uy, uz)) for the vector model")
        pts = _points(points)
        out = np.zeros((len(pts), 3), complex)
        if reflected and medium.is_free_space:
            return out
        grid_pts = pts
        if reflected:
            grid_pts = pts.copy()
            grid_pts[:, 2] = 2 * medium.z_interfaces[0] - pts[:, 2]
        P, Q, A, dpq = self._spectrum(k, grid_pts)
        keep = A != 0
        e = np.array(self.polarization)
        for z in np.unique(pts[:, 2]):
            sel = pts[:, 2] == z
            V = np.zeros((*P.shape, 3), complex)
            V[keep] = vector_transfer(k, medium, P[keep], Q[keep], e, float(self.center[2]),
                                      float(z), reflected=reflected)
            for c in range(3):
                S = np.where(keep, A * V[..., c], 0)
                if np.any(S):
                    out[sel, c] = self._sum(P, Q, S, pts[sel]) * dpq / (4 * np.pi**2)
        return out

    def field_vector(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Incident electric field vectors (N, 3) at ``points`` (N, 3)."""
        return self._vector(k, medium, points, False)

    def reflected_vector(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """The beam's specular reflection (N, 3) at air ``points``."""
        return self._vector(k, medium, points, True)

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
