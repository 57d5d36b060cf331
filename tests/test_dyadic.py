"""The electric dipole's dyadic Green's function through the stack, against closed forms.

Each test names the law it checks. The integrals share their quadrature with the
scalar Green's function (converged to ~1e-9 there), so closed forms are met to
~1e-8 relative; tolerances below leave a factor of ~100 for the Bessel sums.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from holoradar.physics.dyadic import (
    buried_dipole_dyadic,
    free_space_dyadic,
    reflected_dyadic,
    transmitted_dyadic,
)
from holoradar.physics.green import _nodes
from holoradar.physics.medium import Medium, fresnel

K = 2 * np.pi * 9.9e9 / 299_792_458.0
SRC = np.array([0.02, -0.01, 0.05])


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


def test_free_space_dyadic_is_grad_grad_of_the_spherical_wave():
    # (I + grad grad/k^2) exp(ikR)/R by central differences of the scalar wave: their
    # truncation error is (k h)^2/12 of the k^2 g-sized terms, 3e-6 at h = 3e-5 m, and
    # round-off eps |g|/(k h)^2 ~ 1e-9: 1e-4 leaves a margin of 30.
    p = np.array([0.07, -0.04, 0.3])
    h = 3e-5

    def g(r):
        R = np.linalg.norm(r - SRC)
        return np.exp(1j * K * R) / R

    H = np.zeros((3, 3), complex)
    for i in range(3):
        for j in range(3):
            ei, ej = np.eye(3)[i] * h, np.eye(3)[j] * h
            H[i, j] = (g(p + ei + ej) - g(p + ei - ej) - g(p - ei + ej) + g(p - ei - ej)) / (
                4 * h * h)
    want = g(p) * np.eye(3) + H / K**2
    assert _rel(free_space_dyadic(K, SRC, p[None])[0], want) < 1e-4


def test_unit_reflection_is_the_mirrored_dipole_near_field_included():
    # R_h = R_v = -1 (tangential E reversed: a perfect conductor): the image of a
    # horizontal dipole is reversed, of a vertical one kept. R = +1: the opposite.
    m = Medium.half_space(0.3, 4.0)
    pts = np.array([[0.1, 0.07, 0.0], [-0.2, 0.1, 0.25], [0.0, 0.0, 0.0], [0.01, 0.0, 0.29]])
    img = SRC * [1, 1, -1] + [0, 0, 0.6]
    for sign in (-1.0, 1.0):
        G = reflected_dyadic(K, m, SRC, pts, coefficients=(lambda x, s=sign: s + 0 * x,
                                                           lambda x, s=sign: s + 0 * x))
        want = free_space_dyadic(K, img, pts) @ np.diag([sign, sign, -sign])
        assert _rel(G, want) < 1e-7


def test_index_matched_ground_transmits_the_free_space_field():
    # eps = 1 below the "surface": no interface, the transmitted field is the direct one.
    m = Medium.half_space(0.3, 1.0)
    pts = np.array([[0.1, 0.07, 0.45], [-0.2, 0.1, 0.35], [0.0, 0.0, 0.31]])
    assert _rel(transmitted_dyadic(K, m, SRC, pts), free_space_dyadic(K, SRC, pts)) < 1e-7


@pytest.mark.parametrize("eps", [4.0, 9.0 + 1.0j])
def test_reciprocity_with_exchanged_dipoles(eps):
    # p1 . G(r1, r2) p2 == p2 . G(r2, r1) p1 for any p1, p2 (reflected: both in the air).
    m = Medium.half_space(0.3, eps)
    a, b = np.array([0.1, 0.07, 0.02]), np.array([-0.05, 0.12, 0.1])
    p1, p2 = np.array([0.3, -1.0, 0.2j]), np.array([1.0, 0.5, -0.7])
    g12 = p1 @ reflected_dyadic(K, m, b, a[None])[0] @ p2
    g21 = p2 @ reflected_dyadic(K, m, a, b[None])[0] @ p1
    assert abs(g12 - g21) < 1e-10 * abs(g12)


def _upward_by_plane_waves(eps: complex, z0: float, src: np.ndarray, obs: np.ndarray,
                           nphi: int = 64) -> np.ndarray:
    """A buried dipole's field in the air, built independently: its own plane waves
    (Weyl in the ground, weight 1/kz_m), each split into TE and TM with the explicit
    unit vectors of the up-going wave, carried up by the Fresnel transmission of the
    tangential field, and integrated over (kappa, phi) by brute force (trapezoid in
    phi, which is spectrally exact for the periodic integrand)."""
    m = Medium.half_space(z0, eps)
    phis = 2 * np.pi * np.arange(nphi) / nphi
    d = obs - src
    G = np.zeros((3, 3), complex)
    km = K * m.n(1)
    for kap, w in _nodes(K, m, float(abs(m.n(1)) * (src[2] - z0) + (z0 - obs[2])),
                         float(np.hypot(d[0], d[1])), z0 - obs[2]):
        k2 = kap**2
        kz0, kzm = m.kz(K, k2, 0), m.kz(K, k2, 1)
        rh, _ = fresnel(kzm, kz0, eps, 1.0, "TE")  # from the ground up into the air
        rv, _ = fresnel(kzm, kz0, eps, 1.0, "TM")
        th, tv = 1 + rh, 1 + rv
        ph = np.exp(1j * kzm * (src[2] - z0) + 1j * kz0 * (z0 - obs[2]))
        for phi in phis:
            c, s = np.cos(phi), np.sin(phi)
            eh = np.stack([-s + 0 * kap, c + 0 * kap, 0 * kap], -1)
            vm = np.stack([-kzm * c, -kzm * s, -kap + 0j], -1) / km     # up-going, ground
            v0 = np.stack([-kz0 * c, -kz0 * s, -kap + 0j], -1) / K      # up-going, air
            # TM: tangential -kz_m/k_m a in the ground -> tv times it in the air,
            # where it is -kz0/k a'.
            scale = tv * (kzm / km) * (K / kz0)
            M = (th[:, None, None] * eh[:, :, None] * eh[:, None, :]
                 + scale[:, None, None] * v0[:, :, None] * vm[:, None, :])
            lat = np.exp(1j * kap * (d[0] * c + d[1] * s))
            f = (1j / (2 * np.pi)) * kap / kzm * ph * lat * w * (2 * np.pi / nphi)
            G += np.einsum("n,nij->ij", f, M)
    return G


@pytest.mark.parametrize("eps", [2.5, 6.0 + 0.3j])
def test_buried_dipole_field_is_the_transpose_of_the_transmitted_one(eps):
    # Reciprocity across the interface: the downward integral (a dipole in the air,
    # transposed) against an independent upward one (the buried dipole's own waves).
    src = np.array([0.03, -0.02, 0.42])
    obs = np.array([-0.08, 0.05, 0.0])
    up = _upward_by_plane_waves(eps, 0.3, src, obs)
    down = buried_dipole_dyadic(K, Medium.half_space(0.3, eps), src, obs[None])[0]
    assert _rel(down, up) < 1e-6


def test_reflected_integral_against_quadpack():
    # The zz entry (a vertical dipole's glare) as one real-axis Sommerfeld integral,
    # D = -i ∫ (kappa/kz0) R_v (kappa/k)^2 exp(i kz0 L) J0(kappa rho) dkappa, by adaptive
    # QUADPACK (QAGS handles the 1/sqrt singularity at kappa = k).
    from scipy.special import j0

    m = Medium.half_space(0.3, 4.0 + 0.2j)
    obs = np.array([0.12, -0.03, 0.0])
    L = 0.6 - SRC[2] - obs[2]
    rho = float(np.hypot(*(obs[:2] - SRC[:2])))
    tm = m.with_polarization("TM")

    def f(kap, part):
        k2 = np.array(kap * kap)
        kz0 = complex(m.kz(K, k2, 0))
        v = (-1j * kap / kz0 * complex(tm.reflection(K, k2)) * (kap / K) ** 2
             * np.exp(1j * kz0 * L) * j0(kap * rho))
        return v.real if part == 0 else v.imag

    kmax = K * (1 + (60 / (K * L)) ** 2) ** 0.5
    total = 0j
    for lo, hi in ((0.0, K), (K, kmax)):
        for part in (0, 1):
            val, _ = quad(f, lo, hi, args=(part,), limit=800, epsabs=1e-13, epsrel=1e-9)
            total += val if part == 0 else 1j * val
    G = reflected_dyadic(K, m, SRC, obs[None])[0, 2, 2]
    assert abs(G - total) < 1e-7 * abs(total)


def test_far_reflected_field_tends_to_the_ray_with_fresnel_coefficients():
    # Stationary phase: far from source and image, the reflected field is the image's
    # transverse far field with the plane-wave coefficients of the specular angle,
    # R_h e_h e_h - R_v v_- v_+, up to a relative error O(1/(k R')): doubling R' must
    # halve the error (first-order convergence), at 0, 45 and 75 degrees.
    m = Medium.half_space(0.3, 4.0 + 0.1j)
    src = np.array([0.0, 0.0, 0.0])

    def error(theta: float, Rp: float) -> float:
        h = Rp * np.cos(theta) - 0.3  # air path beyond the surface: z0 + (z0 - z) = R' cos
        obs = np.array([Rp * np.sin(theta) * 0.6, Rp * np.sin(theta) * 0.8, 0.3 - h])
        G = reflected_dyadic(K, m, src, obs[None])[0]
        kap = K * np.sin(theta)
        c, s = 0.6, 0.8
        kz = K * np.cos(theta)
        eh = np.array([-s, c, 0])
        vp = np.array([kz * c, kz * s, -kap]) / K
        vm = np.array([-kz * c, -kz * s, -kap]) / K
        k2 = np.array(kap * kap)
        Rh = complex(m.with_polarization("TE").reflection(K, k2))
        Rv = complex(m.with_polarization("TM").reflection(K, k2))
        ray = (Rh * np.outer(eh, eh) - Rv * np.outer(vm, vp)) * np.exp(1j * K * Rp) / Rp
        return _rel(G, ray)

    for theta in np.radians([0.0, 45.0, 75.0]):
        e1, e2 = error(theta, 3.0), error(theta, 6.0)
        assert e1 < 0.05
        assert 1.6 < e1 / e2 < 2.5, (np.degrees(theta), e1, e2)


@pytest.mark.parametrize("eps", [(4.0, 9.0), (5.0 + 0.1j, 8.0 + 0.2j)])
def test_layered_transmission_meets_the_boundary_conditions(eps):
    # Inside a stack the field is a down- and an up-going wave, and the vertical field of
    # the TM part changes sign between them. Across the deeper interface the tangential
    # E and the normal D = eps E_z are continuous: a wrong sign of the up-going part
    # breaks the second. Points 1e-7 m either side: the jump of a smooth field over that
    # gap is ~k n 1e-7 ~ 1e-4 of it; we allow 1e-3.
    m = Medium.layered([0.3, 0.33], list(eps))
    above = np.array([[0.04, -0.07, 0.33 - 1e-7], [0.1, 0.02, 0.33 - 1e-7]])
    below = above + np.array([0, 0, 2e-7])
    Ga = transmitted_dyadic(K, m, SRC, above)
    Gb = transmitted_dyadic(K, m, SRC, below)
    assert _rel(Gb[:, :2, :], Ga[:, :2, :]) < 1e-3
    assert _rel(eps[1] * Gb[:, 2, :], eps[0] * Ga[:, 2, :]) < 1e-3
    # and at the surface, from the air side (the direct wave plus the reflected one)
    air = above * [1, 1, 0] + [0, 0, 0.3 - 1e-7]
    ground = air + np.array([0, 0, 2e-7])
    Gair = transmitted_dyadic(K, m, SRC, air) + reflected_dyadic(K, m, SRC, air)
    Gg = transmitted_dyadic(K, m, SRC, ground)
    assert _rel(Gg[:, :2, :], Gair[:, :2, :]) < 1e-3
    assert _rel(eps[0] * Gg[:, 2, :], Gair[:, 2, :]) < 1e-3
