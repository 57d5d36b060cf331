"""Medium: Fresnel coefficients, stack transfer and reflection against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from conftest import F0
from holoradar import theory

K = 2 * np.pi * F0 / hr.C0


@pytest.mark.parametrize("pol", ["TE", "TM"])
@pytest.mark.parametrize("eps", [2.5, 9.0, 4.0 + 0.3j])
def test_normal_incidence_coefficients(eps, pol):
    # Paper section 3.2: V = (1 - n)/(1 + n), W = 2/(1 + n), back out 2n/(1 + n), for
    # either polarisation (the scalar field is the tangential electric field).
    n = np.sqrt(complex(eps))
    m = hr.Medium.half_space(0.3, eps, polarization=pol)
    zero = np.array(0.0)
    np.testing.assert_allclose(m.reflection(K, zero), (1 - n) / (1 + n), rtol=1e-13)
    # Just above to just below the surface (a point on the interface belongs below).
    down = m.vertical_transfer(K, zero, 0.3 - 1e-9, 0.3 + 1e-9)
    up = m.vertical_transfer(K, zero, 0.3 + 1e-9, 0.3 - 1e-9)
    np.testing.assert_allclose(down, 2 / (1 + n), rtol=1e-6)
    np.testing.assert_allclose(up, 2 * n / (1 + n), rtol=1e-6)


@pytest.mark.parametrize("theta_deg", [0, 20, 45, 70])
@pytest.mark.parametrize("pol", ["TE", "TM"])
def test_oblique_energy_conservation(theta_deg, pol):
    # theory.fresnel_coefficients (Medium's own coefficients) across a lossless
    # interface. Power through the plane: S_z ~ |E_t|^2 Y with the admittance Y = kz
    # (TE) or eps/kz (TM, since H_y = omega eps0 eps E_x / kz): |r|^2 + Y2/Y1 |t|^2 = 1.
    eps1, eps2 = 1.0, 6.0
    c = theory.fresnel_coefficients(eps1, eps2, np.radians(theta_deg))
    th = np.radians(theta_deg)
    kz1 = np.cos(th)
    kz2 = np.sqrt(eps2 - np.sin(th) ** 2)
    if pol == "TE":
        total = abs(c["r_te"]) ** 2 + kz2 / kz1 * abs(c["t_te"]) ** 2
    else:
        total = abs(c["r_tm"]) ** 2 + (eps2 / kz2) / (eps1 / kz1) * abs(c["t_tm"]) ** 2
    assert abs(total - 1) < 1e-12


def test_brewster_angle_tm():
    eps2 = 4.0
    th_b = np.arctan(np.sqrt(eps2))
    c = theory.fresnel_coefficients(1.0, eps2, th_b)
    assert abs(c["r_tm"]) < 1e-12
    assert abs(c["r_te"]) > 0.3


@pytest.mark.parametrize("theta_deg", [10, 35, 60])
def test_coefficients_match_textbook_angle_forms(theta_deg):
    # Born & Wolf, sec. 1.5, in terms of angles (Snell: n1 sin t1 = n2 sin t2):
    # r_s = (n1 c1 - n2 c2)/(n1 c1 + n2 c2), t_s = 2 n1 c1/(n1 c1 + n2 c2),
    # r_p = (n2 c1 - n1 c2)/(n2 c1 + n1 c2), t_p = 2 n1 c1/(n2 c1 + n1 c2);
    # r_p is signed by the magnetic field: the tangential-E convention used here is -r_p,
    # and the tangential transmission is t_p cos(t2)/cos(t1) (= 1 + r for both).
    n1, n2 = 1.0, 2.2
    t1 = np.radians(theta_deg)
    t2 = np.arcsin(n1 * np.sin(t1) / n2)
    c1, c2 = np.cos(t1), np.cos(t2)
    c = theory.fresnel_coefficients(n1**2, n2**2, t1)
    assert c["r_te"] == pytest.approx((n1 * c1 - n2 * c2) / (n1 * c1 + n2 * c2), abs=1e-13)
    assert c["t_te"] == pytest.approx(2 * n1 * c1 / (n1 * c1 + n2 * c2), abs=1e-13)
    assert c["r_tm"] == pytest.approx(-(n2 * c1 - n1 * c2) / (n2 * c1 + n1 * c2), abs=1e-13)
    assert c["t_tm"] == pytest.approx(2 * n1 * c1 / (n2 * c1 + n1 * c2) * c2 / c1, abs=1e-13)
    assert c["t_tm"] == pytest.approx(1 + c["r_tm"], abs=1e-13)


def test_medium_matches_theory_coefficients():
    m = hr.Medium.half_space(0.3, 5.0, polarization="TM")
    th = np.radians(35)
    kap2 = np.array((K * np.sin(th)) ** 2)
    c = theory.fresnel_coefficients(1.0, 5.0, th)
    np.testing.assert_allclose(m.reflection(K, kap2), c["r_tm"], rtol=1e-12)
    m = hr.Medium.half_space(0.3, 5.0)
    np.testing.assert_allclose(m.reflection(K, kap2), c["r_te"], rtol=1e-12)


def test_layer_reflection_quarter_wave_antireflection():
    # A lambda/4 layer of index sqrt(n2) on a substrate n2 cancels normal reflection.
    n2 = 4.0
    n1 = np.sqrt(n2)
    h = 2 * np.pi / K / (4 * n1)
    m = hr.Medium.layered([0.3, 0.3 + h], [n1**2, n2**2])
    assert abs(m.reflection(K, np.array(0.0))) < 1e-12


def test_layer_of_same_medium_is_invisible():
    a = hr.Medium.layered([0.3, 0.35], [2.5, 2.5])
    b = hr.Medium.half_space(0.3, 2.5)
    kap2 = np.linspace(0, 1.2, 7) ** 2 * K**2
    np.testing.assert_allclose(a.reflection(K, kap2), b.reflection(K, kap2), atol=1e-13)
    np.testing.assert_allclose(a.vertical_transfer(K, kap2, 0.4, 0.0),
                               b.vertical_transfer(K, kap2, 0.4, 0.0), atol=1e-13)


def test_attenuation_in_lossy_layer():
    # Amplitude decays as exp(-k Im(n) d) at normal incidence (paper section 3.2).
    eps = 2.5 + 0.0125j
    m = hr.Medium.half_space(0.3, eps)
    d = 0.2
    t = m.vertical_transfer(K, np.array(0.0), 0.3 + d, 0.3 - 1e-12)
    n = np.sqrt(eps)
    np.testing.assert_allclose(abs(t), abs(2 * n / (1 + n)) * np.exp(-K * n.imag * d),
                               rtol=1e-9)
    np.testing.assert_allclose(theory.attenuation(eps, F0, d)["factor"],
                               np.exp(-K * n.imag * d), rtol=1e-12)


def test_apparent_distance():
    m = hr.Medium.half_space(0.30, 9.0)
    assert m.apparent_distance(0.50) == pytest.approx(0.30 + 0.20 / 3)
    assert theory.apparent_distance(0.50, 0.30, 9.0) == pytest.approx(0.30 + 0.20 / 3)
    assert m.apparent_distance(0.2) == pytest.approx(0.2)


def test_permittivity_from_conductivity():
    # sigma = 0.0069 S/m at 9.9 GHz is the gprMax sand: Im(eps) = sigma/(omega eps0) = 0.0125.
    e = hr.permittivity(2.5, sigma=0.0069, frequency=9.9e9)
    assert e.imag == pytest.approx(0.01253, rel=1e-3)


def test_vertical_transfers_equal_one_range_at_a_time_for_any_kappa_shape():
    # Many ranges at once (the stack's coefficients computed once) against one at a time,
    # through two layers and for 0-d, 1-d and 2-d spectra; exact to rounding.
    m = hr.Medium.layered([0.3, 0.34], [3.0 + 0.03j, 6.0])
    z = np.array([0.1, 0.2, 0.31, 0.33, 0.5, 0.6])  # two ranges in each region
    for k2 in (np.array(900.0), np.linspace(0, 4e4, 7), np.linspace(0, 9e4, 12).reshape(3, 4)):
        many = m.vertical_transfers(200.0, k2, 0.0, z)
        assert many.shape == z.shape + k2.shape
        for i, zi in enumerate(z):
            np.testing.assert_allclose(many[i], m.vertical_transfer(200.0, k2, 0.0, zi),
                                       rtol=1e-12, atol=1e-15)
