"""Electric-dipole fields through the layered stack: the dyadic Green's function.

Normalisation. In a homogeneous region of permittivity eps (``k_m = k*sqrt(eps)``)
a dipole of moment ``p`` gives

    E(r) = G(r, r') p,    G = (I + grad grad / k_m^2) exp(i*k_m*R)/R,

which is ``4*pi*eps0/k^2`` times the physical field of a dipole moment ``p``
(C m) under ``exp(-i*omega*t)``: far from it, broadside, ``|E| = |p|/R``. The
same ``G`` (``4*pi`` times the usual dyadic Green's function ``Gbar`` of
``E = omega^2 mu0 Gbar p``) holds in every layer, so reciprocity reads
``G(r1, r2) = G(r2, r1)^T`` across the whole stack.

Spectral split. Weyl's identity gives the field of a dipole in the air as plane
waves,

    G p = (i/(2*pi)) ∫∫ (I - k^ k^) p exp(i*(p x + q y) + i*kz0*|z - z'|)/kz0 dp dq,

and each plane wave ``(kappa cos(phi), kappa sin(phi), +-kz0)`` is split into
its TE part (E along ``h = (-sin(phi), cos(phi), 0)``, horizontal) and its TM
part (E in the plane of incidence along ``v = (+-kz cos(phi), +-kz sin(phi),
-kappa)/k``). Each part crosses the stack with its own exact coefficients
(:meth:`Medium.reflection`, :meth:`Medium.transfer_parts` for ``"TE"`` and
``"TM"``; both laws of the tangential electric field). The tangential field of
a TM wave is ``+-kz/k`` times its amplitude, and its vertical field follows from
``div E = 0``: ``E_z = -+ kappa E_t / kz`` for a wave travelling down (up).

Integrating over the azimuth ``phi`` (Jacobi-Anger,
``∫ exp(i n phi + i x cos(phi - a)) dphi = 2 pi i^n J_n(x) exp(i n a)``) leaves
Sommerfeld integrals with ``J0``, ``J1`` and ``J2`` of ``kappa*rho``; with ``a``
the azimuth of the observation point seen from the source, ``u = kz0/k`` and
``w = kappa/k``:

reflected (source and observation in the air, ``R_h``, ``R_v`` of the stack,
``L`` the air path down to the surface and back):

    xx, yy = A +- B cos(2a),  xy = yx = B sin(2a),
    xz = C cos(a),  yz = C sin(a),  zx = -C cos(a),  zy = -C sin(a),  zz = D,
    A, B = ∫ (i/2)(kappa/kz0) (R_h +- R_v u^2) e J0|J2 dkappa,
    C = ∫ (kappa/kz0) R_v u w e J1 dkappa,   D = -i ∫ (kappa/kz0) R_v w^2 e J0 dkappa,
    e = exp(i*kz0*L);

transmitted (source in the air, observation in a ground layer, ``tau = down +
up``, ``sigma = down - up`` the tangential transfers of :meth:`Medium.transfer_parts`,
``kz_m`` the layer's own vertical wavenumber):

    xx, yy = A +- B cos(2a),  xy = B sin(2a),
    xz = C cos(a),  yz = C sin(a),  zx = Z cos(a),  zy = Z sin(a),  zz = D,
    A, B = ∫ (i/2)(kappa/kz0)(tau_h +- tau_v u^2) J0|J2,
    C = ∫ (kappa/kz0) tau_v u w J1,
    Z = ∫ (kappa/kz0) sigma_v (kappa/kz_m) u^2 J1,
    D = i ∫ (kappa/kz0) sigma_v (kappa/kz_m) u w J0.

A buried dipole's field in the air is the transpose of the transmitted one
(reciprocity). The quadrature is the scalar Green's function's
(:mod:`holoradar.physics.green`): Gauss-Legendre over ``k sin(theta)`` for the
waves that propagate in the air and over ``k cosh(t)`` beyond, split at every
layer's branch point, sized by the largest phase; evanescent waves and the near
field are included. The direct wave in the air is the closed form above.
"""

from __future__ import annotations

import hashlib

import numpy as np

from .conductor import refuse_perfect_conductor, surface_is_perfect_conductor
from .green import _nodes, _phase_length
from .medium import Medium

__all__ = ["RadialDyadic", "buried_dipole_dyadic", "dyadic_from_profiles", "dyadic_profiles",
           "dyadic_times", "free_space_dyadic", "reflected_dyadic", "transmitted_dyadic"]


def free_space_dyadic(k: complex, src: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """``(I + grad grad/k^2) exp(i*k*R)/R`` from ``src`` (3,) to ``pts`` (N, 3).

    Returns
    -------
    ndarray, shape (N, 3, 3)
        ``G[n] @ p`` is the field at ``pts[n]`` of a dipole ``p`` at ``src``
        (near and far field).

    Examples
    --------
    >>> G = free_space_dyadic(200.0, np.zeros(3), np.array([[0.0, 0.0, 10.0]]))
    >>> np.round(abs(G[0, 0, 0]) * 10, 4), np.round(abs(G[0, 2, 2]) * 10, 4)   # broadside, axial
    (np.float64(1.0), np.float64(0.001))
    """
    d = np.atleast_2d(np.asarray(pts, float)) - np.asarray(src, float)
    R = np.linalg.norm(d, axis=1)
    if np.any(R == 0):
        raise ValueError("free_space_dyadic: an observation point coincides with the dipole")
    u = d / R[:, None]
    kr = k * R
    g = np.exp(1j * kr) / R
    a = (1 + 1j / kr - 1 / kr**2) * g
    b = (-1 - 3j / kr + 3 / kr**2) * g
    return a[:, None, None] * np.eye(3) + b[:, None, None] * u[:, :, None] * u[:, None, :]


def _j2(x: np.ndarray, J0: np.ndarray, J1: np.ndarray) -> np.ndarray:
    # J2 = 2 J1/x - J0 (recurrence), with J2(0) = 0; below x ~ 1e-3 its series x^2/8.
    small = x < 1e-3
    safe = np.where(small, 1.0, x)
    return np.where(small, x * x / 8, 2 * J1 / safe - J0)


def _profiles(rho: np.ndarray, quad: list[tuple[np.ndarray, np.ndarray, list]],
              reflected: bool, chunk: int = 4096) -> np.ndarray:
    """The five radial functions (A, B, C, Z, D) at distances ``rho``: shape (5, N).

    The Bessel matrices are kept for reuse (a fit over trial permittivities meets the
    same distances and the same propagating nodes again)."""
    from .green import _bessel_matrix

    out = np.zeros((5, rho.size), complex)
    for c0 in range(0, rho.size, chunk):
        r = np.ascontiguousarray(rho[c0:c0 + chunk])
        for kap, w, (kA, kB, kC, kZ, kD) in quad:
            J0 = _bessel_matrix(r, kap)
            J1, J2 = _bessel_j12(r, kap, J0)
            out[0, c0:c0 + chunk] += J0 @ (w * kA)
            out[1, c0:c0 + chunk] += J2 @ (w * kB)
            out[2, c0:c0 + chunk] += J1 @ (w * kC)
            out[4, c0:c0 + chunk] += J0 @ (w * kD)
            if not reflected:
                out[3, c0:c0 + chunk] += J1 @ (w * kZ)
    if reflected:
        out[3] = -out[2]
    return out


def _radial_grid(k: float, medium: Medium, rho_max: float) -> np.ndarray:
    """Distances at a sixteenth of the shortest wavelength in the stack, to ``rho_max``."""
    refuse_perfect_conductor(medium)  # its |n| ~ 1e15 would ask for ~1e17 distances
    n_max = max(abs(medium.n(m)) for m in range(medium.n_regions))
    step = 2 * np.pi / (k * n_max) / 16
    return np.arange(0.0, float(rho_max) + 3 * step, step)


def _spline_profiles(grid: np.ndarray, prof: np.ndarray):
    """Interpolator of radial functions (5, n) given on ``grid``: cubic splines of their
    real and imaginary parts after removing the unwrapped phase of the first (the
    propagation phase all five share), which is splined too."""
    from scipy.interpolate import CubicSpline

    phase = np.unwrap(np.angle(prof[0]))
    demod = prof * np.exp(-1j * phase)
    sp_phase = CubicSpline(grid, phase)
    sp_re = CubicSpline(grid, demod.real, axis=1)
    sp_im = CubicSpline(grid, demod.imag, axis=1)

    def at(rho: np.ndarray) -> np.ndarray:
        return (sp_re(rho) + 1j * sp_im(rho)) * np.exp(1j * sp_phase(rho))

    return at


def _assemble(offsets: np.ndarray, quad: list[tuple[np.ndarray, np.ndarray, list]],
              reflected: bool) -> np.ndarray:
    """Sum the kernels' Hankel transforms at lateral ``offsets`` (N, 2) and build G."""
    rho = np.hypot(offsets[:, 0], offsets[:, 1])
    return _build(offsets, _profiles(rho, quad, reflected))


def _build(offsets: np.ndarray, prof: np.ndarray) -> np.ndarray:
    """G (N, 3, 3) from the radial functions (5, N) and the offsets' azimuths."""
    a = np.arctan2(offsets[:, 1], offsets[:, 0])
    c1, s1, c2, s2 = np.cos(a), np.sin(a), np.cos(2 * a), np.sin(2 * a)
    A, B, C, Z, D = prof
    G = np.empty((offsets.shape[0], 3, 3), complex)
    G[:, 0, 0] = A + B * c2
    G[:, 1, 1] = A - B * c2
    G[:, 0, 1] = G[:, 1, 0] = B * s2
    G[:, 0, 2] = C * c1
    G[:, 1, 2] = C * s1
    G[:, 2, 0] = Z * c1
    G[:, 2, 1] = Z * s1
    G[:, 2, 2] = D
    return G


def _reflected_kernels(k: float, medium: Medium, kap: np.ndarray, L: float,
                       coefficients=None) -> list[np.ndarray]:
    k2 = kap**2
    kz0 = medium.kz(k, k2, 0)
    if coefficients is None:
        Rh = medium.with_polarization("TE").reflection(k, k2)
        Rv = medium.with_polarization("TM").reflection(k, k2)
    else:  # test hook: given laws R_h(kappa), R_v(kappa)
        Rh, Rv = (np.broadcast_to(np.asarray(f(kap), complex), kap.shape)
                  for f in coefficients)
    e = np.exp(1j * kz0 * L) * kap / kz0
    u, w = kz0 / k, kap / k
    return [0.5j * e * (Rh + Rv * u * u), 0.5j * e * (Rh - Rv * u * u), e * Rv * u * w,
            None, -1j * e * Rv * w * w]


def reflected_dyadic(k: float, medium: Medium, src: np.ndarray, pts: np.ndarray, *,
                     coefficients=None) -> np.ndarray:
    """The stack's reflection of a dipole's field, seen in the air: shape (N, 3, 3).

    Parameters
    ----------
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
        The stack (its ``polarization`` is ignored: both laws are used).
    src : ndarray, shape (3,)
        Dipole position in the air, metres (z the range from the aperture).
    pts : ndarray, shape (N, 3)
        Observation points in the air, metres.
    coefficients : (callable, callable), optional
        Replace the stack's reflection coefficients by ``R_h(kappa)``,
        ``R_v(kappa)`` (tangential electric field; for tests of the integrals).

    Returns
    -------
    ndarray, shape (N, 3, 3)
        ``G[n] @ p`` is the reflected field at ``pts[n]`` (see the module notes
        for the normalisation). A perfectly conducting ground
        (:mod:`holoradar.physics.conductor`) gives the image dipole's field in
        closed form: the horizontal moment reversed, the vertical one kept.

    Examples
    --------
    >>> m = Medium.half_space(0.3, 4.0)
    >>> G = reflected_dyadic(200.0, m, np.zeros(3), np.array([[0.0, 0.0, 0.0]]))
    >>> np.round(abs(G[0, 1, 1]) * 0.6, 3)    # ~ |(1 - n)/(1 + n)| over the mirror distance
    np.float64(0.333)
    """
    src = np.asarray(src, float)
    pts = np.atleast_2d(np.asarray(pts, float))
    if medium.is_free_space:
        return np.zeros((len(pts), 3, 3), complex)
    z0 = medium.z_interfaces[0]
    if src[2] >= z0 or np.any(pts[:, 2] >= z0):
        raise ValueError("reflected_dyadic: the dipole and the points must lie in the air "
                         f"above the surface (range < {z0} m)")
    if coefficients is None and surface_is_perfect_conductor(medium):
        # R_h = R_v = -1 at every angle: the Sommerfeld integrals are the mirror image's
        # field, a dipole whose horizontal moment is reversed and vertical one kept.
        image = np.array([src[0], src[1], 2 * z0 - src[2]])
        return free_space_dyadic(k, image, pts) * np.array([-1.0, -1.0, 1.0])
    out = np.empty((len(pts), 3, 3), complex)
    zkeys, inverse = np.unique(np.round(pts[:, 2], 12), return_inverse=True)
    for iz in range(zkeys.size):
        sel = np.nonzero(inverse == iz)[0]
        L = (z0 - src[2]) + (z0 - float(pts[sel[0], 2]))
        off = pts[sel, :2] - src[:2]
        rho_max = float(np.hypot(off[:, 0], off[:, 1]).max(initial=0.0))
        pieces = _nodes(k, medium, L + _phase_length(medium, z0, z0), rho_max, L)
        quad = [(kap, w, _reflected_kernels(k, medium, kap, L, coefficients))
                for kap, w in pieces]
        grid = _radial_grid(k, medium, rho_max)
        if sel.size > 2 * grid.size:
            # Many points: the radial functions on a grid, then splines (error ~1e-7).
            rho = np.hypot(off[:, 0], off[:, 1])
            out[sel] = _build(off, _spline_profiles(grid, _profiles(grid, quad, True))(rho))
        else:
            out[sel] = _assemble(off, quad, reflected=True)
    return out


def _transmitted_kernels(k: float, medium: Medium, kap: np.ndarray, z_src: float,
                         z_obs: float) -> list[np.ndarray]:
    k2 = kap**2
    region = medium.region_of(z_obs)
    kz0 = medium.kz(k, k2, 0)
    kzm = medium.kz(k, k2, region)
    dh, uh = medium.with_polarization("TE").transfer_parts(k, k2, z_src, z_obs)
    dv, uv = medium.with_polarization("TM").transfer_parts(k, k2, z_src, z_obs)
    tau_h, tau_v, sig_v = dh + uh, dv + uv, dv - uv
    e = kap / kz0
    u, w = kz0 / k, kap / k
    ratio = kap / kzm
    return [0.5j * e * (tau_h + tau_v * u * u), 0.5j * e * (tau_h - tau_v * u * u),
            e * tau_v * u * w, e * sig_v * ratio * u * u, 1j * e * sig_v * ratio * u * w]


def transmitted_dyadic(k: float, medium: Medium, src: np.ndarray, pts: np.ndarray
                       ) -> np.ndarray:
    """Field below a dipole in the air: shape (N, 3, 3).

    Points in the ground get the wave transmitted through the stack (every
    interface, every multiple reflection, and the reflection from the layers
    below the point); points in the air get the direct wave (closed form; the
    ground's reflection is :func:`reflected_dyadic`).

    Parameters
    ----------
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
    src : ndarray, shape (3,)
        Dipole position in the air, metres.
    pts : ndarray, shape (N, 3)
        Observation points at ranges beyond the dipole's, metres.

    Examples
    --------
    >>> m = Medium.half_space(0.3, 4.0)
    >>> G = transmitted_dyadic(200.0, m, np.zeros(3), np.array([[0.0, 0.0, 0.5]]))
    >>> np.round(abs(G[0, 0, 0]) * (0.3 + 0.2 / 2), 3)   # ~ 2/(1 + n) over the apparent distance
    np.float64(0.667)
    """
    src = np.asarray(src, float)
    pts = np.atleast_2d(np.asarray(pts, float))
    if medium.region_of(float(src[2])) != 0:
        raise ValueError("transmitted_dyadic: the dipole must lie in the air above the surface")
    if np.any(pts[:, 2] < src[2]):
        raise ValueError("transmitted_dyadic: the points must lie at ranges beyond the dipole's")
    out = np.empty((len(pts), 3, 3), complex)
    zkeys, inverse = np.unique(np.round(pts[:, 2], 12), return_inverse=True)
    for iz in range(zkeys.size):
        sel = np.nonzero(inverse == iz)[0]
        z = float(pts[sel[0], 2])
        if medium.region_of(z) == 0:
            out[sel] = free_space_dyadic(k, src, pts[sel])
            continue
        off = pts[sel, :2] - src[:2]
        rho_max = float(np.hypot(off[:, 0], off[:, 1]).max(initial=0.0))
        air_len = max(0.0, medium.z_interfaces[0] - float(src[2]))
        pieces = _nodes(k, medium, _phase_length(medium, float(src[2]), z), rho_max, air_len)
        quad = [(kap, w, _transmitted_kernels(k, medium, kap, float(src[2]), z))
                for kap, w in pieces]
        out[sel] = _assemble(off, quad, reflected=False)
    return out


def buried_dipole_dyadic(k: float, medium: Medium, src: np.ndarray, pts: np.ndarray
                         ) -> np.ndarray:
    """Field in the air of a dipole buried in the ground: shape (N, 3, 3).

    By reciprocity ``G(r_air, r_buried) = G(r_buried, r_air)^T``: the field of a
    dipole at each air point, transmitted down to the buried one, transposed.
    Air points that share a range share one set of integrals.

    Examples
    --------
    >>> m = Medium.half_space(0.3, 4.0)
    >>> up = buried_dipole_dyadic(200.0, m, np.array([0.01, 0.0, 0.4]),
    ...                           np.array([[0.1, 0.05, 0.0]]))
    >>> down = transmitted_dyadic(200.0, m, np.array([0.1, 0.05, 0.0]),
    ...                           np.array([[0.01, 0.0, 0.4]]))
    >>> bool(np.allclose(up[0], down[0].T))
    True
    """
    src = np.asarray(src, float)
    pts = np.atleast_2d(np.asarray(pts, float))
    if medium.region_of(float(src[2])) == 0:
        raise ValueError("buried_dipole_dyadic: the dipole must lie in the ground")
    out = np.empty((len(pts), 3, 3), complex)
    zkeys, inverse = np.unique(np.round(pts[:, 2], 12), return_inverse=True)
    for iz in range(zkeys.size):
        sel = np.nonzero(inverse == iz)[0]
        z_air = float(pts[sel[0], 2])
        if medium.region_of(z_air) != 0:
            raise ValueError("buried_dipole_dyadic: the observation points must lie in the air")
        # Each air point is a source at (x_e, y_e, z_air); the buried point lies at
        # lateral offset (x_t - x_e, y_t - y_e) from it.
        rel = np.c_[src[0] - pts[sel, 0], src[1] - pts[sel, 1], np.full(sel.size, src[2])]
        down = transmitted_dyadic(k, medium, np.array([0.0, 0.0, z_air]), rel)
        out[sel] = np.swapaxes(down, 1, 2)
    return out


class RadialDyadic:
    """G between one source range and one observation range, for many lateral offsets.

    The stack is invariant along x and y, so ``G`` is five functions of the
    lateral distance (the module's A, B, C, Z, D) and trigonometric functions of
    the azimuth. They are computed once on a radial grid (spacing a sixteenth of
    the shortest wavelength in the stack) and interpolated by cubic splines of
    their real and imaginary parts after removing the phase of ``A`` (the
    propagation phase all five share): what is left varies on the scale of the
    ranges, not of the wavelength.

    Parameters
    ----------
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
    z_src, z_obs : float
        Ranges of the source (in the air) and of the observation points, metres.
    rho_max : float
        Largest lateral distance asked for, metres.
    kind : {"transmitted", "reflected"}
        As :func:`transmitted_dyadic` or :func:`reflected_dyadic`.

    Examples
    --------
    >>> m = Medium.half_space(0.3, 4.0)
    >>> tab = RadialDyadic(200.0, m, 0.0, 0.4, 0.3)
    >>> off = np.array([[0.1, 0.05], [-0.2, 0.1]])
    >>> exact = transmitted_dyadic(200.0, m, np.zeros(3), np.c_[off, [0.4, 0.4]])
    >>> bool(np.abs(tab(off) - exact).max() < 1e-6 * np.abs(exact).max())
    True
    """

    def __init__(self, k: float, medium: Medium, z_src: float, z_obs: float, rho_max: float,
                 kind: str = "transmitted") -> None:
        self.rho = _radial_grid(k, medium, rho_max)
        z0 = medium.z_interfaces[0] if not medium.is_free_space else np.inf
        if kind == "reflected":
            L = (z0 - z_src) + (z0 - z_obs)
            pieces = _nodes(k, medium, L + _phase_length(medium, z0, z0), self.rho[-1], L)
            quad = [(kap, w, _reflected_kernels(k, medium, kap, L)) for kap, w in pieces]
        else:
            air_len = max(0.0, min(z0, z_obs) - z_src)
            pieces = _nodes(k, medium, _phase_length(medium, z_src, z_obs), self.rho[-1],
                            air_len)
            quad = [(kap, w, _transmitted_kernels(k, medium, kap, z_src, z_obs))
                    for kap, w in pieces]
        self._at = _spline_profiles(self.rho, _profiles(self.rho, quad, kind == "reflected"))

    def __call__(self, offsets: np.ndarray) -> np.ndarray:
        """G (N, 3, 3) at lateral ``offsets`` (N, 2) = observation - source, metres."""
        off = np.atleast_2d(np.asarray(offsets, float))
        rho = np.hypot(off[:, 0], off[:, 1])
        if rho.size and rho.max() > self.rho[-1]:
            raise ValueError(f"RadialDyadic: offset {rho.max():.4g} m beyond the table's "
                             f"{self.rho[-1]:.4g} m")
        return _build(off, self._at(rho))


def _kernels_many(k: float, medium: Medium, kap: np.ndarray, z_src: float,
                  z_obs: np.ndarray) -> np.ndarray:
    """:func:`_transmitted_kernels` for many ground ranges, shape (nz, 5, nkappa).

    Inside one region the down- and up-going parts only change by
    ``exp(+-i kz (z - top))``: the stack is solved once per region, at its top.
    """
    k2 = kap**2
    kz0 = medium.kz(k, k2, 0)
    te, tm = medium.with_polarization("TE"), medium.with_polarization("TM")
    e = kap / kz0
    u, w = kz0 / k, kap / k
    out = np.empty((z_obs.size, 5, kap.size), complex)
    regions = np.atleast_1d(medium.region_of(z_obs))
    for region in np.unique(regions):
        sel = np.nonzero(regions == region)[0]
        top = medium.top_of(int(region))
        dh, uh = te.transfer_parts(k, k2, z_src, top)
        dv, uv = tm.transfer_parts(k, k2, z_src, top)
        kzm = medium.kz(k, k2, int(region))
        ph = np.exp(1j * kzm * (z_obs[sel, None] - top))      # (nz, nkappa)
        back = 1 / ph
        tau_h = dh * ph + uh * back
        tau_v = dv * ph + uv * back
        sig_v = dv * ph - uv * back
        ratio = kap / kzm
        out[sel, 0] = 0.5j * e * (tau_h + tau_v * u * u)
        out[sel, 1] = 0.5j * e * (tau_h - tau_v * u * u)
        out[sel, 2] = e * tau_v * u * w
        out[sel, 3] = e * sig_v * ratio * u * u
        out[sel, 4] = 1j * e * sig_v * ratio * u * w
    return out


def _bessel_j12(rho: np.ndarray, kappa: np.ndarray, J0: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """``J1`` and ``J2`` of ``rho kappa``, kept for reuse beside the scalar field's ``J0``."""
    from scipy.special import j1  # here, not at import: holoradar._lazy

    from .green import _J0_CACHE

    digest = hashlib.blake2b(rho.tobytes() + b"|J12|" + kappa.tobytes(), digest_size=16).digest()

    def make() -> np.ndarray:
        x = np.outer(rho, kappa)
        J1 = j1(x)
        return np.stack([J1, _j2(x, J0, J1)])

    J12 = _J0_CACHE.get(("J12", rho.shape, kappa.shape, digest), make)
    return J12[0], J12[1]


def dyadic_profiles(k: float, medium: Medium, z_src: float, z_obs: np.ndarray,
                    rho: np.ndarray) -> np.ndarray:
    """The five radial functions (A, B, C, Z, D) of :func:`transmitted_dyadic` from a
    dipole in the air at range ``z_src`` to ground ranges ``z_obs`` at distances ``rho``.

    One quadrature (sized for the farthest range) and one set of Bessel matrices
    (kept for reuse, as the scalar field's) serve every range, as
    :func:`holoradar.physics.green.transmitted_profiles` does for the scalar
    field. Returns shape ``(len(z_obs), 5, len(rho))``; ``G`` at an offset follows
    from them as in the module notes (:func:`dyadic_from_profiles`).

    Examples
    --------
    >>> m = Medium.half_space(0.3, 4.0)
    >>> prof = dyadic_profiles(200.0, m, 0.0, np.array([0.35, 0.4]), np.array([0.0, 0.1]))
    >>> G = transmitted_dyadic(200.0, m, np.zeros(3), np.array([[0.1, 0.0, 0.4]]))
    >>> bool(np.isclose(prof[1, 0, 1] + prof[1, 1, 1], G[0, 0, 0]))   # xx = A + B at azimuth 0
    True
    """
    from .green import _bessel_matrix

    z_obs = np.atleast_1d(np.asarray(z_obs, float))
    rho = np.asarray(rho, float)
    if medium.region_of(float(z_src)) != 0 or np.any(np.asarray(medium.region_of(z_obs)) == 0):
        raise ValueError("dyadic_profiles: the dipole must lie in the air and the ranges in "
                         "the ground")
    air_len = max(0.0, medium.z_interfaces[0] - float(z_src))
    pieces = _nodes(k, medium, _phase_length(medium, float(z_src), float(z_obs.max())),
                    float(rho.max(initial=0.0)), air_len)
    out = np.zeros((z_obs.size, 5, rho.size), complex)
    for kap, w in pieces:
        J0 = _bessel_matrix(rho, kap)
        J1, J2 = _bessel_j12(rho, kap, J0)
        fw = _kernels_many(k, medium, kap, float(z_src), z_obs) * w   # (nz, 5, nkappa)
        nz = z_obs.size
        for J, rows in ((J0, (0, 4)), (J1, (2, 3)), (J2, (1,))):
            # One real BLAS product per Bessel matrix for all ranges and kernels that use
            # it (real and imaginary parts side by side, contiguous): a complex @ real
            # product would copy J to complex, and strided real views miss BLAS.
            cols = np.concatenate([fw[:, r].real for r in rows] + [fw[:, r].imag for r in rows])
            prod = J @ np.ascontiguousarray(cols.T)                  # (nrho, 2 * len * nz)
            half = len(rows) * nz
            for j, r in enumerate(rows):
                out[:, r] += (prod[:, j * nz:(j + 1) * nz]
                              + 1j * prod[:, half + j * nz:half + (j + 1) * nz]).T
    return out


def dyadic_times(offsets: np.ndarray, prof: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``G @ u`` (..., N, 3) straight from the radial functions ``prof`` (..., 5, N) at
    lateral ``offsets`` (N, 2), for one vector ``u`` (3,): without forming G.

    Examples
    --------
    >>> prof = np.arange(10.0).reshape(5, 2) + 1j
    >>> off = np.array([[0.1, 0.0], [0.0, 0.2]])
    >>> u = np.array([0.2, 1.0, -0.5])
    >>> bool(np.allclose(dyadic_times(off, prof, u), dyadic_from_profiles(off, prof) @ u))
    True
    """
    off = np.atleast_2d(np.asarray(offsets, float))
    a = np.arctan2(off[:, 1], off[:, 0])
    c1, s1, c2, s2 = np.cos(a), np.sin(a), np.cos(2 * a), np.sin(2 * a)
    A, B, C, Z, D = (prof[..., i, :] for i in range(5))
    ux, uy, uz = (float(v) for v in u)
    out = np.empty((*A.shape, 3), complex)
    out[..., 0] = (A + B * c2) * ux + B * (s2 * uy) + C * (c1 * uz)
    out[..., 1] = B * (s2 * ux) + (A - B * c2) * uy + C * (s1 * uz)
    out[..., 2] = Z * (c1 * ux + s1 * uy) + D * uz
    return out


def dyadic_from_profiles(offsets: np.ndarray, prof: np.ndarray) -> np.ndarray:
    """G (..., N, 3, 3) from radial functions ``prof`` (..., 5, N) at lateral ``offsets``
    (N, 2) (observation minus source, metres)."""
    off = np.atleast_2d(np.asarray(offsets, float))
    a = np.arctan2(off[:, 1], off[:, 0])
    c1, s1, c2, s2 = np.cos(a), np.sin(a), np.cos(2 * a), np.sin(2 * a)
    A, B, C, Z, D = (prof[..., i, :] for i in range(5))
    G = np.empty((*A.shape, 3, 3), complex)
    G[..., 0, 0] = A + B * c2
    G[..., 1, 1] = A - B * c2
    G[..., 0, 1] = G[..., 1, 0] = B * s2
    G[..., 0, 2] = C * c1
    G[..., 1, 2] = C * s1
    G[..., 2, 0] = Z * c1
    G[..., 2, 1] = Z * s1
    G[..., 2, 2] = D
    return G
