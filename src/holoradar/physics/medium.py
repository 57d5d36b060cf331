"""Horizontally layered media seen from an aperture in air.

Conventions (docs/conventions.md): time dependence ``exp(-i*omega*t)``; ``z`` is
range from the aperture plane (z = 0) towards the scene, in metres; complex
relative permittivity ``eps = eps' * (1 + i*tan_delta)`` with ``Im(eps) >= 0`` for
loss; refractive index ``n = sqrt(eps)`` with ``Im(n) >= 0``; vertical wavenumber
``kz = sqrt(k^2*eps - p^2 - q^2)`` with ``Im(kz) >= 0``.

Region 0 (``0 <= z < z_interfaces[0]``) is air and holds the aperture; region j
lies between ``z_interfaces[j-1]`` and ``z_interfaces[j]`` and the last one extends
to infinity. A point exactly on an interface belongs to the deeper region.

Plane-wave transmission across each interface uses the Fresnel coefficient of the
chosen polarisation (TE by default, i.e. the electric field parallel to the
interface, the scalar model of the paper); multiple reflections inside a layer
are neglected in transmission (first-order, as in the paper's Eqs. 8-11), while
the specular reflection of the whole stack (:meth:`Medium.reflection`) sums them.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validate import check_frequency

__all__ = ["Medium", "permittivity"]

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


def _check_eps(eps: complex, name: str) -> complex:
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
        if any(not np.isfinite(z) or z <= 0 for z in zi):
            raise ValueError("z_interfaces must be finite ranges > 0 m from the aperture "
                             f"(the aperture lies in air), got {self.z_interfaces}")
        if any(b <= a for a, b in itertools.pairwise(zi)):
            raise ValueError(f"z_interfaces must be strictly increasing, got {zi}")
        eps = tuple(_check_eps(e, f"eps[{i}]") for i, e in enumerate(np.atleast_1d(self.eps)))
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
        return cls((z,), (1.0, _check_eps(eps, "eps")), polarization)

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
        return cls(zi, (1.0, *ep), polarization)

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

    def region_of(self, z: float | np.ndarray) -> np.ndarray | int:
        """Index of the region that contains range ``z`` (interfaces belong below).

        Examples
        --------
        >>> Medium.half_space(0.3, 2.5).region_of(np.array([0.1, 0.3, 0.5]))
        array([0, 1, 1])
        """
        idx = np.searchsorted(np.asarray(self.z_interfaces), z, side="right")
        return int(idx) if np.ndim(idx) == 0 else idx

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
        kz = np.sqrt(k * k * complex(self.eps[region]) - np.asarray(kappa2, dtype=complex))
        return np.where(kz.imag < 0, -kz, kz)

    # ------------------------------------------------------------ interface laws
    def transmission(self, kz_from: np.ndarray, kz_to: np.ndarray, eps_from: complex,
                     eps_to: complex) -> np.ndarray:
        """Fresnel transmission of the field amplitude across one interface.

        TE: ``2 kz1 / (kz1 + kz2)``; TM (electric-field amplitude):
        ``2 n1 n2 kz1 / (eps2 kz1 + eps1 kz2)``. Both give ``2 n1/(n1 + n2)`` at
        normal incidence.
        """
        if self.polarization == "TE":
            return 2 * kz_from / (kz_from + kz_to)
        n1, n2 = np.sqrt(complex(eps_from)), np.sqrt(complex(eps_to))
        return 2 * n1 * n2 * kz_from / (eps_to * kz_from + eps_from * kz_to)

    def fresnel_reflection(self, kz_from: np.ndarray, kz_to: np.ndarray, eps_from: complex,
                           eps_to: complex) -> np.ndarray:
        """Fresnel reflection of the field amplitude at one interface.

        TE: ``(kz1 - kz2)/(kz1 + kz2)``; TM: ``(eps1 kz2 - eps2 kz1)/(eps2 kz1 + eps1 kz2)``,
        signed as the tangential electric field (the negative of the usual
        magnetic-field r_p), so that both give ``(n1 - n2)/(n1 + n2)`` at normal
        incidence, as the scalar field of this model requires.
        """
        if self.polarization == "TE":
            return (kz_from - kz_to) / (kz_from + kz_to)
        return (eps_from * kz_to - eps_to * kz_from) / (eps_to * kz_from + eps_from * kz_to)

    # ------------------------------------------------------------ stack transfer
    def vertical_transfer(self, k: float, kappa2: np.ndarray, z_from: float,
                          z_to: float) -> np.ndarray:
        """Plane-wave transfer of each angular component from range ``z_from`` to ``z_to``.

        A component of amplitude 1 at ``z_from`` arrives at ``z_to`` with this factor:
        ``exp(i*kz_m*h_m)`` over the thickness ``h_m`` crossed in every region m,
        times the Fresnel transmission of every interface crossed, in the direction
        of travel (down when ``z_to > z_from``, up otherwise). In free space it is
        ``exp(i*kz*|z_to - z_from|)``. Evanescent components decay.

        Parameters
        ----------
        k : float
            Wavenumber in air, rad/m.
        kappa2 : ndarray
            ``p^2 + q^2`` of the components, rad^2/m^2.
        z_from, z_to : float
            Ranges from the aperture plane, metres.

        Examples
        --------
        >>> m = Medium.half_space(0.3, 4.0)
        >>> t = m.vertical_transfer(200.0, np.array([0.0]), 0.4, 0.0)
        >>> np.round(abs(t), 6)   # 2n/(1+n) for n = 2
        array([1.333333])
        """
        kappa2 = np.asarray(kappa2, dtype=float)
        lo, hi = min(z_from, z_to), max(z_from, z_to)
        down = z_to >= z_from
        j_lo, j_hi = self.region_of(lo), self.region_of(hi)
        total = np.ones(np.shape(kappa2), dtype=complex)
        kz_prev = None
        for m in range(j_lo, j_hi + 1):
            kz_m = self.kz(k, kappa2, m)
            top = lo if m == j_lo else self.top_of(m)
            bottom = hi if m == j_hi else self.z_interfaces[m]
            total *= np.exp(1j * kz_m * (bottom - top))
            if kz_prev is not None:
                if down:
                    total *= self.transmission(kz_prev, kz_m, self.eps[m - 1], self.eps[m])
                else:
                    total *= self.transmission(kz_m, kz_prev, self.eps[m], self.eps[m - 1])
            kz_prev = kz_m
        return total

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
        nreg = self.n_regions
        if nreg == 1:
            return np.zeros(np.shape(kappa2), dtype=complex)
        kzs = [self.kz(k, kappa2, m) for m in range(nreg)]
        r = np.zeros(np.shape(kappa2), dtype=complex)
        for m in range(nreg - 2, -1, -1):
            r_m = self.fresnel_reflection(kzs[m], kzs[m + 1], self.eps[m], self.eps[m + 1])
            if m + 1 < nreg - 1:
                h = self.z_interfaces[m + 1] - self.z_interfaces[m]
                ph = np.exp(2j * kzs[m + 1] * h)
                r = (r_m + r * ph) / (1 + r_m * r * ph)
            else:
                r = r_m
        return r

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

        For a half-space: ``L = z0 + (z - z0)/n`` (PHYSICS.md section 6).
        """
        return float(sum(h / self.n(m).real for m, h in self.crossings(z)))

    def optical_path(self, z: float) -> complex:
        """Normal-incidence optical path ``sum n_j h_j`` from the aperture to ``z`` (metres)."""
        return complex(sum(self.n(m) * h for m, h in self.crossings(z)))
