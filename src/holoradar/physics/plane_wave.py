"""The plane-wave source: :class:`PlaneWave`.

Its incident field through the layered medium and its specular reflection from
the ground, in closed form per layer (conventions: :mod:`.sources`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_real
from ._geometry import _points
from .medium import Medium
from .vector_waves import vector_transfer, wave_polarization

__all__ = ["PlaneWave"]


@dataclass(frozen=True)
class PlaneWave:
    """A plane wave of unit amplitude travelling into the scene (towards +z).

    Parameters
    ----------
    alpha, beta : float
        Angles from the z axis towards x and towards y, radians. The transverse
        wavenumbers are ``p0 = k*sin(alpha)``, ``q0 = k*sin(beta)``.
    polarization : (float, float, float), optional
        Direction of the electric field in the scene's axes (its part across the
        direction of travel is kept, normalised): ``(0, 1, 0)`` for E along y.
        With it the wave is a vector field (:meth:`field_vector`): TE and TM parts
        cross the ground with their own Fresnel laws. Default ``None``: scalar.

    Notes
    -----
    The field in the air is ``exp(i*(p0*x + q0*y + kz0*z))``: phase 0 at the
    aperture centre (0, 0, 0). In a layer it is multiplied by the Fresnel
    transmissions and the layer phases (:meth:`Medium.vertical_transfer`).

    Examples
    --------
    >>> [round(v, 3) for v in PlaneWave(np.radians(10), 0.0).wavenumbers(200.0)]
    [34.73, 0.0]
    >>> PlaneWave(polarization=(0, 1, 0)).polarization
    (0.0, 1.0, 0.0)
    """

    alpha: float = 0.0
    beta: float = 0.0
    polarization: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "alpha", as_real(self.alpha, "alpha"))
        object.__setattr__(self, "beta", as_real(self.beta, "beta"))
        if np.sin(self.alpha) ** 2 + np.sin(self.beta) ** 2 >= 1:
            raise ValueError("alpha, beta must satisfy sin(alpha)^2 + sin(beta)^2 < 1 (a "
                             f"propagating wave), got alpha={self.alpha}, beta={self.beta}")
        object.__setattr__(self, "polarization",
                           wave_polarization(self.direction, self.polarization))

    @property
    def direction(self) -> np.ndarray:
        """Unit vector of travel (towards +z)."""
        sa, sb = np.sin(self.alpha), np.sin(self.beta)
        return np.array([sa, sb, np.sqrt(1 - sa * sa - sb * sb)])

    def _vector(self, k: float, medium: Medium, points: np.ndarray, reflected: bool
                ) -> np.ndarray:
        if self.polarization is None:
            raise ValueError("this PlaneWave has no polarization: give "
                             "PlaneWave(..., polarization=(ux, uy, uz)) for the vector model")
        pts = _points(points)
        p0, q0 = self.wavenumbers(k)
        lateral = np.exp(1j * (p0 * pts[:, 0] + q0 * pts[:, 1]))
        out = np.zeros((len(pts), 3), complex)
        if reflected and medium.is_free_space:
            return out
        e = np.array(self.polarization)
        for z in np.unique(pts[:, 2]):
            sel = pts[:, 2] == z
            v = vector_transfer(k, medium, np.array(p0), np.array(q0), e, 0.0, float(z),
                                reflected=reflected)
            out[sel] = lateral[sel, None] * v
        return out

    def field_vector(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Incident (down-going) electric field vectors (N, 3) at ``points`` (N, 3)."""
        return self._vector(k, medium, points, False)

    def reflected_vector(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Its specular reflection from the ground (N, 3) at air ``points``."""
        return self._vector(k, medium, points, True)

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
