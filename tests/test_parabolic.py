"""The parabolic-equation propagator through a graded ground: against the exact layered
transfer, its order of convergence in the step, forward/adjoint, a Gaussian beam."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from holoradar.physics.parabolic import ParabolicEquation

K = 2 * np.pi * 9.9e9 / hr.C0
WET = hr.Medium.graded(0.30, lambda d: 3.0 + 20.0 * d, 0.30, step=0.0005)  # eps' 3 -> 9
ZA, ZB = 0.30, 0.50


def _pe_at(s: np.ndarray, *, step: float | None = None, wide: bool = False,
           medium: hr.Medium = WET) -> np.ndarray:
    pe = ParabolicEquation((4, 4), (0.01, 0.01), K, medium, ZA, ZB, step=step, wide_angle=wide)
    pe.kappa2 = (K * s) ** 2  # evaluate the multiplier at chosen angles
    return pe._transfer()


def _exact(s: np.ndarray) -> np.ndarray:
    """The exact layered transfer inside the ground: air -> z_to over air -> z_from."""
    kap2 = (K * s) ** 2
    return WET.vertical_transfer(K, kap2, 0.0, ZB) / WET.vertical_transfer(K, kap2, 0.0,
                                                                           ZA + 1e-9)


def _bounds(s: np.ndarray) -> tuple[np.ndarray, float]:
    """Error bounds. The paraxial phase drops the quartic term of the square root:
    int kappa^4/(8 k^3 n^3) dz (rad). Both forms drop the gradient's own reflection: the
    exact total field carries it, of order n'/(4 k n^2) at each end of the gradient
    (first-order WKB); twice the larger end's value bounds it."""
    z = np.linspace(ZA, ZB, 2001)
    n = np.sqrt(3.0 + 20.0 * (z - 0.30))
    quartic = (K * s) ** 4 / (8 * K**3) * np.trapezoid(1 / n**3, z)
    dn = 10.0 / n  # d/dz sqrt(3 + 20 d)
    reflection = 2 * float(np.max(dn / (4 * K * n * n)))
    return quartic, reflection


def test_paraxial_form_matches_the_exact_layered_transfer_at_small_angles():
    s = np.array([0.0, 0.1, 0.2, 0.3])  # sines of the angle in air: up to 17.5 degrees
    err = np.abs(_pe_at(s) - _exact(s)) / np.abs(_exact(s))
    quartic, reflection = _bounds(s)
    assert np.all(err <= quartic + reflection)
    assert np.all(err <= 0.01)  # the 1%, met up to 17.5 degrees in air
    # and beyond the paraxial range it departs, as the quartic term says it must
    big = np.array([0.8])
    assert np.abs(_pe_at(big) - _exact(big))[0] / np.abs(_exact(big))[0] > 0.05


def test_wide_angle_form_matches_at_all_propagating_angles():
    s = np.linspace(0.0, 0.8, 9)  # to 53 degrees in air
    err = np.abs(_pe_at(s, wide=True) - _exact(s)) / np.abs(_exact(s))
    _, reflection = _bounds(s)
    assert np.all(err <= reflection)


def test_split_step_converges_with_the_second_order():
    """The midpoint rule for int n dz and int dz/n: the error falls as step^2. The
    profile is sampled much finer (7 um layers, incommensurate with the steps) than any
    step, so that the steps, not the staircase, set the error."""
    fine = hr.Medium.graded(0.30, lambda d: 3.0 + 20.0 * d, 0.20, step=7e-6)
    s = np.array([0.2])
    ref = _pe_at(s, step=1e-4, medium=fine)
    errs = [abs(_pe_at(s, step=h, medium=fine)[0] - ref[0]) for h in (0.02, 0.01, 0.005)]
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 2) < 0.2), orders


@pytest.mark.parametrize("wide", [False, True])
def test_forward_and_adjoint_pass_the_dot_test(wide):
    rng = np.random.default_rng(3)
    pe = ParabolicEquation((32, 24), (0.004, 0.005), K, WET, ZA, ZB, step=0.003,
                           wide_angle=wide)
    x = rng.standard_normal((32, 24)) + 1j * rng.standard_normal((32, 24))
    y = rng.standard_normal((32, 24)) + 1j * rng.standard_normal((32, 24))
    lhs, rhs = np.vdot(y, pe.forward(x)), np.vdot(pe.adjoint(y), x)
    assert abs(lhs - rhs) <= 1e-12 * abs(lhs)


def test_gaussian_beam_through_the_graded_ground():
    """A beam (6 cm waist, 10 degrees) taken at the top of the ground and carried down by
    the PE equals the exact layered beam at depth, within the paraxial bound (its
    spectrum holds kappa up to 3/w0: sin 0.25 in air)."""
    beam = hr.GaussianBeam(0.06, center=(0.0, 0.0, 0.15), alpha=np.radians(10))
    coarse = hr.Medium.graded(0.30, lambda d: 3.0 + 20.0 * d, 0.30, step=0.002)
    n, d = 64, 0.012  # lambda/2.5 in the densest ground; 0.77 m: the beam never wraps
    x = (np.arange(n) - n / 2) * d
    X, Y = np.meshgrid(x, x)
    pts = np.stack([X.ravel(), Y.ravel(), np.full(X.size, ZA + 1e-9)], 1)
    top = beam.field(K, coarse, pts).reshape(n, n)
    pts[:, 2] = ZB
    bottom = beam.field(K, coarse, pts).reshape(n, n)
    pe = ParabolicEquation((n, n), (d, d), K, coarse, ZA, ZB, wide_angle=True)
    err = np.linalg.norm(pe.forward(top) - bottom) / np.linalg.norm(bottom)
    _, reflection = _bounds(np.array([0.0]))
    assert err <= 0.01 and err <= 2 * reflection + 1e-3


def test_graded_profiles_refuse_implausible_values():
    with pytest.raises(ValueError, match="below 1"):
        hr.Medium.graded(0.3, lambda d: 0.5 + d, 0.2)
    with pytest.raises(ValueError, match="negative imaginary part"):
        hr.Medium.graded(0.3, lambda d: 3.0 - 0.1j + 0 * d, 0.2)
    with pytest.raises(ValueError, match="larger than the profile's sample spacing"):
        hr.Medium.graded(0.3, ([0.0, 0.01, 0.02], [3.0, 4.0, 5.0]), 0.02, step=0.015)
    with pytest.raises(ValueError, match="step"):
        ParabolicEquation((4, 4), (0.01, 0.01), K, WET, ZA, ZB, step=0.5)


def test_a_constant_graded_ground_is_the_half_space():
    """Thin layers of one permittivity: interfaces between equal media transmit exactly 1,
    so migration through them equals migration through the half-space to rounding."""
    flat = hr.Medium.graded(0.30, lambda d: 4.0 + 0.04j + 0 * d, 0.2, step=0.01)
    half = hr.Medium.half_space(0.30, 4.0 + 0.04j)
    h = hr.simulate(hr.Scene(half, hr.PlaneWave(), [hr.PointTarget((0.0, 0.0, 0.42))]),
                    hr.Aperture.grid(24, 0.0125), 9.9e9)
    a = hr.migrate(h, [0.40, 0.42], medium=flat, upsample=2)
    b = hr.migrate(h, [0.40, 0.42], medium=half, upsample=2)
    assert np.allclose(a.data, b.data, rtol=0, atol=1e-9 * np.abs(b.data).max())


def test_glare_suppression_and_synthesis_take_a_graded_ground():
    """The graded ground is an ordinary layered Medium: the glare of a horn over it is
    removed (>= 20 dB at the mirror spot) and views synthesised through it focus on the
    object (within a pixel, 6.25 mm)."""
    wet = hr.Medium.graded(0.30, lambda d: 3.0 + 20.0 * d, 0.20, step=0.005)
    target = [hr.PointTarget((0.02, 0.0, 0.40), 0.02)]
    ap = hr.Aperture.grid(32, 0.0125)
    h = hr.simulate(hr.Scene(wet, hr.PointSource((0.0, 0.0, -0.05)), target), ap, 9.9e9)
    _, rep = hr.suppress_surface(h, wet, method="gaussian", direct=False)
    assert rep.glare_suppression_db >= 20
    views = [hr.simulate(hr.Scene(wet, hr.PlaneWave(np.radians(a), 0.0), target), ap, 9.9e9)
             for a in (-15, 0, 15)]
    img = hr.synthesize(views, [0.38, 0.40, 0.42], medium=wet, upsample=2)
    x, y, _ = img.peak()
    assert abs(x - 0.02) <= 0.00625 and abs(y) <= 0.00625
