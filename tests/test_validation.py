"""Bad input: a clear ValueError naming the argument; aliasing warns and goes on."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from conftest import F0

X = np.arange(8) * 0.01


def _h(**kw):
    args = {"data": np.ones((8, 8), complex), "x": X, "y": X, "frequency": F0}
    args.update(kw)
    return hr.Hologram(args.pop("data"), args.pop("x"), args.pop("y"), args.pop("frequency"))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nonfinite_data(bad):
    d = np.ones((8, 8), complex)
    d[2, 3] = bad
    with pytest.raises(ValueError, match="data must be finite"):
        _h(data=d)


def test_shape_coordinate_mismatch():
    with pytest.raises(ValueError, match="x must have 8 values"):
        _h(x=np.arange(7) * 0.01)
    with pytest.raises(ValueError, match="y must have 8 values"):
        _h(y=np.arange(9) * 0.01)
    with pytest.raises(ValueError, match="data must have at least 2 dimensions"):
        _h(data=np.ones(8))


def test_non_increasing_axis():
    # Decreasing throughout: reversed with its data (tests/test_grid_axes.py); out of
    # order: refused.
    x = X.copy()
    x[[0, 1]] = x[[1, 0]]
    with pytest.raises(ValueError, match="x must be strictly increasing"):
        _h(x=x)


def test_non_uniform_grid_refused_by_migrate():
    x = np.array([0, 0.01, 0.02, 0.035, 0.04, 0.05, 0.06, 0.07])
    h = _h(x=x)  # a non-uniform grid is a valid hologram...
    with pytest.raises(ValueError, match="x must be uniformly spaced"):
        hr.migrate(h, 0.3)  # ...but FFT migration needs a uniform one


@pytest.mark.parametrize("z", [-0.1, [0.2, -0.01], np.nan])
def test_negative_or_nonfinite_range(z):
    with pytest.raises(ValueError, match="z must be"):
        hr.migrate(_h(), z)


@pytest.mark.parametrize("f", [0.0, -9.9e9, np.nan, "ghz"])
def test_bad_frequency(f):
    with pytest.raises(ValueError, match="frequency must be a positive"):
        _h(frequency=f)
    with pytest.raises(ValueError, match="frequency must be a positive"):
        hr.simulate(hr.Scene(), hr.Aperture.grid(4, 0.01), f)


def test_gain_medium_refused():
    with pytest.raises(ValueError, match="negative imaginary part"):
        hr.Medium.half_space(0.3, 2.5 - 0.1j)
    with pytest.raises(ValueError, match="negative imaginary part"):
        hr.Medium.layered([0.3, 0.4], [2.5, 4 - 1j])


def test_bad_medium_geometry():
    with pytest.raises(ValueError, match="z_interfaces must be finite ranges >= 0"):
        hr.Medium.half_space(-0.1, 2.5)
    with pytest.raises(ValueError, match="strictly increasing"):
        hr.Medium.layered([0.4, 0.3], [2.5, 4.0])
    with pytest.raises(ValueError, match="one value per interface"):
        hr.Medium.layered([0.3], [2.5, 4.0])


def test_bad_method_upsample_pad():
    with pytest.raises(ValueError, match="method must be"):
        hr.migrate(_h(), 0.3, method="kirchhoff")
    with pytest.raises(ValueError, match="upsample must be an integer >= 1"):
        hr.migrate(_h(), 0.3, upsample=0)
    with pytest.raises(ValueError, match="pad must be"):
        hr.migrate(_h(), 0.3, pad=0.5)
    with pytest.raises(ValueError, match=r"hologram must be a holoradar\.Hologram"):
        hr.migrate(np.ones((8, 8)), 0.3)
    with pytest.raises(ValueError, match="z must be > 0 with method='fresnel'"):
        hr.migrate(_h(), 0.0, method="fresnel")


def test_bad_sources_and_targets():
    with pytest.raises(ValueError, match="position must be three finite"):
        hr.PointSource((0, 0))
    with pytest.raises(ValueError, match="propagating wave"):
        hr.PlaneWave(np.pi / 2, 0.1)
    with pytest.raises(ValueError, match="waist must be a positive"):
        hr.GaussianBeam(0.0)
    with pytest.raises(ValueError, match="position z must be > 0"):
        hr.PointTarget((0, 0, -0.1))
    with pytest.raises(ValueError, match="targets\\[0\\] must be"):
        hr.Scene(targets=["rock"])
    scene = hr.Scene(hr.Medium.half_space(0.3, 2.5), hr.PointSource((0, 0, 0.35)))
    with pytest.raises(ValueError, match="must lie above the ground surface"):
        hr.simulate(scene, hr.Aperture.grid(4, 0.01), F0)
    with pytest.raises(ValueError, match=r"shape \(N, 2\) or \(N, 3\)"):
        hr.simulate(hr.Scene(), np.ones((4, 5)), F0)


def test_coarse_pitch_warns_and_goes_on():
    x = np.arange(16) * 0.025  # the paper's array: 2.5 cm > lambda/2 = 1.5 cm
    h = hr.Hologram(np.ones((16, 16)), x, x, F0)
    with pytest.warns(hr.AliasingWarning, match=r"exceeds lambda/2.*37\.\d degrees"):
        img = hr.migrate(h, 0.4)
    assert np.all(np.isfinite(img.data))


def test_theory_refuses_bad_arguments():
    from holoradar import theory

    with pytest.raises(ValueError, match="distance must be > 0"):
        theory.lateral_resolution(0.03, -0.6, 0.4)
    with pytest.raises(ValueError, match="distance must be > 0"):
        theory.longitudinal_resolution(0.03, 0.0, 0.4)
    with pytest.raises(ValueError, match=r"Im\(eps\) >= 0"):
        theory.apparent_distance(0.5, 0.3, 9 - 1j)
    with pytest.raises(ValueError, match="theta must be an angle"):
        theory.fresnel_coefficients(1.0, 4.0, 2.0)
    with pytest.raises(ValueError, match="frequency must be a positive"):
        theory.wavelength(0.0)


def test_more_bad_arguments_name_themselves():
    with pytest.raises(ValueError, match="z_surface must be a range"):
        hr.Medium.half_space(None, 2.5)
    with pytest.raises(ValueError, match="n must be a whole number"):
        hr.Aperture.grid(2.7, 0.01)
    with pytest.raises(ValueError, match=r"dtype must be numpy\.complex64"):
        hr.migrate(_h(), 0.3, dtype=float)
    with pytest.raises(ValueError, match="snr_db must be a number"):
        hr.simulate(hr.Scene(), hr.Aperture.grid(4, 0.01), F0, snr_db="ten")
    with pytest.raises(ValueError, match="alpha must be finite"):
        hr.PlaneWave(np.nan, 0.0)
    with pytest.raises(ValueError, match="propagating beam"):
        hr.GaussianBeam(0.05, alpha=1.4, beta=1.4)
    with pytest.raises(ValueError, match="amplitude must be a finite complex"):
        hr.PointSource((0, 0, 0), amplitude="loud")
    with pytest.raises(ValueError, match="amplitude must be finite"):
        hr.PointTarget((0, 0, 0.4), amplitude=np.nan)
    with pytest.raises(ValueError, match="source must be a PlaneWave"):
        hr.Hologram(np.ones((4, 4)), X[:4], X[:4], F0, source=42)
    layered = hr.Medium.layered(0.3, [2.5])  # a scalar interface is one interface
    assert layered.z_interfaces == (0.3,)


def test_inputs_are_copied_not_shared():
    x = np.arange(8) * 0.01
    h = hr.Hologram(np.ones((8, 8)), x, x, F0)
    x[0] = 5.0  # the caller may still write to their array ...
    assert h.x[0] == 0.0  # ... and the hologram does not see it
    pos = np.array([0.0, 0.0, 0.1])
    src = hr.PointSource(pos)
    pos[2] = 0.9
    assert src.position[2] == 0.1
