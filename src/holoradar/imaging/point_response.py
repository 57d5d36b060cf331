"""The exact field a compact buried scatterer sends to the elements, and its match.

A point scatterer at ``r = (x0, y0, z)`` in the ground, lit by the incident
field ``E0``, gives every element ``e`` the field ``a * E0(r) * G(r -> e)``
(``G`` the exact layered Green's function, the same Sommerfeld integral
:func:`holoradar.simulate` uses); a scanned transceiver receives
``a * G(e -> r)^2``. ``a`` is the unknown complex scattering amplitude.

The normalised matched filter (the "focus fraction")

    F(eps, r) = |<h, g>|^2 / (||g||^2 ||h||^2),    g = E0 * G  (or G^2),

is the share of the hologram's energy that one scatterer at ``r`` explains
(``a`` fitted by least squares): maximising it over ``r`` and ``eps`` is the
maximum-likelihood fit of one compact object in white noise, and the residual
energy is ``||h||^2 (1 - F)``. At one frequency ``E0(r)`` is a constant for the
one target and cancels in ``F``: only the shape of the wave front across the
aperture carries the ground's permittivity. Across frequencies ``a`` is taken
as common, so ``E0`` and the two-way delay enter, unless the illumination is
unknown (a receiver array without its ``source``), when each frequency keeps its
own amplitude.

For an untilted aperture (every element at one range) ``G`` depends on the
lateral distance and the object's range only. For each trial permittivity it is
computed once on a window of ranges (spacing lambda/8 in the ground) and a
radial grid (lambda/16 in the air), with one quadrature shared by all ranges
(:func:`~holoradar.physics.green.transmitted_profiles`), and interpolated by
4 x 4-point (bicubic Lagrange) interpolation of its amplitude and unwrapped
phase (both smooth on the scale of the wavelength): moving the object costs no
new integral. A point source's incident field is interpolated the same way.

Vector model (a hologram that records a ``polarization`` u, lit by a polarised
source): the scatterer is an isotropic induced dipole (a sphere), and the
element records ``u . G(e <- r) a E0(r) = a (G(r <- e) u) . E0(r)`` by
reciprocity, ``G`` the dyadic Green's function (:mod:`holoradar.physics.dyadic`);
a scanned transceiver along u records ``a v . v`` with ``v = G(r <- e) u``. The
incident field's direction now matters at one frequency too. The five radial
functions of ``G`` are tabulated on the same (range, rho) windows and
interpolated after removing the phase of the first (their common propagation
phase).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..data.hologram import C0, Hologram
from ..data.tx_offset import refuse_tx_offset
from ..physics.dipole import Dipole
from ..physics.dyadic import (
    buried_dipole_dyadic,
    dyadic_from_profiles,
    dyadic_profiles,
    dyadic_times,
)
from ..physics.green import layered_green, transmitted_profiles
from ..physics.medium import Medium
from ..physics.sources import PlaneWave, PointSource, ray_direction
from ..physics.vector_waves import vector_transfer

__all__ = ["PointResponse"]

_RHO_STEPS = 8    # radial samples per wavelength (in air; in the ground for a thin gap): 4-point
#                  Lagrange of the demodulated functions, 3e-8 relative at 9.9 GHz
_Z_STEPS = 8      # range samples per wavelength in the ground
_Z_HALF = 6       # a window holds 2*_Z_HALF + 1 ranges (+- 0.75 wavelength)


class PointResponse:
    """Normalised matched filter of one point scatterer against a hologram.

    Parameters
    ----------
    hologram : Hologram
        One frame, one or several frequencies.
    make_medium : callable
        ``eps' -> Medium``: the ground model for a trial permittivity.
    coherent : bool
        Share one complex amplitude across frequencies (needs the incident field
        or a monostatic hologram); otherwise one amplitude per frequency.
    phase_only : bool
        Match the phases only (the model takes the data's own amplitudes).

    Notes
    -----
    The object may lie anywhere within ``LATERAL_MARGIN`` (metres) of the
    aperture's extent.

    Examples
    --------
    >>> import holoradar as hr
    >>> m = hr.Medium.half_space(0.3, 4.0)
    >>> h = hr.simulate(hr.Scene(m, hr.PlaneWave(), [hr.PointTarget((0.01, 0.0, 0.45))]),
    ...                 hr.Aperture.paper(), 9.9e9, include_surface=False)
    >>> pr = PointResponse(h, lambda e: hr.Medium.half_space(0.3, e), coherent=True)
    >>> round(pr.focus(4.0, 0.45, (0.01, 0.0)), 6)
    1.0
    """

    LATERAL_MARGIN = 0.05
    SOURCE_BAND = 0.12  # half-width (m) of the source's table around ``xy_hint``

    def __init__(self, hologram: Hologram, make_medium: Callable[[float], Medium], *,
                 coherent: bool, phase_only: bool = False) -> None:
        refuse_tx_offset(hologram, "the point response (autofocus, detection's model)")
        self.phase_only = bool(phase_only)
        self.h = hologram.data.reshape(hologram.nf, -1)
        self.energy = float(np.vdot(self.h, self.h).real)
        self.points = hologram.points
        self.ks = 2 * np.pi * hologram.frequencies / C0
        self.monostatic = bool(hologram.monostatic)
        self.source = hologram.source
        self.coherent = bool(coherent)
        self.make_medium = make_medium
        z_el = np.unique(self.points[:, 2])
        self.flat = z_el.size == 1
        self.z_el = float(z_el[0])
        self.integrals = 0  # Sommerfeld integrals evaluated (frequency x eps x range)
        self.responses = 0  # point responses evaluated (each: all elements, all frequencies)
        lo, hi = self.points[:, :2].min(axis=0), self.points[:, :2].max(axis=0)
        self.bounds = (lo - self.LATERAL_MARGIN, hi + self.LATERAL_MARGIN)
        self._rho_max = float(np.hypot(*(hi - lo))) + 2 * self.LATERAL_MARGIN
        self.vector = bool(hologram.is_vector)
        self.pol = np.asarray(hologram.polarization) if self.vector else None
        self.needs_e0 = (not self.monostatic and self.coherent and len(self.ks) > 1)
        if self.vector and not self.monostatic:
            self.needs_e0 = True  # the incident field's direction matters at one frequency
        self._point_source = (self.needs_e0 and isinstance(self.source, PointSource | Dipole)
                              and self.flat)
        if self._point_source:
            s = self.source.position
            far = np.hypot(*np.maximum(abs(self.bounds[0] - s[:2]), abs(self.bounds[1] - s[:2])))
            self._rho_max_src = float(far) + self.LATERAL_MARGIN
        self._windows: dict[float, list[_Window]] = {}
        self.xy_hint: Any = None  # where the object is (x, y): the source's table covers it

    # ------------------------------------------------------------ responses
    def spacing(self, eps: float) -> float:
        """Range spacing of the windows at ``eps`` (lambda/8 in the ground), metres."""
        return 2 * np.pi / (self.ks.max() * np.sqrt(max(eps, 1.0))) / _Z_STEPS

    def scan(self, eps: float, z_lo: float, z_hi: float, xy: Any, *, samples: int = 24,
             coherent: bool | None = None) -> tuple[float, float]:
        """Range in [z_lo, z_hi] with the best focus at ``xy``, and that focus fraction.

        Sampled at :meth:`spacing`, or in ``samples`` steps when that is coarser (a wide
        search only needs a start: the fit then refines the range on a fine window).
        """
        n = int(np.ceil((z_hi - z_lo) / self.spacing(eps)))

        def f(z: float, w: _Window | None = None) -> float:
            return self.match(self.response(eps, z, xy, window=w), coherent=coherent)[0]

        if not self.flat:
            zs = np.linspace(z_lo, z_hi, max(min(n, samples), 2))  # exact, slow: few
            F = [f(z) for z in zs]
        elif n <= 2 * _Z_HALF:
            w = self._window(float(eps), 0.5 * (z_lo + z_hi), z_hi - z_lo)
            zs = w.zs[(w.zs >= z_lo) & (w.zs <= z_hi)]
            zs = zs if zs.size else np.array([0.5 * (z_lo + z_hi)])
            F = [f(z) for z in zs]
        else:
            zs = np.linspace(z_lo, z_hi, samples)
            w = self._compute(float(eps), zs)  # coarse: evaluated at its nodes only
            F = [f(z, w) for z in zs]
        i = int(np.argmax(F))
        return float(zs[i]), float(F[i])

    def _window(self, eps: float, z: float, span: float = 0.0) -> _Window:
        for w in self._windows.get(eps, []):
            if w.holds(z) and w.zs[-1] - w.zs[0] >= span:
                return w
        dz = self.spacing(eps)
        z0 = self.make_medium(float(eps)).z_interfaces[0]
        half = max(_Z_HALF, int(np.ceil(span / 2 / dz)) + 1)
        zs = z + dz * np.arange(-half, half + 1)
        zs = zs - min(0.0, zs[0] - (z0 + dz / 4))  # stay in the ground
        w = self._compute(eps, zs)
        self._windows.setdefault(eps, []).append(w)
        if sum(len(v) for v in self._windows.values()) > 256:  # bound the memory
            self._windows.pop(next(iter(self._windows)))
        return w

    def _compute(self, eps: float, zs: np.ndarray) -> _Window:
        """Green's functions (and a point source's or plane wave's incident field) of
        every frequency on the ranges ``zs`` and a radial grid."""
        medium = self.make_medium(float(eps))
        z0 = medium.z_interfaces[0]
        # At the aperture the field varies laterally on the air's wavelength, unless the
        # air gap is too thin to damp the ground's evanescent waves.
        gap = z0 - self.z_el
        n_lat = 1.0 if gap > 2 * np.pi / self.ks.min() else np.sqrt(max(eps, 1.0))
        rstep = 2 * np.pi / (self.ks.max() * n_lat) / _RHO_STEPS
        grid = np.arange(0.0, self._rho_max + 3 * rstep, rstep)
        if self.vector:
            G = _VGrid(zs, grid, np.stack([dyadic_profiles(float(k), medium, self.z_el, zs, grid)
                                           for k in self.ks]))
        else:
            G = _Grid(zs, grid, np.stack([transmitted_profiles(float(k), medium, self.z_el, zs,
                                                               grid) for k in self.ks]))
        E = None
        if self._point_source and self.vector:
            s = self.source.position
            lo, hi = 0.0, self._rho_max_src
            if self.xy_hint is not None:
                # Only a band of distances from the source around the located object: the
                # fits stay within a few wavelengths of it (outside, the exact field).
                r = float(np.hypot(*(np.asarray(self.xy_hint) - s[:2])))
                lo, hi = max(0.0, r - self.SOURCE_BAND), min(hi, r + self.SOURCE_BAND)
            sgrid = np.arange(max(0.0, lo - 2 * rstep), hi + 3 * rstep, rstep)
            E = _VGrid(zs, sgrid, np.stack([dyadic_profiles(float(k), medium, float(s[2]), zs,
                                                            sgrid) for k in self.ks]))
        elif self._point_source:
            s = self.source.position
            sgrid = np.arange(0.0, self._rho_max_src + 3 * rstep, rstep)
            E = _Grid(zs, sgrid, np.stack([transmitted_profiles(float(k), medium, float(s[2]),
                                                                zs, sgrid) for k in self.ks]))
        elif self.needs_e0 and isinstance(self.source, PlaneWave) and not self.vector:
            # A plane wave: exp(i(p0 x + q0 y)) times a transfer that depends on range only.
            E = np.stack([self.source.field(float(k), medium,
                                            np.c_[np.zeros((zs.size, 2)), zs]) for k in self.ks])
            E = _Grid(zs, np.array([0.0, 1.0, 2.0, 3.0, 4.0]), np.repeat(E[:, :, None], 5, 2))
        self.integrals += len(self.ks) * zs.size * (2 if self._point_source else 1)
        return _Window(zs, G, E, medium)

    def response(self, eps: float, z: float, xy: Any, *, window: _Window | None = None
                 ) -> np.ndarray:
        """``g`` at the elements, shape (nf, N), for a unit scatterer at (x, y, z)."""
        eps, z = float(eps), float(z)
        self.responses += 1
        pos = np.array([[xy[0], xy[1], z]])
        if self.vector:
            return self._vector_response(eps, z, xy, pos, window)
        if self.flat:
            w = window or self._window(eps, z)
            rho = np.hypot(self.points[:, 0] - xy[0], self.points[:, 1] - xy[1])
            G = w.G(z, rho)
            medium = w.medium
        else:
            medium = self.make_medium(eps)
            G = np.stack([layered_green(float(k), medium, pos[0], self.points) for k in self.ks])
            self.integrals += len(self.ks)
        if self.monostatic:
            return G * G
        if not self.needs_e0:
            return G
        if self.flat and isinstance(self.source, PlaneWave):
            p0, q0 = self.source.wavenumbers(1.0)
            E0 = w.E(z, np.array([2.0]))[:, 0] * np.exp(1j * self.ks * (p0 * xy[0] + q0 * xy[1]))
        elif self._point_source:
            s = self.source
            r = np.hypot(xy[0] - s.position[0], xy[1] - s.position[1])
            E0 = s.amplitude * w.E(z, np.array([r]))[:, 0]
            if s.has_pattern:
                E0 = E0 * np.array([s.pattern(ray_direction(float(k), medium, s.position, pos))[0]
                                    for k in self.ks])
        else:
            E0 = np.array([self.source.field(float(k), medium, pos)[0] for k in self.ks])
        return G * E0[:, None]

    def _vector_response(self, eps: float, z: float, xy: Any, pos: np.ndarray,
                         window: _Window | None) -> np.ndarray:
        """``u . G(e <- r) E0(r)`` (or ``v . v``, monostatic) at the elements, (nf, N)."""
        if self.flat:
            w = window or self._window(eps, z)
            off = np.c_[xy[0] - self.points[:, 0], xy[1] - self.points[:, 1]]
            v = dyadic_times(off, w.G(z, np.hypot(off[:, 0], off[:, 1])), self.pol)
            medium = w.medium
        else:
            medium = self.make_medium(eps)
            v = np.stack([np.swapaxes(buried_dipole_dyadic(float(k), medium, pos[0],
                                                           self.points), 1, 2) @ self.pol
                          for k in self.ks])
            self.integrals += len(self.ks)
            w = None
        # v = G(r <- e) u, (nf, N, 3)
        if self.monostatic:
            return np.einsum("fni,fni->fn", v, v)
        return np.einsum("fni,fi->fn", v, self._incident_vector(medium, pos, xy, z, w))

    def _incident_vector(self, medium: Medium, pos: np.ndarray, xy: Any, z: float,
                         w: _Window | None) -> np.ndarray:
        """The incident field vector at the object, (nf, 3)."""
        return self._incident_vectors(medium, np.atleast_2d(np.asarray(xy, float)[:2]), z,
                                      w)[:, 0]

    def _incident_vectors(self, medium: Medium, xy: np.ndarray, z: float,
                          w: _Window | None) -> np.ndarray:
        """The incident field vectors at lateral positions ``xy`` (M, 2) on range ``z``,
        (nf, M, 3): the source's table where it covers them, closed form for a plane
        wave, else the source's exact field."""
        s = self.source
        pts = np.c_[xy, np.full(len(xy), z)]
        if isinstance(s, PlaneWave):
            p0, q0 = s.wavenumbers(1.0)
            out = []
            for k in self.ks:
                v = vector_transfer(float(k), medium, np.array(p0 * k), np.array(q0 * k),
                                    np.array(s.polarization), 0.0, z)
                out.append(v[None, :] * np.exp(1j * k * (xy @ np.array([p0, q0])))[:, None])
            return np.array(out)
        if w is not None and self._point_source:
            off = xy - s.position[:2]
            rho = np.hypot(off[:, 0], off[:, 1])
            if w.E.holds_rho(float(rho.min())) and w.E.holds_rho(float(rho.max())):
                moment = (s.moment if isinstance(s, Dipole) else np.asarray(s.polarization))
                E = s.amplitude * (dyadic_from_profiles(off, w.E(z, rho)) @ moment)
                if isinstance(s, PointSource) and s.pattern_exponent:
                    E = E * np.stack([s.pattern(ray_direction(float(k), medium, s.position,
                                                              pts)) for k in self.ks])[..., None]
                return E
        return np.stack([s.field_vector(float(k), medium, pts) for k in self.ks])

    # ------------------------------------------------------------- matching
    def match(self, g: np.ndarray, *, phase: bool | None = None,
              coherent: bool | None = None) -> tuple[float, np.ndarray]:
        """Focus fraction of ``g`` and the fitted amplitude(s) (one per frequency).

        Phase-only (``phase=True``, default :attr:`phase_only`): the model is the data's
        own amplitude with the phases of ``g``, ``m = a |h| g/|g|`` with ``|a| = 1``;
        ``F = |sum |h|^2 exp(i(arg h - arg g))| / sum |h|^2`` and the residual energy
        ``2 ||h||^2 (1 - F)``.
        """
        coherent = self.coherent if coherent is None else coherent
        if self.phase_only if phase is None else phase:
            u = self.h * np.abs(self.h) * np.exp(-1j * np.angle(g))
            c = u.sum(axis=1)
            if coherent:
                c_all = c.sum()
                a = c_all / abs(c_all) if c_all else 1.0
                return float(abs(c_all) / self.energy), np.full(len(c), a)
            a = np.where(c != 0, c / np.where(c != 0, np.abs(c), 1.0), 1.0)
            return float(np.abs(c).sum() / self.energy), a
        c = np.einsum("fe,fe->f", g.conj(), self.h)
        n = np.einsum("fe,fe->f", g.conj(), g).real
        if coherent:
            a = c.sum() / n.sum()
            return float(abs(c.sum()) ** 2 / n.sum() / self.energy), np.full(len(c), a)
        return float(np.sum(np.abs(c) ** 2 / n) / self.energy), c / n

    def focus(self, eps: float, z: float, xy: Any) -> float:
        """Focus fraction of a scatterer at (x, y, z) in a ground of permittivity eps'."""
        return self.match(self.response(eps, z, xy))[0]

    def model(self, g: np.ndarray, a: np.ndarray, *, phase: bool | None = None) -> np.ndarray:
        """The fitted field: ``a g``, or ``a |h| g/|g|`` when phase-only."""
        if self.phase_only if phase is None else phase:
            return a[:, None] * np.abs(self.h) * np.exp(1j * np.angle(g))
        return a[:, None] * g

    def unmodelled_energy(self, eps: float, z: float, xy: Any, g: np.ndarray,
                          a: np.ndarray) -> float:
        """Energy of what the model knowingly leaves out at a fit (``g`` the response,
        ``a`` its amplitudes): none for a point (a small scatterer's second bounce off
        the surface is ``(k a)^3 / (k d)`` of its own field: negligible)."""
        return 0.0

    def residual(self, eps: float, z: float, xy: Any, *, phase: bool | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Residual ``h - model``, the response ``g`` and the amplitudes ``a``."""
        g = self.response(eps, z, xy)
        _, a = self.match(g, phase=phase)
        return self.h - self.model(g, a, phase=phase), g, a


def require_vector_flat(pr: PointResponse, hologram: Hologram, target: str, *,
                        transceiver: bool) -> None:
    """What the line and sphere models need: the vector model (with a separate source,
    unless ``transceiver``) on an untilted grid; a ValueError naming ``target`` else."""
    if not pr.vector or (pr.monostatic and not transceiver):
        raise ValueError(
            f"target={target!r} needs the vector model"
            f"{'' if transceiver else ' with a separate source'}: a hologram with a "
            "polarization (the recorded field component) and a polarised source (a Dipole, "
            "or a source given a polarization)" + (", or a scanned transceiver"
                                                    if transceiver else ""))
    if not (pr.flat and hologram.pose.is_identity):
        raise ValueError(f"target={target!r} needs an untilted aperture (a tilted one is not "
                         f"modelled for {target}s)")


class _Window:
    def __init__(self, zs: np.ndarray, G: list, E: list | None, medium: Medium) -> None:
        self.zs, self.G, self.E, self.medium = zs, G, E, medium

    def holds(self, z: float) -> bool:
        # The 4-point stencil is clamped inside the grid: valid over its whole span.
        return bool(self.zs[0] <= z <= self.zs[-1])


class _Grid:
    """Complex fields of all frequencies on a uniform (range, rho) grid, interpolated by
    4 x 4-point (bicubic Lagrange) interpolation of amplitude and unwrapped phase."""

    def __init__(self, zs: np.ndarray, rho: np.ndarray, values: np.ndarray) -> None:
        # values: (nf, nz, nrho)
        phase = np.unwrap(np.angle(values), axis=2)
        # Make the rows agree at rho = 0 (unwrap along the range there).
        phase += (np.unwrap(phase[:, :, 0], axis=1) - phase[:, :, 0])[:, :, None]
        self.z0, self.dz = float(zs[0]), float(zs[1] - zs[0])
        self.r0, self.dr = float(rho[0]), float(rho[1] - rho[0])
        self.amp, self.phase = np.abs(values), phase
        self.nz, self.nr = zs.size, rho.size

    # The 4-point Lagrange weights on nodes -1, 0, 1, 2 as cubics in t: [1, t, t^2, t^3] @ C
    # (-t(t-1)(t-2)/6, (t+1)(t-1)(t-2)/2, -(t+1)t(t-2)/2, (t+1)t(t-1)/6), one product.
    _CUBIC = np.array([[0.0, 1.0, 0.0, 0.0], [-1 / 3, -1 / 2, 1.0, -1 / 6],
                       [1 / 2, -1.0, 1 / 2, 0.0], [-1 / 6, 1 / 2, -1 / 2, 1 / 6]])

    @staticmethod
    def _weights(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, float)
        return (t[..., None] ** np.arange(4)) @ _Grid._CUBIC

    def __call__(self, z: float, rho: np.ndarray) -> np.ndarray:
        """Field at range ``z`` and distances ``rho``, shape (nf, len(rho))."""
        u = (z - self.z0) / self.dz
        iz = min(max(int(np.floor(u)), 1), self.nz - 3)
        wz = self._weights(np.array(u - iz))
        v = (np.asarray(rho, float) - self.r0) / self.dr
        ir = np.clip(np.floor(v).astype(int), 1, self.nr - 3)
        wr = self._weights(v - ir)                                   # (N, 4)
        idx = ir[:, None] + np.arange(-1, 3)                         # (N, 4)
        out = []
        for table in (self.amp, self.phase):
            rows = np.tensordot(wz, table[:, iz - 1:iz + 3, :], axes=(0, 1))  # (nf, nrho)
            out.append(np.einsum("fnk,nk->fn", rows[:, idx], wr))
        return out[0] * np.exp(1j * out[1])


class _VGrid:
    """The five radial functions of the dyadic Green's function for all frequencies on a
    uniform (range, rho) grid, values (nf, nz, 5, nrho); interpolated by 4 x 4-point
    Lagrange interpolation of their real and imaginary parts after removing the
    unwrapped phase of the first (which is interpolated too)."""

    def __init__(self, zs: np.ndarray, rho: np.ndarray, values: np.ndarray) -> None:
        phase = np.unwrap(np.angle(values[:, :, 0, :]), axis=2)
        phase += (np.unwrap(phase[:, :, 0], axis=1) - phase[:, :, 0])[:, :, None]
        # The demodulated values, and the phase appended as a sixth (real) row.
        table = values * np.exp(-1j * phase)[:, :, None, :]
        self.table = np.concatenate([table, phase[:, :, None, :].astype(complex)], axis=2)
        self.z0, self.dz = float(zs[0]), float(zs[1] - zs[0])
        self.r0, self.dr = float(rho[0]), float(rho[1] - rho[0])
        self.nz, self.nr = zs.size, rho.size

    def holds_rho(self, rho: float) -> bool:
        """True when ``rho`` lies inside the table (its stencil never reaches beyond)."""
        return self.r0 <= rho <= self.r0 + (self.nr - 2) * self.dr

    def __call__(self, z: float, rho: np.ndarray) -> np.ndarray:
        """Radial functions at range ``z`` and distances ``rho``: (nf, 5, len(rho))."""
        v = (np.asarray(rho, float) - self.r0) / self.dr
        ir = np.clip(np.floor(v).astype(int), 1, self.nr - 3)
        lo, hi = int(ir.min()) - 1, int(ir.max()) + 3   # only the columns in use
        return self.along(self.row(z, lo, hi), rho, lo)

    def row(self, z: float, lo: int = 0, hi: int | None = None) -> np.ndarray:
        """The table interpolated to range ``z`` (columns ``lo:hi``): (nf, 6, n)."""
        u = (z - self.z0) / self.dz
        iz = min(max(int(np.floor(u)), 1), self.nz - 3)
        wz = _Grid._weights(np.array(u - iz))
        return np.tensordot(wz, self.table[:, iz - 1:iz + 3, :, lo:hi], axes=(0, 1))

    def along(self, row: np.ndarray, rho: np.ndarray, lo: int = 0) -> np.ndarray:
        """Radial functions at distances ``rho`` from a :meth:`row` that starts at column
        ``lo``: (nf, 5, len(rho)); four weighted gathers (the 4-point stencil)."""
        v = (np.asarray(rho, float) - self.r0) / self.dr
        ir = np.clip(np.floor(v).astype(int), 1, self.nr - 3)
        wr = _Grid._weights(v - ir)                                   # (N, 4)
        base = ir - 1 - lo
        # Gather whole columns (all frequencies and functions, contiguous) per stencil point.
        cols = np.ascontiguousarray(row.reshape(-1, row.shape[-1]).T)   # (n, nf * 6)
        vals = cols[base] * wr[:, :1]
        for j in (1, 2, 3):
            vals += cols[base + j] * wr[:, j:j + 1]
        vals = vals.T.reshape(row.shape[0], row.shape[1], -1)
        return vals[:, :5] * np.exp(1j * vals[:, 5].real)[:, None, :]
