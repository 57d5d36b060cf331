"""The field a buried perfectly conducting sphere sends to the elements.

A sphere whose size matters (``k a`` of 1-10 in the ground, a ball bearing, a mine's
casing, a stone wrapped in foil) is not an isotropic point: its echo comes from the
part of its surface that faces the bisector of the incident and scattered rays, and
its strength and phase change with the scattering angle. :class:`SphereResponse`
replaces the point model's induced dipole ``a E0`` (:mod:`holoradar.imaging.point_response`)
by the dipole that radiates the sphere's own far field towards each element:

    p_n = (i / x) [S2(theta_n) (E0 . e_par) e_par_n + S1(theta_n) (E0 . e_perp_n) e_perp_n]

``S1, S2`` the Mie amplitudes of a perfect conductor (:mod:`holoradar.physics.mie`)
at ``x = k_g a`` (``k_g`` the ground's wavenumber), ``theta_n`` the scattering angle
between the incident ray's direction at the sphere ``d_i`` and the ray leaving it
for element n ``d_n`` (both refracted through the layers, Snell's law),
``e_perp_n = d_i x d_n / |d_i x d_n|``, ``e_par = e_perp_n x d_i`` and
``e_par_n = e_perp_n x d_n``. The element then records ``a (G(r <- e) u) . p_n`` as
for a point (reciprocity).

Its frequency dependence. Matching the far fields of a dipole and of the sphere, the
sphere radiates as a dipole of SI polarisability ``alpha = 4 pi eps0 a^3 i S / x^3``.
holoradar's fields are normalised as ``G = (I + grad grad / k_m^2) exp(i k_m R)/R``,
the physical field of a dipole moment divided by ``k^2 / (4 pi eps0)`` (its sources:
a :class:`~holoradar.Dipole` of fixed moment), and data across a band are taken as
calibrated to that source: a physical field ``E`` is ``k^2/(4 pi eps0) x`` the
calibrated one, for the incident field and for the scattered one alike. The sphere's
echo in calibrated units is then ``k^2 a^3 (i S / x^3) G E0 = a (i S / x) G E0``:
the factor ``i S / x`` (the point model's amplitude is a constant). Small spheres
rise as ``x^2`` (``S1 -> -i x^3 (1 - cos theta / 2)``, an electric dipole and a
magnetic one of half its strength); large ones are flat, ``|S(pi)| / x -> 1/2``,
the echo of the near side turning as ``exp(-2 i k_g a)``. With ``S1 = 1`` and
``S2 = cos theta`` at one frequency it is the point model exactly. (SMUTHI's
fields of a fixed moment, calibrated by ``1/k^2``: the sphere leaves 3e-4 of a
9-11 GHz band unexplained at the true eps', ``i S / x^3`` 2e-2, the point 7e-3.)

The sphere must lie in the far field of each element's ray (``k_g R >> x^2``) and the
layers' interaction with the sphere (a second bounce between the sphere and the
surface) is left out: a sphere 8.5 cm under sand, ``x = 4.9``, is within the
full-wave (T-matrix) solution's noise this way (the tests).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from .._validate import as_real
from ..data.hologram import Hologram
from ..physics.dipole import Dipole
from ..physics.dyadic import dyadic_times
from ..physics.line_green import RayFan
from ..physics.medium import Medium
from ..physics.mie import pec_sphere_amplitudes
from ..physics.sources import PlaneWave, PointSource
from .point_response import PointResponse, require_vector_flat

__all__ = ["SphereResponse", "check_sphere_radius", "sphere_backscatter", "sphere_dipoles"]


def check_sphere_radius(radius: Any) -> float:
    """A sphere's radius in metres, > 0.

    Examples
    --------
    >>> check_sphere_radius(0.015)
    0.015
    """
    if isinstance(radius, str | bytes):
        raise ValueError(f"sphere_radius must be the sphere's radius in metres, got {radius!r}")
    return as_real(radius, "sphere_radius (the sphere's radius in metres)", positive=True)


class SphereResponse(PointResponse):
    """Normalised matched filter of a buried perfectly conducting sphere.

    ``xy`` and ``z`` in the methods are the sphere's centre. Needs the vector model
    (a hologram with a ``polarization``, lit by a plane wave, a point source or a
    dipole, or a scanned transceiver) on an untilted grid.

    Parameters
    ----------
    hologram, make_medium, coherent, phase_only
        As :class:`~holoradar.imaging.point_response.PointResponse`.
    radius : float
        The sphere's radius, metres.
    fit_radius : bool
        Fit the radius with the position: ``xy`` is then ``(x, y, radius)`` in the
        methods (from :attr:`shape_start`), refitted at every trial eps' within a
        quarter of the ripple period ``pi / k_g`` of ``radius`` either side.

    Examples
    --------
    A small sphere (``k_g a`` = 0.003) is the point model's dipole and a magnetic
    dipole of half its strength: its response differs from the point's by 3e-5 in
    correlation here (1 - |<g, point>| / (|g| |point|)), a 2 cm one's by 4e-3.

    >>> import holoradar as hr
    >>> m = hr.Medium.half_space(0.3, 2.5)
    >>> h = hr.Hologram(np.zeros((16, 16)), np.linspace(-0.2, 0.2, 16),
    ...                 np.linspace(-0.2, 0.2, 16), 9.9e9, polarization=(0, 1, 0),
    ...                 source=hr.PlaneWave(polarization=(0, 1, 0)))
    >>> point = PointResponse(h, lambda e: m, coherent=True).response(2.5, 0.4, (0, 0))
    >>> def corr(a):
    ...     g = SphereResponse(h, lambda e: m, coherent=True, radius=a).response(
    ...         2.5, 0.4, (0, 0))
    ...     return 1 - abs(np.vdot(g, point)) / np.linalg.norm(g) / np.linalg.norm(point)
    >>> bool(corr(1e-4) < 1e-4), bool(corr(0.02) > 1e-3)
    (True, True)
    """

    def __init__(self, hologram: Hologram, make_medium: Callable[[float], Medium], *,
                 coherent: bool, radius: float, phase_only: bool = False,
                 fit_radius: bool = False) -> None:
        super().__init__(hologram, make_medium, coherent=coherent, phase_only=phase_only)
        self.radius = check_sphere_radius(radius)
        self.fit_radius = bool(fit_radius)
        require_vector_flat(self, hologram, "sphere", transceiver=True)
        if not self.monostatic and not isinstance(self.source, PlaneWave | PointSource
                                                  | Dipole):
            raise ValueError("target='sphere' needs the hologram's source as a PlaneWave, a "
                             f"PointSource or a Dipole, got {type(self.source).__name__}")

    # The search's extra parameters (Search.evaluate): the radius, refitted at every eps'.
    hold_shape = False
    shape_names = ("the sphere's radius",)

    @property
    def shape_start(self) -> tuple[float, ...]:
        """The extra parameters' start: the radius where it is fitted, else none."""
        return (self.radius,) if self.fit_radius else ()

    def shape_box(self, shape0: np.ndarray, eps: float, lam: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Bounds and scale of the radius in a fit at ``eps`` (``lam`` the free-space
        wavelength): a quarter of the focus's ripple period ``pi / k_g`` either side
        (the next ripple is another fit)."""
        half = np.pi / (4 * 2 * np.pi / lam * np.sqrt(eps))
        a0 = float(shape0[0])
        return (np.array([max(a0 - half, 0.2 * a0)]), np.array([a0 + half]),
                np.array([half / 5]))

    def _radius(self, xy: Any) -> float:
        return float(xy[2]) if len(xy) > 2 else self.radius

    def _vector_response(self, eps: float, z: float, xy: Any, pos: np.ndarray,
                         window: Any) -> np.ndarray:
        """``u . G(e <- r) p_n`` at the elements, (nf, N): the point's with the sphere's
        dipoles (module notes)."""
        w = window or self._window(eps, z)
        off = np.c_[xy[0] - self.points[:, 0], xy[1] - self.points[:, 1]]
        v = dyadic_times(off, w.G(z, np.hypot(off[:, 0], off[:, 1])), self.pol)
        medium = w.medium
        region = int(medium.region_of(float(z)))
        n_c = np.sqrt(complex(medium.eps[region]))
        x = self.ks * n_c * self._radius(xy)     # size parameter per frequency
        if self.monostatic:
            # Back to the element along the ray it came by: theta = pi for every
            # element, the polarisation kept: the point's v . v times i S1(pi) / x.
            return np.einsum("fni,fni->fn", v, v) * sphere_backscatter(x)[:, None]
        E0 = self._incident_vector(medium, pos, xy, z, w)                  # (nf, 3)
        d_i = self._incident_direction(medium, xy, z)                      # (3,)
        d_s = self._rays_to_elements(medium, xy, z)                        # (N, 3)
        p = sphere_dipoles(E0, d_i, d_s, x)
        return np.einsum("fni,fni->fn", v, p)

    def unmodelled_energy(self, eps: float, z: float, xy: Any, g: np.ndarray,
                          a: np.ndarray) -> float:
        """The sphere's second bounce off the interface above it, left out of the model:
        its field back at the sphere is ``|V| |S1(pi)| / (|k_g| 2 d)`` of the incident
        one (the echo sent up, ``S1(pi) / (k_g r)`` at ``r = 2 d`` by way of the surface
        ``d`` above the centre, reflected with the normal-incidence ``V`` of that
        interface) and the sphere scatters it again much as the first time: an error of
        that share of the fitted field at each frequency, whose energy this returns."""
        medium = self.make_medium(float(eps))
        region = int(medium.region_of(float(z)))
        above = medium.z_interfaces[region - 1]
        n_in, n_up = np.sqrt(complex(medium.eps[region])), np.sqrt(complex(medium.eps[region - 1]))
        V = abs((n_in - n_up) / (n_in + n_up))
        k_g = self.ks * n_in
        a_s = self._radius(xy)
        x = k_g * a_s
        share = V * np.abs(sphere_backscatter(x) * x) / (np.abs(k_g) * 2 * (float(z) - above))
        fitted = np.sum(np.abs(self.model(g, a)) ** 2, axis=1)
        return float(np.sum(share**2 * fitted))

    def _incident_direction(self, medium: Medium, xy: Any, z: float) -> np.ndarray:
        """The incident ray's unit direction at the sphere (into the ground)."""
        n = np.sqrt(float(complex(medium.eps[int(medium.region_of(float(z)))]).real))
        s = self.source
        if isinstance(s, PlaneWave):
            p = np.array(s.wavenumbers(1.0), float)           # horizontal slowness, air
        else:
            lateral = np.array([xy[0] - s.position[0], xy[1] - s.position[1]], float)
            rho = float(np.hypot(*lateral))
            slow = float(RayFan(medium, float(s.position[2]), float(z)).slowness(
                np.array([rho]))[0])
            p = slow * (lateral / rho if rho > 0 else np.zeros(2))
        t = p / n
        return np.array([t[0], t[1], np.sqrt(max(0.0, 1.0 - t @ t))])

    def _rays_to_elements(self, medium: Medium, xy: Any, z: float) -> np.ndarray:
        """Unit directions of the rays leaving the sphere for each element (N, 3)."""
        n = np.sqrt(float(complex(medium.eps[int(medium.region_of(float(z)))]).real))
        lateral = self.points[:, :2] - np.asarray(xy, float)[:2]
        rho = np.hypot(lateral[:, 0], lateral[:, 1])
        slow = RayFan(medium, self.z_el, float(z)).slowness(rho)
        unit = lateral / np.where(rho > 0, rho, 1.0)[:, None]
        t = (slow / n)[:, None] * unit
        return np.c_[t, -np.sqrt(np.clip(1.0 - np.sum(t * t, axis=1), 0.0, None))]


def sphere_backscatter(x: np.ndarray) -> np.ndarray:
    """``i S1(pi) / x``: a sphere's dipole factor straight back along the incident ray
    (``S1(pi) = -S2(pi)``: the polarisation kept), per size parameter ``x``.

    Examples
    --------
    Small: ``3/2 x^2`` (the electric dipole's 1 and the magnetic one's 1/2). Large: 1/2
    in modulus, the echo from the near side, its phase falling by 2 per unit of ``x``
    (a round trip ``a`` shorter than to the centre).

    >>> float(np.round(sphere_backscatter(np.array([1e-3]))[0].real / 1e-6, 6))
    1.5
    """
    return np.array([1j * pec_sphere_amplitudes(xf, np.array([np.pi]))[0][0] / xf
                     for xf in np.atleast_1d(x)])


def sphere_dipoles(E0: np.ndarray, d_i: np.ndarray, d_s: np.ndarray,
                   x: np.ndarray) -> np.ndarray:
    """The dipoles ``(i / x) [S2 (E0 . e_par) e_par_n + S1 (E0 . e_perp_n) e_perp_n]``
    radiating a perfectly conducting sphere's far field along each ``d_s``.

    Parameters
    ----------
    E0 : numpy.ndarray
        (nf, 3) incident field at the sphere.
    d_i : numpy.ndarray
        (3,) the incident direction (unit).
    d_s : numpy.ndarray
        (N, 3) the scattered directions (unit).
    x : numpy.ndarray
        (nf,) size parameters ``k_g a``.

    Returns
    -------
    numpy.ndarray
        (nf, N, 3).

    Examples
    --------
    A small sphere seen sideways, E0 across the scattering plane: ``x^2 E0``
    (``S1 = -i x^3 (1 - cos theta / 2)``).

    >>> p = sphere_dipoles(np.array([[0, 1, 0]]), np.array([0, 0, 1.0]),
    ...                    np.array([[1.0, 0, 0]]), np.array([1e-3]))
    >>> np.round(p.real / 1e-6, 3)
    array([[[0., 1., 0.]]])
    """
    cross = np.cross(d_i[None, :], d_s)
    norm = np.linalg.norm(cross, axis=1)
    # Forward or back along d_i the scattering plane is any plane through d_i
    # (S1 = S2 forward, S1 = -S2 back: the sum does not depend on which).
    spare = np.cross(d_i, [1.0, 0.0, 0.0] if abs(d_i[0]) < 0.9 else [0.0, 1.0, 0.0])
    spare /= np.linalg.norm(spare)
    perp = np.where(norm[:, None] > 1e-9, cross / np.where(norm > 1e-9, norm, 1.0)[:, None],
                    spare[None, :])
    par_i = np.cross(perp, d_i[None, :])
    par_s = np.cross(perp, d_s)
    theta = np.arccos(np.clip(d_s @ d_i, -1.0, 1.0))
    out = np.empty((len(x), len(d_s), 3), complex)
    for f, xf in enumerate(x):
        S1, S2 = pec_sphere_amplitudes(xf, theta)
        c = 1j / xf
        e_par = par_i @ E0[f]
        e_perp = perp @ E0[f]
        out[f] = c * ((S2 * e_par)[:, None] * par_s + (S1 * e_perp)[:, None] * perp)
    return out
