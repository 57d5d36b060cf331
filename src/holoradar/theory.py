"""Closed-form theory of holographic imaging (docs/imaging.md): ``holoradar.theory``.

All lengths in metres, frequencies in Hz, angles in radians, wavenumbers in
rad/m. Apertures are FULL widths A, B (half-widths a = A/2, b = B/2).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ._lazy import lazy_module
from ._validate import as_real, check_frequency
from .data.hologram import C0
from .physics.medium import check_eps
from .physics.medium import fresnel as _interface_fresnel

# Imported on first use (holoradar._lazy): `import holoradar` should cost little more
# than numpy.
_opt = lazy_module("scipy.optimize")
_special = lazy_module("scipy.special")

__all__ = [
    "SpectralWindow",
    "apparent_distance",
    "attenuation",
    "focal_shift",
    "fresnel_coefficients",
    "fresnel_number",
    "lateral_resolution",
    "longitudinal_resolution",
    "max_monostatic_pitch",
    "max_unaliased_angle",
    "range_resolution",
    "refractive_index",
    "spectral_window",
    "unambiguous_range",
    "wavelength",
    "wavenumber",
]


def _positive(**kw: float) -> list[float]:
    """Check that each named length or angle is a finite number > 0."""
    return [as_real(v, k, positive=True) for k, v in kw.items()]


def wavelength(frequency: float, eps: complex = 1.0) -> float:
    """Wavelength ``c/(f*Re(n))`` in a medium of permittivity ``eps``, metres.

    Examples
    --------
    >>> round(wavelength(9.9e9), 5), round(wavelength(9.9e9, 9.0), 5)
    (0.03028, 0.01009)
    """
    return C0 / (check_frequency(frequency) * refractive_index(eps).real)


def wavenumber(frequency: float) -> float:
    """Wavenumber in air ``2*pi*f/c``, rad/m.

    Examples
    --------
    >>> round(wavenumber(9.9e9), 2)
    207.49
    """
    return 2 * np.pi * check_frequency(frequency) / C0


def refractive_index(eps: complex) -> complex:
    """``n = sqrt(eps)`` with ``Im(n) >= 0``.

    Examples
    --------
    >>> refractive_index(9.0)
    (3+0j)
    """
    n = complex(np.sqrt(check_eps(eps, "eps")))
    return -n if n.imag < 0 else n


@dataclass(frozen=True)
class SpectralWindow:
    """The rectangle of object spatial frequencies a finite aperture records.

    Attributes
    ----------
    mu, nu : float
        Half-widths ``k*a/L``, ``k*b/L`` (rad/m).
    p0, q0 : float
        Transverse wavenumbers of the illumination, ``k*sin(alpha0)``, ``k*sin(beta0)``.

    Notes
    -----
    In the frame of the reflected field ``f*E0`` (the hologram's own frame) the
    window is ``|p| <= mu, |q| <= nu``. Since ``E0 = exp(i*(p0*x + q0*y))``
    shifts the object's spectrum to ``F(p - p0, q - q0)``, the object's own
    spectrum (incident phase removed) is seen over ``|p + p0| <= mu``,
    ``|q + q0| <= nu``: the window centred at :attr:`center` = ``(-p0, -q0)``
    (with ``F = ∫ f exp(-i(px + qy))``).
    """

    mu: float
    nu: float
    p0: float = 0.0
    q0: float = 0.0

    @property
    def center(self) -> tuple[float, float]:
        """Centre in the object-spectrum frame, ``(-p0, -q0)``."""
        return -self.p0, -self.q0

    @property
    def p_range(self) -> tuple[float, float]:
        """``(-mu - p0, mu - p0)``: the object frequencies seen along p."""
        return -self.mu - self.p0, self.mu - self.p0

    @property
    def q_range(self) -> tuple[float, float]:
        """``(-nu - q0, nu - q0)``."""
        return -self.nu - self.q0, self.nu - self.q0

    def contains(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """True where the object frequency (p, q) is recorded."""
        return (np.abs(np.asarray(p) + self.p0) <= self.mu) & (
            np.abs(np.asarray(q) + self.q0) <= self.nu)


def spectral_window(frequency: float, aperture: float, distance: float, *,
                    aperture_y: float | None = None, alpha0: float = 0.0,
                    beta0: float = 0.0) -> SpectralWindow:
    """Spectral window of an aperture of full widths (A, B) focused at ``distance``.

    ``mu = k*A/(2*L)``, ``nu = k*B/(2*L)`` (paper Eqs. 5-7); pass the
    apparent distance for a buried object.

    Examples
    --------
    >>> w = spectral_window(9.9e9, 0.40, 0.60)
    >>> round(np.pi / w.mu, 4)    # = lateral resolution lambda*L/A
    0.0454
    """
    k = wavenumber(frequency)
    B = aperture if aperture_y is None else aperture_y
    _positive(aperture=aperture, aperture_y=B, distance=distance)
    return SpectralWindow(k * aperture / (2 * distance), k * B / (2 * distance),
                          k * np.sin(alpha0), k * np.sin(beta0))


def lateral_resolution(wavelength: float, distance: float, aperture: float) -> float:
    """``delta = lambda*L/A`` (first null of the sinc, paper section 3.1).

    Examples
    --------
    >>> round(lateral_resolution(0.03, 0.60, 0.40), 4)   # the paper's check
    0.045
    """
    _positive(wavelength=wavelength, distance=distance, aperture=aperture)
    return wavelength * distance / aperture


def _fresnel_amplitude(w: np.ndarray | float) -> np.ndarray:
    """|∫_{-a}^{a} exp(i*psi*x^2) dx| / (2a) as a function of w = a*sqrt(2*psi/pi)."""
    w = np.asarray(w, float)
    S, C = _special.fresnel(w)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(w > 0, np.hypot(C, S) / np.where(w > 0, w, 1), 1.0)


def longitudinal_resolution(wavelength: float, distance: float, aperture: float, *,
                            aperture_y: float | None = None) -> float:
    """Depth resolution of a monochromatic hologram: FWHM of the on-axis intensity, metres.

    A defocus dz multiplies the aperture field by ``exp(i*psi*(x^2 + y^2))`` with
    ``psi = k*dz/(2*L^2)`` (paraxial). For a rectangular aperture the on-axis
    amplitude factorises into two Fresnel integrals, ``A(w) = |C(w) + i S(w)|/w``
    with ``w = a*sqrt(2*psi/pi)``; the intensity ``(A(w_x) A(w_y))^2`` falls to half
    at a defocus found here by root finding. For a square aperture the result is
    ``FWHM = 4*w_h^2*lambda*(L/A)^2`` with ``A(w_h)^4 = 1/2``, ``w_h = 1.1145``, i.e.
    ``4.97*lambda*(L/A)^2``: a half-width of ``2.48*lambda*(L/A)^2`` against the
    quarter-wave estimate ``2*lambda*(L/A)^2``.

    Examples
    --------
    >>> round(longitudinal_resolution(0.03, 0.60, 0.40), 3)
    0.335
    """
    B = aperture if aperture_y is None else aperture_y
    _positive(wavelength=wavelength, distance=distance, aperture=aperture, aperture_y=B)
    a, b = aperture / 2, B / 2

    def half(dz: float) -> float:
        psi = np.pi * dz / (wavelength * distance**2)  # k*dz/(2 L^2)
        wx = a * np.sqrt(2 * psi / np.pi)
        wy = b * np.sqrt(2 * psi / np.pi)
        return float((_fresnel_amplitude(wx) * _fresnel_amplitude(wy)) ** 2 - 0.5)

    hi = 8 * wavelength * (distance / min(a, b)) ** 2
    return 2 * _opt.brentq(half, 1e-12 * hi, hi)


def focal_shift(wavelength: float, distance: float, aperture: float, *,
                aperture_y: float | None = None) -> float:
    """Shift of the on-axis intensity peak of a migrated point image, metres (negative: nearer).

    The back-propagation kernel carries a ``1/z`` amplitude, so the on-axis
    amplitude is ``(1/z) * A(w_x(z)) * A(w_y(z))`` with the defocus
    ``psi = (k/2)*(1/L - 1/z)``; its maximum lies slightly nearer than L when the
    Fresnel number ``a^2/(lambda*L)`` is small (Li & Wolf's focal shift). For a
    buried point, pass the apparent distance and multiply the result by Re(n).

    Examples
    --------
    >>> round(focal_shift(0.0303, 0.376, 0.40), 4)    # paper array, L in sand
    -0.0159
    """
    B = aperture if aperture_y is None else aperture_y
    _positive(wavelength=wavelength, distance=distance, aperture=aperture, aperture_y=B)
    a, b = aperture / 2, B / 2
    k = 2 * np.pi / wavelength

    def neg_amp(z: float) -> float:
        psi = abs(0.5 * k * (1 / distance - 1 / z))
        s = np.sqrt(2 * psi / np.pi)
        return -float(_fresnel_amplitude(a * s) * _fresnel_amplitude(b * s) / z)

    span = longitudinal_resolution(wavelength, distance, aperture, aperture_y=aperture_y)
    res = _opt.minimize_scalar(neg_amp,
                               bounds=(max(distance - span, distance / 4), distance + 1e-9),
                               method="bounded", options={"xatol": 1e-7})
    return float(res.x - distance)


def fresnel_number(aperture: float, wavelength: float, distance: float) -> float:
    """``N_F = a^2/(lambda*L)`` with the half-width a = A/2.

    Examples
    --------
    >>> round(fresnel_number(0.40, 0.0303, 0.376), 2)
    3.51
    """
    _positive(aperture=aperture, wavelength=wavelength, distance=distance)
    return (aperture / 2) ** 2 / (wavelength * distance)


def apparent_distance(distance: float, z_surface: float, eps: complex) -> float:
    """``L = z0 + (l - z0)/Re(n)`` for an object at range l below a surface at z0.

    Examples
    --------
    >>> round(apparent_distance(0.50, 0.30, 9.0), 4)    # the paper's Fig. 12 geometry
    0.3667
    """
    _positive(distance=distance, z_surface=z_surface)
    if distance <= z_surface:
        return float(distance)
    return float(z_surface + (distance - z_surface) / refractive_index(eps).real)


def fresnel_coefficients(eps1: complex, eps2: complex, theta: float = 0.0) -> dict[str, complex]:
    """Fresnel amplitude coefficients from medium 1 into medium 2.

    Parameters
    ----------
    eps1, eps2 : complex
        Relative permittivities (incidence from 1).
    theta : float
        Angle of incidence in medium 1, radians.

    Returns
    -------
    dict
        ``r_te, t_te, r_tm, t_tm``: TE (E parallel to the interface) and TM, both
        for the electric field TANGENTIAL to the interface, the scalar field of
        :class:`~holoradar.Medium` (these are its own coefficients,
        :func:`holoradar.physics.medium.fresnel`). So ``t = 1 + r`` for both;
        ``r_tm`` is the negative of the magnetic-field r_p, and ``t_tm`` is the
        total-field ``t_p`` times ``cos(theta2)/cos(theta1)``. At normal incidence
        ``r = (n1 - n2)/(n1 + n2)``, ``t = 2 n1/(n1 + n2)``: from air into ground
        V = (1 - n)/(1 + n), W = 2/(1 + n).

    Examples
    --------
    >>> c = fresnel_coefficients(1.0, 9.0)
    >>> complex(c["r_te"]), complex(c["t_te"])
    ((-0.5+0j), (0.5+0j))
    """
    n1 = refractive_index(eps1)
    refractive_index(eps2)
    theta = as_real(theta, "theta")
    if not 0 <= theta < np.pi / 2:
        raise ValueError(f"theta must be an angle of incidence in [0, pi/2) radians, got {theta}")
    # kz / k on either side (k cancels in the coefficients).
    kap2 = (n1 * np.sin(theta)) ** 2
    c1 = np.sqrt(complex(eps1) - kap2)
    c2 = np.sqrt(complex(eps2) - kap2)
    c1, c2 = (-c if c.imag < 0 else c for c in (c1, c2))
    r_te, t_te = _interface_fresnel(c1, c2, complex(eps1), complex(eps2), "TE")
    r_tm, t_tm = _interface_fresnel(c1, c2, complex(eps1), complex(eps2), "TM")
    return {"r_te": complex(r_te), "t_te": complex(t_te), "r_tm": complex(r_tm),
            "t_tm": complex(t_tm)}


def attenuation(eps: complex, frequency: float, distance: float) -> dict[str, float]:
    """One-way amplitude decay ``exp(-k*Im(n)*d)`` over ``distance`` in a lossy medium.

    Returns ``{"factor": ..., "dB": ..., "skin_depth": 1/(k*Im(n))}``.

    Examples
    --------
    >>> round(float(attenuation(2.5 + 0.0125j, 9.9e9, 0.24)["dB"]), 3)   # sand, 12 cm both ways
    -1.71
    """
    n = refractive_index(eps)
    k = wavenumber(frequency)
    distance = as_real(distance, "distance", nonnegative=True)
    factor = float(np.exp(-k * n.imag * distance))
    skin = float(np.inf if n.imag == 0 else 1 / (k * n.imag))
    return {"factor": factor, "dB": float(20 * np.log10(factor)), "skin_depth": skin}


def max_unaliased_angle(pitch: float, wavelength: float) -> float:
    """Largest arrival angle ``arcsin(lambda/(2*s))`` sampled without aliasing, radians.

    Examples
    --------
    >>> round(float(np.degrees(max_unaliased_angle(0.025, 0.0303))), 1)   # paper's array
    37.3
    """
    _positive(pitch=pitch, wavelength=wavelength)
    return float(np.arcsin(min(1.0, wavelength / (2 * pitch))))


def _two_way_factor(monostatic: bool, incidence: float) -> float:
    """``1 + cos(theta_i)`` (array geometry, illumination at theta_i in the medium) or 2."""
    if monostatic:
        return 2.0
    theta = as_real(incidence, "incidence")
    if not 0 <= theta < np.pi / 2:
        raise ValueError(f"incidence must be an angle in [0, pi/2) radians, got {theta}")
    return 1.0 + float(np.cos(theta))


def range_resolution(bandwidth: float, eps: complex = 1.0, *, monostatic: bool = True,
                     incidence: float = 0.0) -> float:
    """Range (depth) resolution of a wideband hologram: first null of the range response, metres.

    A band of width ``B`` spans the vertical wavenumbers of the image over
    ``dKz = (2*pi*B/c) * Re(n) * f2``, with ``f2 = 2`` for a monostatic transceiver
    (the wave goes down and up along the same ray) and ``f2 = 1 + cos(theta_i)``
    for a receiver array lit by a wave travelling at ``theta_i`` from the vertical
    in the medium (down along the illumination, up to the array). A flat spectrum
    over ``dKz`` images a point as ``sin(dKz*z/2)/(dKz*z/2)``, whose first null is at
    ``2*pi/dKz``: ``c/(2*B*Re(n))`` (monostatic, or normal illumination).

    Parameters
    ----------
    bandwidth : float
        ``f_max - f_min``, Hz.
    eps : complex
        Permittivity of the medium holding the object.
    monostatic : bool
        Scanned transceiver (default) or array geometry.
    incidence : float
        Array geometry: angle of the illumination from the vertical in the medium,
        radians.

    Examples
    --------
    >>> round(range_resolution(4e9), 4)                 # 4 GHz in air: 3.7 cm
    0.0375
    >>> round(range_resolution(4e9, 6.0), 4)            # in eps 6
    0.0153
    """
    _positive(bandwidth=bandwidth)
    n = refractive_index(eps).real
    return C0 / (bandwidth * n * _two_way_factor(monostatic, incidence))


def unambiguous_range(frequency_step: float, eps: complex = 1.0, *, monostatic: bool = True,
                      incidence: float = 0.0) -> float:
    """Range over which a stepped-frequency image does not repeat, metres.

    Frequencies ``df`` apart sample the range response every
    ``dKz = (2*pi*df/c) * Re(n) * f2`` (see :func:`range_resolution`); the image is
    periodic in range with period ``2*pi/dKz = c/(f2*df*Re(n))``: objects farther
    apart in range than that alias onto each other (``c/(2*df)`` monostatic in air).

    Examples
    --------
    >>> round(unambiguous_range(400e6), 4)              # 11 frequencies over 4 GHz
    0.3747
    """
    _positive(frequency_step=frequency_step)
    n = refractive_index(eps).real
    return C0 / (frequency_step * n * _two_way_factor(monostatic, incidence))


def max_monostatic_pitch(frequency_max: float) -> float:
    """Largest scan step of a monostatic transceiver for an unaliased full aperture, metres.

    The round trip doubles the transverse wavenumbers: a wave returning from
    angle theta carries ``2*k*sin(theta)``, up to ``2*k``; the step ``s`` samples up
    to ``pi/s``, so the whole half-space of angles needs ``s <= lambda_min/4``
    (against ``lambda/2`` for a receiver array lit by a separate source).

    Examples
    --------
    >>> round(max_monostatic_pitch(11e9) * 1000, 2)    # mm
    6.81
    """
    return C0 / check_frequency(frequency_max) / 4


def resolution_cells(hologram: Any, medium: Any, z: float) -> tuple[float, float]:
    """``(lateral, range)``: a hologram's resolution cells at range ``z``, metres.

    The one place detection, inversion and the fits take their cells from. Lateral:
    :func:`lateral_resolution` ``lambda L / A`` at the centre frequency, ``L`` the
    apparent distance through ``medium`` (None: free space), ``A`` the shorter side
    of the aperture. Range: across a band :func:`range_resolution` ``c / (2 B n)``
    (``B = f_max - f_min``, ``n`` the index of the layer at ``z``; the round trip of
    a transceiver, or an array lit at normal incidence); one frequency's depth of
    focus ``4.97 lambda (L / A)^2`` (:func:`longitudinal_resolution` of a square
    aperture).

    Examples
    --------
    >>> import holoradar as hr
    >>> h = hr.Hologram(np.zeros((3, 16, 16), complex), np.arange(16) * 0.01,
    ...                 np.arange(16) * 0.01, np.array([9e9, 10e9, 11e9]))
    >>> lat, rng = resolution_cells(h, hr.Medium.half_space(0.1, 4.0), 0.2)

    3 cm at 10 GHz, 15 cm apparent (10 cm of air, 10 cm of eps 4), a 16 cm
    aperture; 2 GHz in n = 2:

    >>> round(lat, 4), round(rng, 4)
    (0.0281, 0.0375)
    """
    A = max(min(hologram.aperture_size), 1e-9)
    L = medium.apparent_distance(z) if medium is not None else z
    f = hologram.frequencies
    lateral = lateral_resolution(C0 / float(np.mean(f)), max(L, 1e-12), A)
    if f.size > 1:
        eps = complex(medium.eps[int(medium.region_of(z))]) if medium is not None else 1.0
        return lateral, float(range_resolution(float(np.ptp(f)), eps))
    return lateral, 4.97 * C0 / float(f[0]) * (L / A) ** 2
