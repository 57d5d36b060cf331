"""The field a long buried line of induced dipoles sends to the air, asymptotically.

A straight horizontal line at range ``z`` in a layered ground, lit by a source in the
air, carries induced dipoles ``P(s) = alpha E0(r(s)) ds`` (``s`` metres along it); an
element records ``g = ∫ v(s) . P(s) ds`` with ``v(s) = G(r(s) <- e) u`` by reciprocity
(:mod:`holoradar.imaging.line_response`). Two asymptotic steps make this cheap:

Rays through the layers. For a dipole in the air at range ``z_a`` and a point at range
``z`` in the ground, lateral distance ``rho``, the Sommerfeld integral of the
transmitted dyadic (:mod:`holoradar.physics.dyadic`) is, by the 2-D saddle point of its
plane waves, the ray's field

    G u = [tau_h (h . u) h + tau_v a_v q0 (rhat - (p/q_m) zhat)] exp(i k Lc) / (q0 sqrt(D1 D2)),

``p`` the ray's horizontal slowness (sine of its angle in the air) that solves
``rho = sum_j h_j p/q_j``, ``q_j = sqrt(n_j^2 - p^2)`` in each region crossed (``h_j``
its thickness; real ``n_j^2 = Re eps_j`` for the geometry, complex ``eps_j`` in the
phase ``Lc = sum_j h_j q_j + p rho`` and the transfers), ``D1 = sum_j h_j n_j^2/q_j^3 =
d rho/d p`` and ``D2 = sum_j h_j/q_j = rho/p`` the two curvatures of the ray tube,
``tau_h``, ``tau_v`` the products of the interfaces' Fresnel transmissions of the
tangential field (one pass, no reverberation), ``h``, ``rhat`` the horizontal unit
vectors across and along the ray, ``a_v = q0 (rhat . u) - p u_z`` the TM amplitude.
In a homogeneous space it is the far field of ``(I + grad grad/k^2) exp(ikR)/R``.
Lengths are metres, ``k`` the air wavenumber (rad/m), ``z`` the range (down).

Stationary phase along the line. The two rays (source to ``r(s)``, ``r(s)`` to the
element) have the optical path ``L(s) = L_src(s) + L_el(s)``; the integral over ``s``
is dominated by its minimum ``s*`` (where the two rays' slownesses along the line
cancel: Keller's cone, the bistatic specular point), and with the line's finite ends
``s1 < s2``

    g ≈ f(s*) exp(i k Lc(s*)) sqrt(2/(k L''(s*))) (F(u2) - F(u1)),
    F(u) = ∫_0^u exp(i t^2) dt,   u_j = sign(s_j - s*) sqrt(k (L(s_j) - L(s*))),

(the uniform form: the phase at either end is exact, the edges' diffraction
included), ``f`` the product of the two rays' amplitudes and the polarizability. For a
line lit at normal incidence by a plane wave this is the 2-D problem's field (a line
current's cylindrical wave through the layers); a dipole at a finite distance lights
the line with a phase that varies along it, and ``s*`` moves with each element: the
3-D geometry kept exactly, at the cost of one ray pair per element instead of one per
node and element. Accuracy: the rays' leading order (relative corrections
``O(1/(k rho))``, a few % at a few wavelengths), one pass through each interface, and
a quadratic phase around ``s*``. Used to search; the exact finite line
(:class:`~holoradar.imaging.line_response.LineResponse`) finishes the fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._lazy import lazy_module
from .medium import Medium, fresnel

_special = lazy_module("scipy.special")

__all__ = ["RayFan", "line_field", "ray_vector"]

_ANGLES = 384          # rays tabulated per fan (air angles 0 .. 89.5 degrees)
_NEWTON = 3            # bracketed Newton steps for the stationary point on the table ...
_NEWTON_EXACT = 1      # ... then on the exact rays (quadratic: 1e-6 m -> 1e-12 m)


class RayFan:
    """Rays from one range in the air to one range in the ground, through the layers.

    Parameters
    ----------
    medium : Medium
        The ground; ``z_air`` must lie above its surface, ``z`` below.
    z_air, z : float
        Ranges of the two ends, metres.

    Examples
    --------
    >>> fan = RayFan(Medium.half_space(0.3, 4.0), 0.0, 0.4)
    >>> p = fan.slowness(np.array([0.0, 0.3]))
    >>> float(p[0]), round(float(fan.distance(p)[1]), 9)   # the ray reaches 0.3 m aside
    (0.0, 0.3)
    """

    def __init__(self, medium: Medium, z_air: float, z: float) -> None:
        z0 = medium.z_interfaces[0]
        if not z_air < z0 <= z:
            raise ValueError(f"RayFan: the air end ({z_air} m) must lie above the surface "
                             f"({z0} m) and the ground end ({z} m) below it")
        region = int(medium.region_of(float(z)))
        h = [z0 - z_air]
        for m in range(1, region + 1):
            bottom = z if m == region else medium.z_interfaces[m]
            h.append(bottom - medium.top_of(m))
        self.h = np.array(h, float)
        self.eps = np.array([complex(medium.eps[m]) for m in range(region + 1)])
        self.n2 = self.eps.real.copy()
        self.n2[0] = 1.0
        self.eps[0] = 1.0
        # The table: rho(p) for air angles up to 89.5 degrees (rays in the ground stay
        # below its critical angle), rho increasing from 0.
        p = np.sin(np.linspace(0.0, np.radians(89.5), _ANGLES))
        self._p, self._rho = p, self.distance(p)
        self._d1, self._d2, _ = self.tube(p)

    def _q(self, p: np.ndarray) -> np.ndarray:
        """Real vertical slownesses (regions, N)."""
        return np.sqrt(np.maximum(self.n2[:, None] - p[None, :] ** 2, 1e-12))

    def distance(self, p: np.ndarray) -> np.ndarray:
        """Lateral distance (metres) the ray of horizontal slowness ``p`` reaches."""
        return p * np.sum(self.h[:, None] / self._q(np.atleast_1d(p)), axis=0)

    def slowness(self, rho: np.ndarray) -> np.ndarray:
        """Horizontal slowness ``p`` of the ray that reaches lateral distance ``rho``."""
        rho = np.asarray(rho, float)
        p = np.interp(rho, self._rho, self._p)
        # Two Newton steps from the table's linear interpolation (error ~1e-5, then
        # ~1e-10, then below rounding): smooth in rho.
        for _ in range(2):
            q = self._q(p)
            d1 = np.sum(self.h[:, None] * self.n2[:, None] / q**3, axis=0)
            rho_p = p * np.sum(self.h[:, None] / q, axis=0)
            p = np.clip(p + (rho - rho_p) / d1, 0.0, self._p[-1])
        return p

    def lookup(self, rho: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``p``, ``D1`` and ``D2`` at distances ``rho`` from the table (linear
        interpolation: the stationary point's iterations)."""
        return (np.interp(rho, self._rho, self._p), np.interp(rho, self._rho, self._d1),
                np.interp(rho, self._rho, self._d2))

    def tube(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``D1 = d rho/d p``, ``D2 = rho/p`` (metres) and the real vertical path
        ``sum_j h_j q_j`` (metres) of the rays ``p``."""
        q = self._q(p)
        h = self.h[:, None]
        return (np.sum(h * self.n2[:, None] / q**3, axis=0), np.sum(h / q, axis=0),
                np.sum(h * q, axis=0))

    def complex_path(self, p: np.ndarray) -> np.ndarray:
        """``sum_j h_j sqrt(eps_j - p^2)`` (metres, complex: the losses)."""
        qc = np.sqrt(self.eps[:, None] - (p**2)[None, :] + 0j)
        qc = np.where(qc.imag < 0, -qc, qc)
        return np.sum(self.h[:, None] * qc, axis=0)

    def transfers(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """TE and TM transmissions of the tangential field down through every interface
        (one pass), and the complex vertical slowness in the ground end's region."""
        qc = np.sqrt(self.eps[:, None] - (p**2)[None, :] + 0j)
        qc = np.where(qc.imag < 0, -qc, qc)
        th = np.ones(p.shape, complex)
        tv = np.ones(p.shape, complex)
        for j in range(len(self.h) - 1):
            th = th * fresnel(qc[j], qc[j + 1], self.eps[j], self.eps[j + 1], "TE")[1]
            tv = tv * fresnel(qc[j], qc[j + 1], self.eps[j], self.eps[j + 1], "TM")[1]
        return th, tv, qc[-1]


def ray_vector(fan: RayFan, p: np.ndarray, rhat: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The ray's field vector at the ground end, (N, 3), for a dipole ``u`` ((3,) or
    (N, 3)) at the air end, without its phase and spreading: ``tau_h (h . u) h + tau_v
    a_v q0 (rhat - (p/q_m) zhat)``; ``rhat`` (N, 2) the horizontal direction of travel."""
    th, tv, qm = fan.transfers(p)
    u = np.broadcast_to(np.asarray(u, complex), (len(p), 3))
    q0 = np.sqrt(np.maximum(1.0 - p * p, 0.0))
    cx, cy = rhat[:, 0], rhat[:, 1]
    a_h = -cy * u[:, 0] + cx * u[:, 1]
    a_v = q0 * (cx * u[:, 0] + cy * u[:, 1]) - p * u[:, 2]
    tm = tv * a_v * q0
    return np.stack([-th * a_h * cy + tm * cx, th * a_h * cx + tm * cy, -tm * p / qm], axis=1)


@dataclass(frozen=True)
class _Leg:
    """The rays from one air range (a point source, or the elements) to the line."""

    fan: RayFan

    def slope(self, along: np.ndarray, across: np.ndarray, exact: bool = False
              ) -> tuple[np.ndarray, np.ndarray]:
        """``dL/ds`` and ``d2L/ds2`` (1/m) at points ``along`` metres along the line from
        each air point's foot on it, ``across`` (N,) the air points' lateral distance from
        the line; from the table, or ``exact`` (the rays solved)."""
        rho = np.sqrt(along * along + across * across)
        if exact:
            p = self.fan.slowness(rho)
            d1, d2, _ = self.fan.tube(p)
        else:
            p, d1, d2 = self.fan.lookup(rho)
        c = np.divide(along, rho, out=np.zeros(len(rho)), where=rho > 0)
        c2 = c * c
        return p * c, c2 / d1 + (1 - c2) / d2

    def path(self, along: np.ndarray, across: np.ndarray) -> np.ndarray:
        """The real optical path (metres) to the points ``along`` the line."""
        rho = np.sqrt(along * along + across * across)
        p = self.fan.slowness(rho)
        return self.fan.tube(p)[2] + p * rho


def _stationary(legs: tuple[_Leg, _Leg], feet: tuple[np.ndarray, np.ndarray | float],
                across: tuple[np.ndarray, np.ndarray | None], lo: np.ndarray,
                hi: np.ndarray) -> np.ndarray:
    """The minimum ``s*`` of the two legs' path along the line: bracketed Newton in
    ``[lo, hi]`` from the paraxial minimum (each leg's path a parabola about the foot of
    its air point, curvature ``1/D2``). ``feet``: the air points' positions along the
    line; ``across``: their distances from it (``None``: a plane wave, whose slope
    along the line is ``feet[1]``)."""
    (leg_e, leg_s), (s_e, s_s), (d_e, d_s) = legs, feet, across
    w_e = 1 / leg_e.fan.lookup(d_e)[2]
    if d_s is None:
        s = s_e - s_s / w_e
    else:
        w_s = 1 / leg_s.fan.lookup(d_s)[2]
        s = (w_e * s_e + w_s * s_s) / (w_e + w_s)
    s = np.clip(s, lo, hi)
    bracket = (lo, hi)
    # A fixed number of steps (the table's, then the exact rays' for quadratic
    # convergence to ~1e-12 m): s* a smooth function of the line's parameters, as the
    # fit's finite differences need. A step outside the bracket bisects it; the exact
    # steps start from the whole bracket again (the table's signs near the root are not
    # the exact ones).
    for i in range(_NEWTON + _NEWTON_EXACT):
        exact = i >= _NEWTON
        if i == _NEWTON:
            lo, hi = bracket
        g, h = leg_e.slope(s - s_e, d_e, exact)
        if d_s is None:
            g = g + s_s
        else:
            g2, h2 = leg_s.slope(s - s_s, d_s, exact)
            g, h = g + g2, h + h2
        lo = np.where(g < 0, s, lo)
        hi = np.where(g > 0, s, hi)
        step = s - g / h
        s = np.where((step >= lo) & (step <= hi), step, 0.5 * (lo + hi))
    return s


def line_field(ks: np.ndarray, medium: Medium, z: float, elements: np.ndarray,
               u: np.ndarray, centre: np.ndarray, azimuth: float, length: float,
               alpha: tuple[np.ndarray, np.ndarray], source: dict,
               fans: dict | None = None) -> np.ndarray:
    """``g`` (nf, N) of a line of induced dipoles at the elements, asymptotically.

    Parameters
    ----------
    ks : ndarray
        Air wavenumbers, rad/m.
    medium : Medium
    z : float
        The line's range (metres, in the ground).
    elements : ndarray
        (N, 3) element positions (one range, in the air).
    u : ndarray
        (3,) the recorded field component.
    centre : ndarray
        (2,) the line's centre (x, y), metres.
    azimuth, length : float
        Its direction (radians from +x towards +y) and length (metres).
    alpha : (ndarray, ndarray)
        Polarizabilities along and across the axis for each frequency (nf,).
    source : dict
        ``{"kind": "point", "position": (3,), "moment": (3,), "pattern": callable or
        None}`` (amplitude in the moment) or ``{"kind": "plane", "slowness": (2,),
        "polarization": (3,)}``.
    fans : dict, optional
        A cache of :class:`RayFan` by (air range, range).

    Returns
    -------
    ndarray
        (nf, N) complex, the normalisation of
        :class:`~holoradar.imaging.line_response.LineResponse`.
    """
    fans = {} if fans is None else fans

    def fan(z_air: float) -> RayFan:
        key = (float(z_air), float(z))
        if key not in fans:
            if len(fans) > 64:
                fans.pop(next(iter(fans)))
            fans[key] = RayFan(medium, z_air, z)
        return fans[key]

    t = np.array([np.cos(azimuth), np.sin(azimuth)])
    n = np.array([-t[1], t[0]])
    c0 = np.asarray(centre, float)
    el = np.asarray(elements, float)
    leg_e = _Leg(fan(float(el[0, 2])))
    s_e, n_e = (el[:, :2] - c0) @ t, (el[:, :2] - c0) @ n   # each element's foot, offset
    d_e = np.abs(n_e)
    if source["kind"] == "point":
        pos = np.asarray(source["position"], float)
        leg_s = _Leg(fan(float(pos[2])))
        s_s, n_s = float((pos[:2] - c0) @ t), float((pos[:2] - c0) @ n)
        d_s = np.full(len(el), abs(n_s))
        lo, hi = np.minimum(s_e, s_s) - 1e-9, np.maximum(s_e, s_s) + 1e-9
        s_star = _stationary((leg_e, leg_s), (s_e, s_s), (d_e, d_s), lo, hi)
    else:
        leg_s = _Leg(fan(0.0))
        sl = np.asarray(source["slowness"], float)
        span = 10.0 * (1.0 + abs(z))
        s_star = _stationary((leg_e, leg_s), (s_e, float(sl @ t)), (d_e, None),
                             s_e - span, s_e + span)
    # The element's ray at s*: the field at the line of a dipole u at the element.
    fe, fs = leg_e.fan, leg_s.fan
    along_e = s_star - s_e
    rho_e = np.sqrt(along_e**2 + d_e**2)
    p_e = fe.slowness(rho_e)
    rhat_e = _unit(along_e[:, None] * t - n_e[:, None] * n, rho_e)
    d1, d2, vert = fe.tube(p_e)
    c = np.divide(along_e, rho_e, out=np.zeros(len(el)), where=rho_e > 0)
    curv = c * c / d1 + (1 - c * c) / d2                 # L''(s*), 1/m
    v = ray_vector(fe, p_e, rhat_e, u) / (np.sqrt(1 - p_e**2) * np.sqrt(d1 * d2))[:, None]
    L_star = vert + p_e * rho_e
    Lc = fe.complex_path(p_e) + p_e * rho_e
    # The incident field at s*.
    if source["kind"] == "point":
        along_s = s_star - s_s
        rho_s = np.sqrt(along_s**2 + d_s**2)
        p_s = fs.slowness(rho_s)
        rhat_s = _unit(along_s[:, None] * t - n_s * n, rho_s)
        d1, d2, vert = fs.tube(p_s)
        c = np.divide(along_s, rho_s, out=np.zeros(len(el)), where=rho_s > 0)
        curv = curv + c * c / d1 + (1 - c * c) / d2
        E0 = ray_vector(fs, p_s, rhat_s, source["moment"])
        E0 /= (np.sqrt(1 - p_s**2) * np.sqrt(d1 * d2))[:, None]
        if source.get("pattern") is not None:
            dirs = np.c_[p_s[:, None] * rhat_s, np.sqrt(1 - p_s**2)]
            E0 *= source["pattern"](dirs)[:, None]
        L_star = L_star + vert + p_s * rho_s
        Lc = Lc + fs.complex_path(p_s) + p_s * rho_s
    else:
        p0 = float(np.hypot(*sl))
        rhat = _unit(sl[None, :], np.array([p0]))
        E0 = ray_vector(fs, np.array([p0]), rhat, source["polarization"])
        lateral = (c0 + s_star[:, None] * t) @ sl
        L_star = L_star + lateral
        Lc = Lc + fs.complex_path(np.array([p0])) + lateral
    # Polarizability: along t t^T + across (I - t t^T), one dot product each.
    t3 = np.array([t[0], t[1], 0.0])
    vt, et = v @ t3, E0 @ t3
    a1 = vt * et
    a2 = np.einsum("ni,ni->n", v, np.broadcast_to(E0, v.shape)) - a1
    # The line integral: stationary phase with the ends' exact phases (uniform form).
    du = []
    for s_end in (-0.5 * length, 0.5 * length):
        L_end = leg_e.path(s_end - s_e, d_e)
        if source["kind"] == "point":     # one ray from the source to each end
            L_end = L_end + float(leg_s.path(np.array([s_end - s_s]), d_s[:1])[0])
        else:
            L_end = L_end + float((c0 + s_end * t) @ sl)
        du.append(np.sign(s_end - s_star) * np.sqrt(np.maximum(L_end - L_star, 0.0)))
    k = np.asarray(ks, float)[:, None]
    sk = np.sqrt(k)
    S2, C2 = _special.fresnel(du[1][None, :] * (sk * np.sqrt(2 / np.pi)))
    S1, C1 = _special.fresnel(du[0][None, :] * (sk * np.sqrt(2 / np.pi)))
    span = (C2 - C1) + 1j * (S2 - S1)
    amp = np.sqrt(np.pi / curv)[None, :] / sk
    along, across = (np.asarray(a, complex)[:, None] for a in alpha)
    return (along * a1 + across * a2) * _phases(k[:, 0], Lc) * (amp * span)


def _phases(k: np.ndarray, Lc: np.ndarray) -> np.ndarray:
    """``exp(i k Lc)`` (nf, N); for uniformly stepped ``k`` by the recurrence
    ``exp(i k_(f+1) Lc) = exp(i k_f Lc) exp(i dk Lc)`` (a product instead of an
    exponential per sample; rounding grows by 1e-16 a step)."""
    dk = np.diff(k)
    if k.size < 3 or np.ptp(dk) > 1e-9 * abs(dk[0]):
        return np.exp(1j * k[:, None] * Lc[None, :])
    out = np.empty((k.size, Lc.size), complex)
    out[0] = np.exp(1j * k[0] * Lc)
    out[1:] = np.exp(1j * dk[0] * Lc)
    return np.cumprod(out, axis=0)


def _unit(off: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """Unit vectors of ``off`` (N, 2); +x where ``rho`` is 0."""
    out = np.zeros_like(off)
    out[:, 0] = 1.0
    nz = rho > 0
    out[nz] = off[nz] / rho[nz, None]
    return out
