"""Field of a point source across a layered medium, by Sommerfeld integration.

A unit point source in region s radiates ``exp(i*k_s*R)/R`` in its own region.
Weyl's identity writes it as plane waves,

    exp(i*k_s*R)/R = (i/(2*pi)) * ∫∫ exp(i*(p*x + q*y) + i*kz_s*|z|) / kz_s dp dq,

and every component then crosses the stack with :meth:`Medium.vertical_transfer`
(or is reflected by :meth:`Medium.reflection`). By axial symmetry the double
integral becomes a Sommerfeld (Hankel) integral over kappa = sqrt(p^2 + q^2):

    G(rho) = i * ∫_0^inf J0(kappa*rho) * T(kappa) * kappa / kz_s dkappa.

It is evaluated by Gauss-Legendre quadrature after the substitutions
``kappa = k*sin(theta)`` (propagating in air) and ``kappa = k*cosh(t)``
(evanescent in air), which remove the square-root branch point of kz0 at
kappa = k. The other branch points, kappa = k*Re(n_j) of every ground layer, lie
in the evanescent range: it is split there and each piece is mapped by
``t = a + (b - a)*(1 - cos(pi*s))/2``, which turns a square-root end point into a
smooth one (without the split a source 1 cm above the ground was 1e-2 off). The
number of nodes follows the largest phase of the integrand (the lateral phase
kappa*rho and the vertical one, reverberations in finite layers included), so
the rule resolves every oscillation (2 nodes per radian on top of a minimum,
which converges to 1e-9 against closed forms and adaptive quadrature in the
tests).
"""

from __future__ import annotations

import functools
import hashlib
import itertools
from typing import Literal

import numpy as np

from .._lazy import lazy_module
from ..caches import named_cache
from .conductor import refuse_perfect_conductor, surface_is_perfect_conductor
from .medium import Medium

# Imported on first use (holoradar._lazy): scipy.special and scipy.interpolate cost more
# than numpy's own import, and `import holoradar` should cost little more than numpy.
_special = lazy_module("scipy.special")

__all__ = ["free_space_green", "green_at_distances", "layered_green", "transmitted_profiles"]

_NODES_PER_RADIAN = 2.0
_MIN_NODES = 256
_MAX_NODES = 20000
_MIN_PIECE_NODES = 96
_EVANESCENT_DECAY = 40.0  # integrate the evanescent tail until exp(-40) ~ 4e-18
_BOUNCES = 4  # reverberations resolved in each finite layer


def free_space_green(k: complex, src: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """``exp(i*k*R)/R`` from ``src`` (3,) to ``pts`` (N, 3); metres, rad/m."""
    R = np.linalg.norm(np.asarray(pts, float) - np.asarray(src, float), axis=-1)
    return np.exp(1j * k * R) / R


@functools.lru_cache(maxsize=64)
def legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    # Gauss-Legendre rules are computed once per n: numpy's eigenvalue problem for small
    # n, scipy's asymptotic expansions (nodes exact to 1e-16, weights to ~1e-11, O(n))
    # beyond 192, where the eigenvalue problem already costs 3x more (0.03 s at n = 512,
    # 0.5 s at 2048).
    x, w = np.polynomial.legendre.leggauss(n) if n <= 192 else _special.roots_legendre(n)
    x.setflags(write=False)
    w.setflags(write=False)
    return x, w


def _rule_size(n: int) -> int:
    """``n`` rounded up to a multiple of 32, and above 256 to 2^j or 1.5 * 2^j: few
    distinct rules (each computed once), and the same nodes for nearby problems, so
    that a sweep over trial permittivities meets the same Bessel matrices again
    (kept by :func:`_bessel_matrix`). At most 1.5x the nodes asked for.

    Examples
    --------
    >>> [_rule_size(n) for n in (100, 256, 300, 400, 700, 1100)]
    [128, 256, 384, 512, 768, 1536]
    """
    n = -(-int(n) // 32) * 32
    if n <= 256:
        return n
    j = int(np.floor(np.log2(n)))
    return next(v for v in (2**j, 3 * 2 ** (j - 1), 2 ** (j + 1)) if v >= n)


def _gauss(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = legendre(_rule_size(n))
    return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w


def layered_green(k: float, medium: Medium, src: np.ndarray, pts: np.ndarray, *,
                  kind: Literal["transmitted", "reflected"] = "transmitted",
                  chunk: int = 4096) -> np.ndarray:
    """Field at ``pts`` of a unit point source at ``src`` in a layered medium.

    Parameters
    ----------
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
        The stack.
    src : ndarray, shape (3,)
        Source position (x, y, z), metres, z the range from the aperture.
    pts : ndarray, shape (N, 3)
        Observation points, metres. For ``"transmitted"`` the source or the
        points lie in the air: the wave crosses the stack exactly (every
        interface's transmission, all multiple reflections, and for a buried end
        the reflections from the layers below it:
        :meth:`Medium.vertical_transfer`); in the source's own region it is the
        direct wave. For ``"reflected"`` source and points lie in the air, and the
        result is the specular reflection of the whole stack.
    kind : {"transmitted", "reflected"}
        Which wave to compute.

    Returns
    -------
    ndarray, shape (N,)
        Complex field; normalised so that a source in a homogeneous region gives
        ``exp(i*k_s*R)/R`` there.
    """
    src = np.asarray(src, float)
    pts = np.atleast_2d(np.asarray(pts, float))
    rho = np.hypot(pts[:, 0] - src[0], pts[:, 1] - src[1])
    zs = src[2]
    s = medium.region_of(zs)
    if kind == "reflected":
        if s != 0 or np.any(medium.region_of(pts[:, 2]) != 0):
            raise ValueError("reflected: source and points must lie in the air above the surface")
        if medium.is_free_space:
            return np.zeros(len(pts), complex)
    out = np.empty(len(pts), complex)
    # Group points by range: each range needs its own vertical transfer.
    zkeys, inverse = np.unique(np.round(pts[:, 2], 12), return_inverse=True)
    for iz in range(zkeys.size):
        sel = np.nonzero(inverse == iz)[0]
        out[sel] = green_at_distances(k, medium, float(zs), float(pts[sel[0], 2]), rho[sel],
                                      kind=kind, chunk=chunk)
    return out


def green_at_distances(k: float, medium: Medium, z_src: float, z_obs: float,
                       rho: np.ndarray, *, kind: Literal["transmitted", "reflected"]
                       = "transmitted", chunk: int = 4096) -> np.ndarray:
    """:func:`layered_green` for one source range and one observation range.

    The stack is invariant along x and y, so the field depends on the lateral
    distances ``rho`` (any shape, metres) only. When there are many of them, the
    field is computed once on a radial grid (lambda/16 in the densest layer) and
    interpolated by cubic splines of its amplitude and unwrapped phase: both vary
    on the scale of the ranges, not of the wavelength, so the spline error
    ``(5/384) h^4 max|f^(4)|`` is ~1e-11 (tested against direct evaluation).

    A perfectly conducting ground (:mod:`holoradar.physics.conductor`) reflects
    ``-exp(i*k*R')/R'``, the mirror image's field, in closed form; the field inside
    or below a perfect conductor is refused.

    Examples
    --------
    >>> m = Medium.half_space(0.3, 4.0)
    >>> g = green_at_distances(200.0, m, 0.0, 0.1, np.array([0.0, 0.2]), kind="reflected")
    >>> np.round(np.abs(g), 4)   # ~ |V(theta)|/R' from the mirror image at range 0.5 m
    array([0.6666, 0.6653])
    """
    rho = np.asarray(rho, dtype=float)
    flat = rho.ravel()
    if kind == "reflected":
        z0 = medium.z_interfaces[0]
        air = (z0 - z_src) + (z0 - z_obs)
        if surface_is_perfect_conductor(medium):
            # Reflection -1 at every angle: the Sommerfeld integral is the mirror image's
            # field (the integral's rule and grid would follow |n| ~ 1e15 of PEC_EPS).
            R = np.hypot(flat, air)
            return (-np.exp(1j * k * R) / R).reshape(rho.shape)

        def field(r: np.ndarray) -> np.ndarray:
            return _reflected(k, medium, r, np.full(r.size, air))
    else:
        def field(r: np.ndarray) -> np.ndarray:
            return _transmitted(k, medium, z_src, z_obs, r)

    if medium.is_free_space or (kind == "transmitted"
                                and medium.region_of(z_obs) == medium.region_of(z_src)):
        return field(flat).reshape(rho.shape)  # closed form
    refuse_perfect_conductor(medium)  # before the grid, whose step follows the largest |n|
    step = 2 * np.pi / (k * max(abs(medium.n(m)) for m in range(medium.n_regions))) / 16
    grid = np.arange(flat.min(initial=0.0), flat.max(initial=0.0) + 3 * step, step)
    if flat.size <= 2 * grid.size:
        parts = [field(flat[c0:c0 + chunk]) for c0 in range(0, flat.size, chunk)]
        return (np.concatenate(parts) if parts else np.zeros(0, complex)).reshape(rho.shape)
    prof = np.concatenate([field(grid[c0:c0 + chunk]) for c0 in range(0, grid.size, chunk)])
    from scipy.interpolate import CubicSpline

    amp = CubicSpline(grid, np.abs(prof))(flat)
    phase = CubicSpline(grid, np.unwrap(np.angle(prof)))(flat)
    return (amp * np.exp(1j * phase)).reshape(rho.shape)


def _phase_length(medium: Medium, lo: float, hi: float) -> float:
    """Optical length |n| h of the path from ``lo`` to ``hi``, plus reverberations.

    Each finite ground layer adds ``_BOUNCES`` round trips: the multiple reflections
    inside it oscillate that much faster in kappa (their weight falls as |r|^m).
    """
    total = 0.0
    for m in range(medium.n_regions):
        top = -np.inf if m == 0 else medium.top_of(m)
        bottom = medium.z_interfaces[m] if m < len(medium.z_interfaces) else np.inf
        direct = max(0.0, min(hi, bottom) - max(lo, top))
        extra = 2 * _BOUNCES * (bottom - top) if 0 < m < medium.n_regions - 1 else 0.0
        total += abs(medium.n(m)) * (direct + extra)
    return total


def _cosine_map(a: float, b: float, n: int, *, at_a: bool,
                at_b: bool) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes on [a, b], clustered quadratically at the branch-point ends.

    ``t = a + (b - a)(1 - cos(pi s))/2`` (both ends), ``a + (b - a) sin(pi s/2)`` (at
    ``b`` only) or ``a + (b - a)(1 - cos(pi s/2))`` (at ``a`` only), s in [0, 1]: near
    a clustered end t - end is quadratic in s, so a square-root branch point there
    becomes a smooth (linear) behaviour of the integrand.
    """
    s, w = _gauss(0.0, 1.0, n)
    if at_a and at_b:
        return (a + 0.5 * (b - a) * (1 - np.cos(np.pi * s)),
                w * 0.5 * (b - a) * np.pi * np.sin(np.pi * s))
    if at_b:
        return a + (b - a) * np.sin(0.5 * np.pi * s), w * (b - a) * 0.5 * np.pi * np.cos(
            0.5 * np.pi * s)
    if at_a:
        return a + (b - a) * (1 - np.cos(0.5 * np.pi * s)), w * (b - a) * 0.5 * np.pi * np.sin(
            0.5 * np.pi * s)
    return a + (b - a) * s, w * (b - a)


def _nodes(k: float, medium: Medium, phase_len: float, rho_max: float,
           air_len: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """Quadrature over kappa: pieces of (kappa, weight*dkappa/dvar)."""
    refuse_perfect_conductor(medium)  # its |n| would size the rule at ~1e17 nodes
    n_prop = int(_MIN_NODES + _NODES_PER_RADIAN * k * (phase_len + rho_max))
    th, wth = _gauss(0.0, np.pi / 2, n_prop)
    pieces = [(k * np.sin(th), wth * k * np.cos(th))]
    # Evanescent in air: decays as exp(-k*sinh(t)*air_len); stop at exp(-40).
    n_max = max(abs(np.sqrt(complex(e))) for e in medium.eps)
    if air_len > 0:
        t_max = float(np.arcsinh(_EVANESCENT_DECAY / (k * air_len)))
    else:
        t_max = float(np.arccosh(4 * n_max))
    # Branch points kappa = k Re(n_j) of the ground layers split the range.
    cuts = sorted({float(np.arccosh(medium.n(m).real)) for m in range(1, medium.n_regions)
                   if 1 < medium.n(m).real and np.arccosh(medium.n(m).real) < t_max})
    edges = [0.0, *cuts, t_max]
    for i, (a, b) in enumerate(itertools.pairwise(edges)):
        # Phase over the piece: kappa*rho and the vertical phase of the layers
        # (at most k*n per unit length while they propagate).
        phase = k * rho_max * (np.cosh(b) - np.cosh(a)) + k * phase_len * (
            min(np.cosh(b), n_max) - min(np.cosh(a), n_max))
        n = min(_MAX_NODES, int(_MIN_PIECE_NODES + _NODES_PER_RADIAN * phase))
        t, wt = _cosine_map(a, b, n, at_a=i > 0, at_b=i < len(edges) - 2)
        pieces.append((k * np.cosh(t), wt * k * np.sinh(t)))
    return pieces


def _hankel(kappa: np.ndarray, weight: np.ndarray, integrand: np.ndarray,
            rho: np.ndarray) -> np.ndarray:
    # sum_n w_n f(kappa_n) J0(kappa_n rho_m): one matrix product per chunk.
    return _special.j0(np.outer(rho, kappa)) @ (weight * integrand)


def _transmitted(k: float, medium: Medium, zs: float, zr: float, rho: np.ndarray) -> np.ndarray:
    s = medium.region_of(zs)
    if medium.is_free_space or medium.region_of(zr) == s:
        # Same homogeneous region: the direct wave in closed form (reflections are
        # the "reflected" kind).
        R = np.hypot(rho, zr - zs)
        return np.exp(1j * k * medium.n(s) * R) / R
    lo, hi = min(zs, zr), max(zs, zr)
    if medium.region_of(lo) != 0:
        raise ValueError("layered_green: the source or the points must lie in the air above "
                         "the surface (a wave between two buried points is not modelled)")
    air_len = max(0.0, min(hi, medium.z_interfaces[0]) - lo)
    pieces = _nodes(k, medium, _phase_length(medium, lo, hi), float(rho.max(initial=0.0)),
                    air_len)
    total = np.zeros(rho.size, complex)
    for kap, w in pieces:
        k2 = kap**2
        T = medium.vertical_transfer(k, k2, zs, zr)
        f = 1j * T * kap / medium.kz(k, k2, s)
        total += _hankel(kap, w, f, rho)
    return total


def _reflected(k: float, medium: Medium, rho: np.ndarray, air_path: np.ndarray) -> np.ndarray:
    # Points may differ in range only through air_path; group by it.
    out = np.empty(rho.size, complex)
    keys, inv = np.unique(np.round(air_path, 12), return_inverse=True)
    for i, L in enumerate(keys):
        sel = inv == i
        pieces = _nodes(k, medium, float(L) + _phase_length(medium, medium.z_interfaces[0],
                                                            medium.z_interfaces[0]),
                        float(rho[sel].max()), float(L))
        acc = np.zeros(int(sel.sum()), complex)
        for kap, w in pieces:
            k2 = kap**2
            kz0 = medium.kz(k, k2, 0)
            f = 1j * medium.reflection(k, k2) * np.exp(1j * kz0 * L) * kap / kz0
            acc += _hankel(kap, w, f, rho[sel])
        out[sel] = acc
    return out


_J0_CACHE = named_cache("Bessel tables", max_bytes=128 * 2**20)


def _bessel_matrix(rho: np.ndarray, kappa: np.ndarray) -> np.ndarray:
    """``J0(rho kappa)`` (nrho, nkappa), kept for reuse (least recently used, 128 MiB at
    most, thread-safe): a sweep over ground permittivities meets the same radial grid and
    the same propagating nodes (``k sin(theta)``) again."""
    digest = hashlib.blake2b(rho.tobytes() + b"|" + kappa.tobytes(), digest_size=16).digest()
    return _J0_CACHE.get((rho.shape, kappa.shape, digest),
                         lambda: _special.j0(np.outer(rho, kappa)))


def clear_bessel_cache() -> None:
    """Free the kept Bessel matrices of :func:`transmitted_profiles`."""
    _J0_CACHE.clear()


def transmitted_profiles(k: float, medium: Medium, z_src: float, z_obs: np.ndarray,
                         rho: np.ndarray) -> np.ndarray:
    """Field of a unit point source in the air at range ``z_src`` at lateral distances
    ``rho`` on several ranges ``z_obs`` below it, shape (len(z_obs), len(rho)).

    The same Sommerfeld integral as :func:`layered_green` ("transmitted"), with one
    quadrature rule for all ranges (sized for the farthest) and one matrix of
    ``J0(kappa*rho)`` shared by them: a stack of image planes costs one matrix
    product instead of one integral per plane.

    Examples
    --------
    >>> m = Medium.half_space(0.3, 2.5)
    >>> g = transmitted_profiles(200.0, m, 0.0, np.array([0.35, 0.4]), np.array([0.0, 0.1]))
    >>> bool(np.allclose(g[1], layered_green(200.0, m, np.zeros(3),
    ...                                      np.array([[0.0, 0, 0.4], [0.1, 0, 0.4]]))))
    True
    """
    z_obs = np.atleast_1d(np.asarray(z_obs, dtype=float))
    rho = np.asarray(rho, dtype=float)
    if medium.region_of(z_src) != 0:
        raise ValueError("transmitted_profiles: the source must lie in the air")
    out = np.empty((z_obs.size, rho.size), complex)
    in_air = np.asarray(medium.region_of(z_obs)) == 0
    for i in np.nonzero(in_air)[0]:  # same region as the source: closed form
        out[i] = _transmitted(k, medium, z_src, float(z_obs[i]), rho)
    deep = np.nonzero(~in_air)[0]
    if deep.size == 0:
        return out
    z_far = float(z_obs[deep].max())
    air_len = max(0.0, medium.z_interfaces[0] - z_src)
    pieces = _nodes(k, medium, _phase_length(medium, z_src, z_far), float(rho.max(initial=0.0)),
                    air_len)
    acc = np.zeros((deep.size, rho.size), complex)
    for kap, w in pieces:
        k2 = kap**2
        J = _bessel_matrix(rho, kap)                                # (nrho, nkappa)
        f = 1j * medium.vertical_transfers(k, k2, z_src, z_obs[deep]) * (
            kap / medium.kz(k, k2, 0))                               # (nz, nkappa)
        fw = f * w
        # One real BLAS product, real and imaginary parts stacked contiguously: a complex @
        # real product would copy J to complex, and the strided views fw.real / fw.imag
        # miss BLAS (NumPy's fallback loop: 40x slower for 29 ranges x 1024 nodes).
        prod = np.concatenate([fw.real, fw.imag]) @ J.T               # (2 nz, nrho)
        acc += prod[:deep.size] + 1j * prod[deep.size:]
    out[deep] = acc
    return out
