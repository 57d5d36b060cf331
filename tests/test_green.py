"""Sommerfeld integration of a point source across layers against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from conftest import F0
from holoradar.physics.green import free_space_green, layered_green

K = 2 * np.pi * F0 / hr.C0


def _pts(n=9, z=0.0):
    return np.c_[np.linspace(-0.25, 0.25, n), np.linspace(0.1, -0.05, n), np.full(n, z)]


@pytest.mark.parametrize("src_z", [0.05, 0.42])
def test_index_matched_interface_is_free_space(src_z):
    # eps = 1 below the "surface": the Sommerfeld integral must reproduce exp(ikR)/R.
    # Gauss-Legendre at >= 2 nodes/radian of phase converges to ~1e-9 here.
    m = hr.Medium.half_space(0.3, 1.0)
    src = np.array([0.03, -0.02, src_z])
    a = layered_green(K, m, src, _pts())
    b = free_space_green(K, src, _pts())
    assert np.max(np.abs(a - b)) / np.max(np.abs(b)) < 1e-6


def test_reciprocity_across_interface():
    m = hr.Medium.layered([0.3, 0.36], [2.5 + 0.02j, 6.0 + 0.1j])
    a = np.array([0.1, -0.03, 0.05])
    b = np.array([-0.02, 0.04, 0.41])
    g1 = layered_green(K, m, a, b[None])[0]
    g2 = layered_green(K, m, b, a[None])[0]
    assert abs(g1 - g2) / abs(g1) < 1e-8


@pytest.mark.parametrize("eps", [2.5, 4.0, 9.0])
def test_reflected_wave_is_mirror_image_far_away(eps):
    # Far from the surface the reflected spherical wave tends to V(theta) exp(ikR')/R'
    # from the mirror image, with a correction of relative order 1/(kR')
    # (Brekhovskikh, Waves in Layered Media, sec. 18): allow 3/(kR').
    m = hr.Medium.half_space(0.6, eps)
    src = np.array([0.0, 0.0, 0.0])
    pts = np.c_[np.array([0.0, 0.1, 0.2]), np.zeros(3), np.zeros(3)]
    g = layered_green(K, m, src, pts, kind="reflected")
    Rm = np.hypot(pts[:, 0], 1.2)
    cos_t = 1.2 / Rm
    kap2 = (K * np.sqrt(1 - cos_t**2)) ** 2
    V = m.reflection(K, kap2)
    ref = V * np.exp(1j * K * Rm) / Rm
    assert np.all(np.abs(g - ref) / np.abs(ref) < 3 / (K * Rm))


def test_transmitted_wave_paraxial_amplitude():
    # Straight down: the wave from an air source crosses with W = 2/(1+n) and diverges
    # from the apparent distance; the next term of the asymptotic series is O(1/(kL)).
    eps = 4.0
    n = 2.0
    m = hr.Medium.half_space(0.5, eps)
    src = np.array([0.0, 0.0, 0.0])
    z = 0.9
    g = layered_green(K, m, src, np.array([[0.0, 0.0, z]]))[0]
    # Stationary phase of G = i ∫ J0(kappa rho) T kappa/kz0 dkappa on axis: the phase is
    # k z0 + k n d - kappa^2 L/(2k) with L = z0 + d/n, so G -> W exp(i k (z0 + n d)) / L.
    L = 0.5 + 0.4 / n
    amp = 2 / (1 + n) / L
    assert abs(abs(g) - amp) / amp < 3 / (K * L)
    phase = K * (0.5 + n * 0.4)
    assert abs(np.angle(g * np.exp(-1j * phase))) < 3 / (K * L)
