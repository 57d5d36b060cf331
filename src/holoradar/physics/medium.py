"""Horizontally layered media seen from an aperture in air.

Conventions (docs/conventions.md): time dependence ``exp(-i*omega*t)``; ``z`` is
range from the aperture plane (z = 0) towards the scene, in metres; complex
relative permittivity ``eps = eps' * (1 + i*tan_delta)`` with ``Im(eps) >= 0`` for
loss; refractive index ``n = sqrt(eps)`` with ``Im(n) >= 0``; vertical wavenumber
``kz = sqrt(k^2*eps - p^2 - q^2)`` with ``Im(kz) >= 0``.

Region 0 (``0 <= z < z_interfaces[0]``) is air and holds the aperture; region j
lies between ``z_interfaces[j-1]`` and ``z_interfaces[j]`` and the last one extends
to infinity. A point exactly on an interface belongs to the deeper region.

The scalar field is the electric field tangential to the interfaces: TE (the
default; E parallel to the interfaces, the paper's scalar model) or TM (the
tangential component of an E field in the plane of incidence). Plane waves cross
the stack exactly: every component is carried with the Fresnel coefficients of
every interface and all the multiple reflections inside the layers (Parratt's
recursion for the reflection, generalised transmission coefficients for the
transmission), in both directions.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal, NamedTuple

import numpy as np

from .._validate import check_frequency

__all__ = ["Medium", "fresnel", "permittivity"]

Polarization = Literal["TE", "TM"]


def permittivity(eps_real: float, tan_delta: float = 0.0, *, sigma: float | None = None,
                 frequency: float | None = None) -> complex:
    """Complex relative permittivity of a lossy medium.

    Parameters
    ----------
    eps_real : float
        Real part eps' of the relative permittivity.
    tan_delta : float, optional
        Loss tangent; gives ``eps = eps' * (1 + i*tan_delta)``.
    sigma : float, optional
        Conductivity in S/m; adds ``i*sigma/(omega*eps0)`` (needs ``frequency``).
    frequency : float, optional
        Frequency in Hz, required with ``sigma``.

    Returns
    -------
    complex
        ``eps`` with ``Im(eps) >= 0`` (loss under the ``exp(-i*omega*t)`` convention).

    Examples
    --------
    >>> permittivity(2.5, 0.005)
    (2.5+0.0125j)
    """
    if tan_delta < 0:
        raise ValueError(f"tan_delta must be >= 0 (a loss tangent), got {tan_delta}")
    eps = complex(eps_real) * (1 + 1j * tan_delta)
    if sigma is not None:
        if sigma < 0:
            raise ValueError(f"sigma must be >= 0 S/m, got {sigma}")
        f = check_frequency(frequency if frequency is not None else -1.0, "frequency")
        eps += 1j * sigma / (2 * np.pi * f * 8.8541878128e-12)
    return eps


def fresnel(kz1: np.ndarray, kz2: np.ndarray, eps1: complex, eps2: complex,
            polarization: Polarization = "TE") -> tuple[np.ndarray, np.ndarray]:
    """Fresnel reflection and transmission of the tangential electric field, from 1 into 2.

    Parameters
    ----------
    kz1, kz2 : ndarray
        Vertical wavenumbers ``sqrt(k^2*eps_j - kappa^2)`` (``Im >= 0``) on either
        side, rad/m.
    eps1, eps2 : complex
        Relative permittivities.
    polarization : {"TE", "TM"}

    Returns
    -------
    r, t : ndarray
        TE: ``r = (kz1 - kz2)/(kz1 + kz2)``. TM, signed as the tangential electric
        field (the negative of the magnetic-field ``r_p``):
        ``r = (eps1 kz2 - eps2 kz1)/(eps2 kz1 + eps1 kz2)``. For both, the tangential
        field is continuous, so ``t = 1 + r``; at normal incidence
        ``r = (n1 - n2)/(n1 + n2)`` and ``t = 2 n1/(n1 + n2)``. Power balance
        across a lossless interface: ``|r|^2 + Y2/Y1 |t|^2 = 1`` with the admittance
        ``Y = kz`` (TE) or ``Y = eps/kz`` (TM). Where both kz vanish (grazing
        incidence on an index-matched interface) there is no interface: ``r = 0``.

    Examples
    --------
    >>> r, t = fresnel(np.array(1.0), np.array(2.0), 1.0, 4.0)
    >>> np.round([r, t], 4)
    array([-0.3333+0.j,  0.6667+0.j])
    """
    kz1 = np.asarray(kz1, dtype=complex)
    kz2 = np.asarray(kz2, dtype=complex)
    if polarization == "TE":
        num, den = kz1 - kz2, kz1 + kz2
    else:
        num, den = eps1 * kz2 - eps2 * kz1, eps2 * kz1 + eps1 * kz2
    r = np.divide(num, den, out=np.zeros(np.broadcast(num, den).shape, complex),
                  where=den != 0)
    return r, 1 + r


class _Stack(NamedTuple):
    kzs: list[np.ndarray]                            # kz of every region
    rt: list[tuple[np.ndarray, np.ndarray]]          # (r, t) down across interface j
    rho: list[np.ndarray]                            # reflection below interface j


def ground_permittivity_problem(eps: Any) -> str | None:
    """Why ``eps`` cannot be a ground's permittivity as a user gave it, or None.

    No ground is optically thinner than air, and a negative real part is a metal
    or a plasma, not soil: both are far likelier slips (a sign, a loss tangent
    or a conductivity typed in the permittivity's place) than the intended
    medium. The real part is judged first: a sign slip also turns the loss of
    ``eps' (1 + i tan_delta)`` negative, and the sign is the cause to name.

    This is the one check of a permittivity that a user typed: the scene
    files, ``--eps``, ``--layers`` and ``--medium`` and :meth:`Medium.half_space`,
    :meth:`Medium.layered` all use it, so a slip reads the same wherever it is
    made. The bare constructor ``Medium(...)`` (used by fits that explore
    trial values) does not refuse these values.

    Parameters
    ----------
    eps : complex
        The permittivity as given (before a loss tangent or conductivity is
        added).

    Returns
    -------
    str or None
        A sentence starting with the value (the caller puts the argument's
        name before it), or None for a plausible ground.

    Examples
    --------
    >>> print(ground_permittivity_problem(-2.5))  # doctest: +ELLIPSIS
    -2.5 has a negative real part: a sign slip? ...
    >>> ground_permittivity_problem(2.5 + 0.0125j) is None
    True
    """
    try:
        e = complex(eps)
    except (TypeError, ValueError):
        return f"{eps!r} is not a complex relative permittivity (e.g. sand 2.5+0.0125j)"
    if not (np.isfinite(e.real) and np.isfinite(e.imag)):
        return f"{eps!r} is not finite"
    shown = f"{e.real:g}" if e.imag == 0 else f"{e.real:g}{e.imag:+g}j"
    if e.real < 0:
        return (f"{shown} has a negative real part: a sign slip? holoradar's permittivities "
                "are eps' + i*eps'' with eps' >= 1 and loss as a positive imaginary part "
                "(e.g. sand 2.5+0.0125j)")
    if e.real < 1:
        return (f"{shown} has a real part below 1 (air): no soil, rock or concrete has one; "
                "was a loss tangent or a conductivity given in the permittivity's place? "
                "(e.g. sand 2.5+0.0125j)")
    if e.imag < 0:
        return (f"{shown} has a negative imaginary part, a medium with gain: loss is a "
                "positive imaginary part under exp(-i*omega*t) (e.g. sand 2.5+0.0125j)")
    return None


def check_ground_permittivity(eps: complex, name: str = "eps") -> complex:
    """A ground permittivity a user gave, as a complex number; ``ValueError`` naming
    ``name`` and the likely slip (:func:`ground_permittivity_problem`) otherwise.

    Examples
    --------
    >>> check_ground_permittivity(-2.5)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: eps = -2.5 has a negative real part: a sign slip? ...
    """
    problem = ground_permittivity_problem(eps)
    if problem is not None:
        raise ValueError(f"{name} = {problem}")
    return complex(eps)


def check_eps(eps: complex, name: str) -> complex:
    try:
        e = complex(eps)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a complex relative permittivity, got {eps!r}") from None
    if not np.isfinite(e.real) or not np.isfinite(e.imag):
        raise ValueError(f"{name} must be finite, got {eps!r}")
    if e.imag < 0:
        raise ValueError(f"{name} must have Im(eps) >= 0 (loss under exp(-i*omega*t)); "
                         f"Im(eps) < 0 would be a medium with gain, got {e}")
    if e == 0:
        raise ValueError(f"{name} must be non-zero")
    return e


@dataclass(frozen=True)
class Medium:
    """A stack of horizontal layers below an air gap holding the aperture.

    Build it with :meth:`free_space`, :meth:`half_space` or :meth:`layered`.

    Attributes
    ----------
    z_interfaces : tuple of float
        Ranges of the interfaces from the aperture plane, metres, increasing, > 0.
    eps : tuple of complex
        Relative permittivity of each region, air first: ``len(eps) ==
        len(z_interfaces) + 1`` and ``eps[0] == 1``.
    polarization : {"TE", "TM"}
        Which Fresnel coefficients the scalar model uses (default TE).
    """

    z_interfaces: tuple[float, ...] = ()
    eps: tuple[complex, ...] = (1.0 + 0j,)
    polarization: Polarization = "TE"

    def __post_init__(self) -> None:
        try:
            zi = tuple(float(z) for z in np.atleast_1d(np.asarray(self.z_interfaces, float)))
        except (TypeError, ValueError):
            raise ValueError("z_interfaces must be ranges in metres (numbers > 0), got "
                             f"{self.z_interfaces!r}") from None
        # The first interface may be at 0: the antennas on the ground (ground-coupled),
        # the aperture in the air just above the surface.
        if any(not np.isfinite(z) or z < 0 for z in zi):
            raise ValueError("z_interfaces must be finite ranges >= 0 m from the aperture "
                             "(the aperture lies in air, on the surface at 0 at the "
                             f"deepest), got {self.z_interfaces}")
        if any(b <= a for a, b in itertools.pairwise(zi)):
            raise ValueError(f"z_interfaces must be strictly increasing, got {zi}")
        eps = tuple(check_eps(e, f"eps[{i}]") for i, e in enumerate(np.atleast_1d(self.eps)))
        if len(eps) != len(zi) + 1:
            raise ValueError(f"eps must hold one permittivity per region ({len(zi) + 1}), got "
                             f"{len(eps)}")
        if eps[0] != 1:
            raise ValueError(f"eps[0] is the air holding the aperture and must be 1, got {eps[0]}")
        if self.polarization not in ("TE", "TM"):
            raise ValueError(f"polarization must be 'TE' or 'TM', got {self.polarization!r}")
        object.__setattr__(self, "z_interfaces", zi)
        object.__setattr__(self, "eps", eps)

    # ----------------------------------------------------------------- builders
    @classmethod
    def free_space(cls) -> Medium:
        """Air everywhere.

        Examples
        --------
        >>> Medium.free_space().is_free_space
        True
        """
        return cls()

    @classmethod
    def half_space(cls, z_surface: float, eps: complex, *,
                   polarization: Polarization = "TE") -> Medium:
        """Air for ``0 <= z < z_surface``, a uniform medium of permittivity ``eps`` beyond.

        Parameters
        ----------
        z_surface : float
            Range of the ground surface from the aperture plane, metres (> 0).
        eps : complex
            Complex relative permittivity of the ground (``Im(eps) >= 0``).

        Examples
        --------
        >>> sand = Medium.half_space(0.30, 2.5 + 0.0125j)
        >>> round(sand.apparent_distance(0.42), 4)
        0.3759
        """
        try:
            z = float(z_surface)
        except (TypeError, ValueError):
            raise ValueError(f"z_surface must be a range in metres > 0, got {z_surface!r}") \
                from None
        return cls((z,), (1.0, check_ground_permittivity(eps, "eps")), polarization)

    @classmethod
    def layered(cls, z_interfaces: Sequence[float], eps: Sequence[complex], *,
                polarization: Polarization = "TE") -> Medium:
        """A stack of layers: ``eps[j]`` fills ``z_interfaces[j] <= z < z_interfaces[j+1]``.

        Parameters
        ----------
        z_interfaces : sequence of float
            Ranges of the interfaces from the aperture, metres, strictly increasing.
        eps : sequence of complex
            Permittivity below each interface (same length as ``z_interfaces``);
            the last layer extends to infinite range. Air above the first interface.

        Examples
        --------
        >>> road = Medium.layered([0.30, 0.38], [4.0 + 0.2j, 9.0 + 0.9j])
        >>> round(road.n(2).real, 3)
        3.004
        """
        zi = tuple(np.atleast_1d(np.asarray(z_interfaces, dtype=float)))
        ep = tuple(np.atleast_1d(np.asarray(eps, dtype=complex)))
        if len(zi) != len(ep):
            raise ValueError(f"eps must have one value per interface ({len(zi)}), got {len(ep)}")
        ep = tuple(check_ground_permittivity(e, f"eps[{j}]") for j, e in enumerate(ep))
        return cls(zi, (1.0, *ep), polarization)

    @classmethod
    def graded(cls, z_surface: float, eps: Any, depth: float, *, step: float | None = None,
               polarization: Polarization = "TE") -> Medium:
        """A smoothly stratified ground: permittivity varying with depth, as thin layers.

        Below the surface at ``z_surface`` the permittivity follows ``eps`` down to
        ``depth`` below the surface, then stays at its last value. The profile is
        sampled at the middle of layers ``step`` thick, and the result is an
        ordinary layered :class:`Medium`: every propagator treats it exactly
        (transmission, reflections, reverberations), and the parabolic-equation
        propagator (:class:`~holoradar.physics.parabolic.ParabolicEquation`) steps
        through the same profile.

        Parameters
        ----------
        z_surface : float
            Range of the surface from the aperture, metres (> 0).
        eps : callable or (array_like, array_like)
            ``eps(d)`` of the depth ``d`` below the surface (metres, array in,
            complex array out), or samples ``(depths, values)`` with depths
            increasing from 0, interpolated linearly (real and imaginary parts).
            Every value a ground permittivity: eps' >= 1, Im(eps) >= 0.
        depth : float
            Depth of the graded part, metres (> 0).
        step : float, optional
            Layer thickness, metres; default ``depth / 200``. It must resolve the
            profile: not larger than the spacing of the given samples.
        polarization : {"TE", "TM"}

        Examples
        --------
        >>> wet = Medium.graded(0.30, lambda d: 3.0 + 20.0 * d, 0.30, step=0.01)
        >>> len(wet.z_interfaces), round(wet.eps[1].real, 6), round(wet.eps[-1].real, 6)
        (30, 3.1, 8.9)
        """
        try:
            z0, dep = float(z_surface), float(depth)
        except (TypeError, ValueError):
            raise ValueError("z_surface and depth must be metres (numbers > 0), got "
                             f"{z_surface!r}, {depth!r}") from None
        if not (np.isfinite(z0) and z0 > 0 and np.isfinite(dep) and dep > 0):
            raise ValueError(f"z_surface and depth must be metres > 0, got {z0}, {dep}")
        h = dep / 200 if step is None else float(step)
        if not (np.isfinite(h) and 0 < h <= dep):
            raise ValueError(f"step must be a thickness in metres, 0 < step <= depth ({dep}), "
                             f"got {step!r}")
        n = int(np.ceil(dep / h - 1e-9))
        mids = (np.arange(n) + 0.5) * (dep / n)
        if callable(eps):
            try:
                values = np.broadcast_to(np.asarray(eps(mids), complex), mids.shape)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"eps(depth) must return permittivities for an array of "
                                 f"depths ({exc})") from None
        else:
            try:
                dz, ev = (np.asarray(v) for v in eps)
                dz = dz.astype(float)
                ev = ev.astype(complex)
            except (TypeError, ValueError):
                raise ValueError("eps must be a function of depth or samples (depths, "
                                 "values)") from None
            if dz.ndim != 1 or dz.shape != ev.shape or dz.size < 2 or np.any(np.diff(dz) <= 0) \
                    or dz[0] != 0:
                raise ValueError("eps samples must be (depths, values) of one length >= 2, "
                                 "depths increasing from 0 m")
            if h > float(np.min(np.diff(dz))) * (1 + 1e-9):
                raise ValueError(f"step {h} m is larger than the profile's sample spacing "
                                 f"{float(np.min(np.diff(dz)))} m: it would skip its detail")
            values = (np.interp(mids, dz, ev.real) + 1j * np.interp(mids, dz, ev.imag))
        ep = [check_ground_permittivity(v, f"eps at depth {d:.4g} m")
              for d, v in zip(mids, values, strict=True)]
        tops = z0 + np.arange(n) * (dep / n)
        return cls(tuple(float(t) for t in tops), (1.0, *ep), polarization)

    # --------------------------------------------------------------- properties
    @property
    def is_free_space(self) -> bool:
        """True when there is no interface."""
        return len(self.z_interfaces) == 0

    @property
    def n_regions(self) -> int:
        """Number of regions, air included."""
        return len(self.eps)

    def n(self, region: int) -> complex:
        """Refractive index ``sqrt(eps)`` of a region, ``Im(n) >= 0``."""
        n = complex(np.sqrt(complex(self.eps[region])))
        return -n if n.imag < 0 else n

    @property
    def is_lossless(self) -> bool:
        """True when no region absorbs (every permittivity real)."""
        return all(complex(e).imag == 0 for e in self.eps)

    def region_of(self, z: float | np.ndarray) -> np.ndarray | int:
        """Index of the region that contains range ``z`` (interfaces belong below).

        Examples
        --------
        >>> Medium.half_space(0.3, 2.5).region_of(np.array([0.1, 0.3, 0.5]))
        array([0, 1, 1])
        """
        idx = np.searchsorted(np.asarray(self.z_interfaces), z, side="right")
        return int(idx) if np.ndim(idx) == 0 else idx

    def on_surface(self, z: float) -> bool:
        """Whether range ``z`` is the ground's surface itself (antennas on the ground:
        the aperture just above it, in the air).

        Examples
        --------
        >>> Medium.half_space(0.0, 6.0).on_surface(0.0)
        True
        """
        return bool(self.z_interfaces) and float(z) == self.z_interfaces[0]

    def top_of(self, region: int) -> float:
        """Range of the upper boundary of a region (0 for the air)."""
        return 0.0 if region == 0 else self.z_interfaces[region - 1]

    def kz(self, k: float, kappa2: np.ndarray | float, region: int) -> np.ndarray:
        """Vertical wavenumber ``sqrt(k^2*eps - kappa^2)`` in a region, ``Im >= 0`` (rad/m).

        Examples
        --------
        >>> Medium.free_space().kz(1.0, np.array([0.0, 4.0]), 0).round(4)   # evanescent: +i
        array([1.+0.j    , 0.+1.7321j])
        """
        eps = complex(self.eps[region])
        if eps.imag == 0:
            # Lossless: a real square root (travelling) or +i times one (evanescent),
            # several times faster than the complex one.
            a = k * k * eps.real - np.asarray(kappa2, dtype=float)
            r = np.sqrt(np.abs(a))
            kz = np.empty(np.shape(a), dtype=complex)
            kz.real = np.where(a >= 0, r, 0.0)
            kz.imag = np.where(a >= 0, 0.0, r)
            return kz
        kz = np.sqrt(k * k * eps - np.asarray(kappa2, dtype=complex))
        return np.where(kz.imag < 0, -kz, kz)

    # ------------------------------------------------------------ interface laws
    def transmission(self, kz_from: np.ndarray, kz_to: np.ndarray, eps_from: complex,
                     eps_to: complex) -> np.ndarray:
        """Fresnel transmission of the tangential electric field across one interface.

        ``1 + r`` for either polarisation (the tangential field is continuous):
        TE ``2 kz1 / (kz1 + kz2)``, TM ``2 eps1 kz2 / (eps2 kz1 + eps1 kz2)``; both
        ``2 n1/(n1 + n2)`` at normal incidence. See :func:`fresnel`.
        """
        return fresnel(kz_from, kz_to, eps_from, eps_to, self.polarization)[1]

    def fresnel_reflection(self, kz_from: np.ndarray, kz_to: np.ndarray, eps_from: complex,
                           eps_to: complex) -> np.ndarray:
        """Fresnel reflection of the tangential electric field at one interface.

        TE ``(kz1 - kz2)/(kz1 + kz2)``; TM ``(eps1 kz2 - eps2 kz1)/(eps2 kz1 + eps1 kz2)``
        (the negative of the usual magnetic-field r_p); both ``(n1 - n2)/(n1 + n2)``
        at normal incidence. See :func:`fresnel`.
        """
        return fresnel(kz_from, kz_to, eps_from, eps_to, self.polarization)[0]

    # ------------------------------------------------------------ stack transfer
    def _interfaces(self, k: float, kappa2: np.ndarray) -> _Stack:
        """Vertical wavenumbers, local coefficients and Parratt ratios of the stack."""
        kzs = [self.kz(k, kappa2, m) for m in range(self.n_regions)]
        rt = [fresnel(kzs[j], kzs[j + 1], self.eps[j], self.eps[j + 1], self.polarization)
              for j in range(self.n_regions - 1)]
        # rho[j]: up/down amplitude ratio just above interface j (the reflection of
        # everything below it), by Parratt's recursion from the bottom half-space up;
        # only exp(2i kz h) with Im(kz) >= 0 appears, so thick lossy layers and
        # evanescent waves cannot overflow.
        rho: list[np.ndarray] = [np.zeros(np.shape(kappa2), complex)] * (self.n_regions - 1)
        gamma = np.zeros(np.shape(kappa2), complex)  # ratio at the top of region j + 1
        for j in range(self.n_regions - 2, -1, -1):
            r = rt[j][0]
            rho[j] = (r + gamma) / (1 + r * gamma)
            if j >= 1:
                gamma = rho[j] * np.exp(2j * kzs[j] * self._thickness(j))
        return _Stack(kzs, rt, rho)

    def _thickness(self, region: int) -> float:
        return self.z_interfaces[region] - self.top_of(region)

    def _down_into(self, st: _Stack, region: int) -> np.ndarray:
        """Down-going amplitude at the top of ``region`` for amplitude 1 down-going in the
        air at the surface, with every multiple reflection (the generalised transmission)."""
        amp = np.ones(np.shape(st.kzs[0]), complex)
        for j in range(region):
            if j >= 1:
                amp = amp * np.exp(1j * st.kzs[j] * self._thickness(j))
            below = (st.rho[j + 1] * np.exp(2j * st.kzs[j + 1] * self._thickness(j + 1))
                     if j + 1 < self.n_regions - 1 else 0.0)
            r, t = st.rt[j]
            amp = amp * t / (1 + r * below)
        return amp

    def _field_in(self, st: _Stack, region: int, z: float) -> np.ndarray:
        """Total field at range ``z`` inside ``region`` for amplitude 1 down-going at the
        surface: the down-going wave plus its reflection from the layers below."""
        top = self.top_of(region)
        field = np.exp(1j * st.kzs[region] * (z - top))
        if region < self.n_regions - 1:
            bottom = self.z_interfaces[region]
            field = field + st.rho[region] * np.exp(1j * st.kzs[region] * (2 * bottom - top - z))
        return self._down_into(st, region) * field

    def _up_from(self, st: _Stack, region: int, z: float) -> np.ndarray:
        """Up-going amplitude in the air at the surface radiated by a source at range ``z``
        in ``region`` emitting amplitude 1 both up and down (a point source's plane waves).

        In the source's layer the waves bounce between the stack above (generalised
        reflection ``R_up``) and the one below (``rho``); the emerging wave then crosses
        the layers above with their own multiple reflections.
        """
        kz = st.kzs[region]
        top = self.top_of(region)
        d1 = z - top
        # Generalised reflection (looking up) and transmission (to the air) of the stack
        # above each region, built from the surface down.
        R_up = np.zeros(np.shape(kz), complex)
        T_up = np.ones(np.shape(kz), complex)
        for m in range(1, region + 1):
            r_dn, t_dn = st.rt[m - 1]  # from m - 1 down into m
            r_m = -r_dn                 # from m up into m - 1: r is odd, t = 1 + r
            t_m = 1 + r_m
            if m == 1:
                R_up, T_up = r_m, t_m
                continue
            ph = np.exp(1j * st.kzs[m - 1] * self._thickness(m - 1))
            den = 1 - R_up * r_dn * ph * ph
            T_up = T_up * t_m * ph / den
            R_up = r_m + t_dn * t_m * R_up * ph * ph / den
        u = np.ones(np.shape(kz), complex)
        if region < self.n_regions - 1:
            d2 = self.z_interfaces[region] - z
            e1, e2 = np.exp(2j * kz * d1), np.exp(2j * kz * d2)
            u = (1 + st.rho[region] * e2) / (1 - R_up * st.rho[region] * e1 * e2)
        return u * np.exp(1j * kz * d1) * T_up

    def vertical_transfer(self, k: float, kappa2: np.ndarray, z_from: float,
                          z_to: float) -> np.ndarray:
        """Exact plane-wave transfer of each angular component from range ``z_from`` to ``z_to``.

        One end must lie in the air that holds the aperture (region 0).

        * Down (``z_from`` in the air, ``z_to >= z_from``): the field at ``z_to`` of a
          component of amplitude 1 travelling down at ``z_from``. In the ground it is
          the wave transmitted through every interface above ``z_to`` with all the
          multiple reflections inside the layers, plus its reflection from the
          layers below ``z_to`` (the total field there); in the air it is the direct
          wave ``exp(i*kz0*(z_to - z_from))`` (the ground's reflection is
          :meth:`reflection`).
        * Up (``z_to`` in the air, ``z_from >= z_to``): the up-going field at ``z_to``
          radiated by a source at ``z_from`` that emits amplitude 1 both up and down,
          as each plane wave of a point source does (Weyl's expansion). Its
          down-going half returns from the layers below, and the waves reverberate
          in every layer, all summed exactly. By reciprocity it equals the down
          transfer times ``kz_s/kz_0`` (TE) or ``eps_s kz_0/(eps_0 kz_s)`` (TM).

        In free space it is ``exp(i*kz*|z_to - z_from|)``. Evanescent components
        decay; the recursion involves only decaying exponentials, so it is stable
        for thick lossy layers.

        Parameters
        ----------
        k : float
            Wavenumber in air, rad/m.
        kappa2 : ndarray
            ``p^2 + q^2`` of the components, rad^2/m^2.
        z_from, z_to : float
            Ranges from the aperture plane, metres.

        Raises
        ------
        ValueError
            When neither end lies in the air.

        Examples
        --------
        >>> m = Medium.half_space(0.3, 4.0)
        >>> t = m.vertical_transfer(200.0, np.array([0.0]), 0.4, 0.0)
        >>> np.round(abs(t), 6)   # 2n/(1+n) for n = 2
        array([1.333333])
        """
        kappa2 = np.asarray(kappa2, dtype=float)
        z_from, z_to = float(z_from), float(z_to)
        down = z_to >= z_from
        z_air, z_far = (z_from, z_to) if down else (z_to, z_from)
        if self.region_of(z_air) != 0 and not self.on_surface(z_air):
            raise ValueError("vertical_transfer needs one end in the air above the surface "
                             f"(range < {self.z_interfaces[0]} m), got z_from={z_from}, "
                             f"z_to={z_to}")
        region = self.region_of(z_far)
        kz0 = self.kz(k, kappa2, 0)
        if region == 0:
            return np.exp(1j * kz0 * (z_far - z_air))
        st = self._interfaces(k, kappa2)
        air = np.exp(1j * kz0 * (self.z_interfaces[0] - z_air))
        if down:
            return air * self._field_in(st, region, z_far)
        return air * self._up_from(st, region, z_far)

    def seen_from(self, height: float) -> Medium:
        """The same layers seen from a level plane at world range ``height`` in the air:
        every interface's range less ``height`` (metres), so that ranges from that
        plane come out.

        Examples
        --------
        >>> Medium.half_space(0.3, 4.0).seen_from(0.1).z_interfaces
        (0.19999999999999998,)
        """
        if height == 0.0 or self.is_free_space:
            return self
        return Medium(tuple(z - height for z in self.z_interfaces), self.eps,
                      self.polarization)

    def with_polarization(self, polarization: Polarization) -> Medium:
        """The same stack with the other Fresnel law (``"TE"`` or ``"TM"``).

        Examples
        --------
        >>> Medium.half_space(0.3, 4.0).with_polarization("TM").polarization
        'TM'
        """
        if polarization == self.polarization:
            return self
        return Medium(self.z_interfaces, self.eps, polarization)

    def transfer_parts(self, k: float, kappa2: np.ndarray, z_from: float,
                       z_to: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`vertical_transfer` down from the air, split into its down- and up-going parts.

        At ``z_to`` inside a ground layer the total tangential field is the wave
        transmitted down plus its reflection from the layers below; a vector
        model needs them apart (the vertical electric field of a TM wave changes
        sign with the direction of travel). In the air (above the surface) and in
        the deepest region the up-going part is zero.

        Returns
        -------
        down, up : ndarray
            Same shape as ``kappa2``; ``down + up == vertical_transfer(...)``.

        Examples
        --------
        >>> m = Medium.layered([0.3, 0.35], [4.0, 9.0])
        >>> k2 = np.array([0.0, 1e4])
        >>> d, u = m.transfer_parts(200.0, k2, 0.0, 0.32)
        >>> bool(np.allclose(d + u, m.vertical_transfer(200.0, k2, 0.0, 0.32)))
        True
        """
        kappa2 = np.asarray(kappa2, dtype=float)
        z_from, z_to = float(z_from), float(z_to)
        if self.region_of(z_from) != 0 or z_to < z_from:
            raise ValueError("transfer_parts goes down from the air: z_from must lie above the "
                             f"surface and z_to below it, got {z_from}, {z_to}")
        region = self.region_of(z_to)
        kz0 = self.kz(k, kappa2, 0)
        if region == 0:
            return np.exp(1j * kz0 * (z_to - z_from)), np.zeros(kappa2.shape, complex)
        st = self._interfaces(k, kappa2)
        amp = np.exp(1j * kz0 * (self.z_interfaces[0] - z_from)) * self._down_into(st, region)
        top = self.top_of(region)
        kz = st.kzs[region]
        down = amp * np.exp(1j * kz * (z_to - top))
        if region < self.n_regions - 1:
            bottom = self.z_interfaces[region]
            up = amp * st.rho[region] * np.exp(1j * kz * (2 * bottom - top - z_to))
        else:
            up = np.zeros(kappa2.shape, complex)
        return down, up

    def vertical_transfers(self, k: float, kappa2: np.ndarray, z_from: float,
                           z_to: np.ndarray) -> np.ndarray:
        """:meth:`vertical_transfer` down from ``z_from`` in the air to many ranges at once.

        The stack's coefficients are computed once for all the ranges ``z_to``
        (each >= ``z_from``); returns shape ``(len(z_to),) + kappa2.shape``.

        Examples
        --------
        >>> m = Medium.half_space(0.3, 4.0)
        >>> k2 = np.array([0.0, 900.0])
        >>> t = m.vertical_transfers(200.0, k2, 0.0, np.array([0.2, 0.4]))
        >>> bool(np.allclose(t[1], m.vertical_transfer(200.0, k2, 0.0, 0.4)))
        True
        """
        kappa2 = np.asarray(kappa2, dtype=float)
        z_to = np.atleast_1d(np.asarray(z_to, dtype=float))
        if self.region_of(float(z_from)) != 0 or np.any(z_to < z_from):
            raise ValueError("vertical_transfers goes down from the air: z_from must lie above "
                             f"the surface and every z_to below z_from, got {z_from}, {z_to}")
        out = np.empty(z_to.shape + kappa2.shape, complex)
        regions = np.atleast_1d(self.region_of(z_to))
        kz0 = self.kz(k, kappa2, 0)
        st = self._interfaces(k, kappa2) if np.any(regions > 0) else None
        for region in np.unique(regions):
            sel = np.nonzero(regions == region)[0]
            dz = z_to[sel].reshape((-1,) + (1,) * kappa2.ndim)
            if region == 0:
                out[sel] = np.exp(1j * kz0 * (dz - z_from))
                continue
            air = np.exp(1j * kz0 * (self.z_interfaces[0] - z_from)) * self._down_into(st, region)
            top = self.top_of(region)
            kz = st.kzs[region]
            field = np.exp(1j * kz * (dz - top))
            if region < self.n_regions - 1:
                bottom = self.z_interfaces[region]
                field = field + st.rho[region] * np.exp(1j * kz * (2 * bottom - top - dz))
            out[sel] = air * field
        return out

    def reflection(self, k: float, kappa2: np.ndarray) -> np.ndarray:
        """Reflection coefficient of the whole stack seen from the air at the surface.

        The recursion (Parratt) sums the multiple reflections inside the layers;
        the phase reference is the top interface. Free space gives 0.

        Examples
        --------
        >>> complex(Medium.half_space(0.3, 9.0).reflection(200.0, np.array(0.0)))  # (1-n)/(1+n)
        (-0.5+0j)
        """
        kappa2 = np.asarray(kappa2, dtype=float)
        if self.n_regions == 1:
            return np.zeros(np.shape(kappa2), dtype=complex)
        return self._interfaces(k, kappa2).rho[0]

    def crossings(self, z: float) -> list[tuple[int, float]]:
        """``(region, thickness)`` of every region crossed from the aperture plane to ``z``.

        Examples
        --------
        >>> [(m, round(h, 6)) for m, h in Medium.half_space(0.3, 2.5).crossings(0.42)]
        [(0, 0.3), (1, 0.12)]
        """
        j = self.region_of(z)
        out = []
        for m in range(j + 1):
            top = self.top_of(m)
            bottom = z if m == j else self.z_interfaces[m]
            if bottom > top:
                out.append((m, bottom - top))
        return out

    def apparent_distance(self, z: float) -> float:
        """Paraxial apparent range ``L = sum of layer thicknesses / Re(n)`` down to ``z``.

        For a half-space: ``L = z0 + (z - z0)/n`` (the paper's section 3.2).
        """
        return float(sum(h / self.n(m).real for m, h in self.crossings(z)))

    def optical_path(self, z: float) -> complex:
        """Normal-incidence optical path ``sum n_j h_j`` from the aperture to ``z`` (metres)."""
        return complex(sum(self.n(m) * h for m, h in self.crossings(z)))


#: Air everywhere, shared (a Medium is immutable): what a function with ``medium=None``
#: works in, without building a new one at every call.
FREE_SPACE: Medium = Medium()
