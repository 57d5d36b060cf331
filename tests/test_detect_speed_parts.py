"""The fast parts of ``detect`` equal what they replace: the decimated local-noise
windows, the plane subset of the image check, the Gauss-Newton finish of the fit."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from conftest import migrate64
from holoradar.analysis.detect import noise as nz_noise
from holoradar.analysis.detect.grid import as_volume
from holoradar.analysis.detect.model import HologramModel
from holoradar.analysis.detect.smooth import LateralSmoother, spline_matrix

pytestmark = pytest.mark.filterwarnings("ignore::holoradar.AliasingWarning")


def _field(shape, seed=0, blur=(0.0, 2.0, 2.0)):
    """A complex Gaussian field with a smooth spectrum (noise through an aperture)."""
    from scipy.ndimage import gaussian_filter

    rng = np.random.default_rng(seed)
    d = rng.normal(size=shape) + 1j * rng.normal(size=shape)
    return gaussian_filter(d.real, blur) + 1j * gaussian_filter(d.imag, blur)


def _d5_reference(a, step, axis):
    """The stencil as first written: ``np.gradient``, its interior replaced."""
    d = np.gradient(a, step, axis=axis)
    s = [slice(None)] * a.ndim

    def take(lo, hi):
        s2 = list(s)
        s2[axis] = slice(lo, hi)
        return a[tuple(s2)]

    s[axis] = slice(2, -2)
    d[tuple(s)] = (-take(4, None) + 8 * take(3, -1) - 8 * take(1, -3) + take(0, -4)) / (12 * step)
    return d


def test_d5_equals_the_gradient_with_the_five_point_interior():
    a = _field((3, 9, 11), seed=1)
    for axis in (1, 2):
        # The same arithmetic reordered: equal to rounding (a few ulps of the values).
        assert np.allclose(nz_noise._d5(a, 0.01, axis), _d5_reference(a, 0.01, axis),
                           rtol=1e-12, atol=1e-12 * np.abs(a).max() / 0.01)


def test_spline_matrix_is_the_not_a_knot_cubic_spline():
    from scipy.interpolate import CubicSpline

    for rows, n in ((np.r_[np.arange(0, 125, 7), 124], 125), (np.arange(0, 9, 2), 9)):
        ref = CubicSpline(rows, np.eye(rows.size), axis=0)(np.arange(n))
        # The same linear map solved two ways: equal to rounding.
        assert np.allclose(spline_matrix(rows, n), ref, atol=1e-12)


def test_smoother_on_every_pixel_equals_the_fft_convolution():
    rng = np.random.default_rng(2)
    a = rng.exponential(size=(3, 50, 60))
    w = np.ones((50, 60))
    w[20:30, 25:35] = 0
    for sx, sy in ((9.0, 7.0), (3.0, 3.0)):
        s = LateralSmoother(w, sx, sy, decimate=False)
        # One kernel (the whole Gaussian, zero outside), two evaluations: rounding only.
        assert np.allclose(s.full(s.coarse(a)), nz_noise._smooth(a, w, sx, sy), rtol=1e-10,
                           atol=1e-12)


@pytest.mark.parametrize("sigma", [14.0, 4.6])
def test_decimated_smoothing_within_the_spline_bound(sigma):
    # White exponential "noise power" with a masked lobe, the worst input (flat spectrum).
    rng = np.random.default_rng(3)
    a = rng.exponential(size=(4, 125, 125))
    w = np.ones((125, 125))
    w[40:60, 50:70] = 0
    ref = LateralSmoother(w, sigma, sigma, decimate=False)
    dec = LateralSmoother(w, sigma, sigma)
    assert dec.rows_x.size < 125 / 1.9            # it does decimate (every D >= 2 pixels)
    exact = ref.coarse(a)
    approx = dec.full(dec.coarse(a))
    # Spline error of a mode p at knots D apart: (5/384)(p D)^4; the smoothed field holds
    # exp(-p^2 sigma^2/2) of it; at D = sigma/2 the product peaks at p sigma = 2 at
    # (5/384) e^-2 = 1.8e-3 of the input's amplitude there, at most the field's mean for
    # an exponential field (its std equals its mean): 2e-3 of the mean.
    assert np.max(np.abs(approx - exact)) < 2e-3 * a.mean()


@pytest.fixture(scope="module")
def residual():
    """Noise through an aperture (smooth spectrum, 4 pixels per cell laterally, 8 planes a
    range cell) with one object 30 dB over it."""
    from scipy.ndimage import gaussian_filter

    d = _field((48, 64, 64), seed=4, blur=(8.0, 2.0, 2.0))
    obj = np.zeros(d.shape)
    obj[24, 30, 34] = 1.0
    obj = gaussian_filter(obj, (8.0, 2.0, 2.0))     # imaged through the same band
    d += obj / obj.max() * np.abs(d).std() * 10 ** 1.5
    x = y = np.arange(64) * 0.0025
    z = 0.2 + np.arange(48) * 0.002
    return d, x, y, z


def test_local_noise_decimated_as_on_every_pixel(residual):
    d, x, y, z = residual
    mask = np.zeros((64, 64), bool)
    mask[28:33, 32:37] = True
    nz_noise._LAST.clear()
    fast = nz_noise.local_noise(d, mask, x, y, z, 1e-3)
    full = nz_noise.local_noise(d, mask, x, y, z, 1e-3, decimate=False)
    assert nz_noise.range_planes(z, fast.cell[2]).size < 48          # the planes were decimated
    assert fast.cell == full.cell and fast.n_ref == full.n_ref
    # The resels are integrals of fields each within ~2e-3 (lateral spline, above) and
    # ~5e-3 of its fluctuation (range spline at 8 planes a cell; the fluctuation of a
    # field averaged over ~100 cells is ~10 %): 1 % bounds them.
    assert np.allclose(fast.resels, full.resels, rtol=1e-2)
    # t moves with log(n_cells): d t = d n / n / (1 - 1/t ...) < 1 % of 1/t ~ 1e-3 relative.
    assert abs(fast.t / full.t - 1) < 1e-3
    # The noise map, interpolated in its logarithm: the lateral bound, 2e-3 (x2 margin for
    # the ratio to the local value near the masked lobe).
    assert np.max(np.abs(fast.sigma2 / full.sigma2 - 1)) < 4e-3


def test_local_noise_remembers_only_the_same_inputs(residual):
    d, x, y, z = residual
    mask = np.zeros((64, 64), bool)
    nz_noise._LAST.clear()
    a = nz_noise.local_noise(d, mask, x, y, z, 1e-3)
    assert nz_noise.local_noise(d, mask, x, y, z, 1e-3) is a
    d2 = d.copy()
    d2[0, 0, 0] += 1.0                              # one pixel changed in place: recomputed
    assert nz_noise.local_noise(d2, mask, x, y, z, 1e-3) is not a
    mask2 = mask.copy()
    mask2[0, 0] = True
    assert nz_noise.local_noise(d, mask2, x, y, z, 1e-3) is not a


@pytest.fixture(scope="module")
def small():
    sand = hr.Medium.half_space(0.10, 2.5 + 0.0125j)
    scene = hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget((0.01, -0.005, 0.17))])
    h = hr.simulate(scene, hr.Aperture.grid(16, 0.01, monostatic=True),
                    np.linspace(8e9, 12e9, 3), include_surface=False, snr_db=20, seed=5)
    img = migrate64(h, np.linspace(0.13, 0.21, 20), medium=sand, upsample=2)
    return h, img, sand


def test_image_check_on_a_few_planes(small):
    h, img, sand = small
    model = HologramModel(h, as_volume(img), sand, {})
    planes = model.check_planes()
    assert planes[-1] == 19 and planes.size == 5 and np.ptp(np.diff(planes)) == 0
    # Each plane of a migration is its own: the subset equals the whole volume's planes
    # to rounding.
    assert np.allclose(model.image(model.res, planes), img.data[planes], rtol=0,
                       atol=1e-12 * np.abs(img.data).max())
    model.start()                                   # passes
    other = h.with_data(h.data * np.exp(0.3j * np.arange(h.nf))[:, None, None])
    with pytest.raises(ValueError, match="image is not migrate"):
        HologramModel(other, as_volume(img), sand, {}).start()


def test_gauss_newton_finish_is_the_matched_filters_maximum(small):
    h, img, sand = small
    model = HologramModel(h, as_volume(img), sand, {})
    p = np.abs(img.data)
    iz, iy, ix = np.unravel_index(np.argmax(p), p.shape)
    start = (float(img.x[ix]), float(img.y[iy]), float(img.z[iz]))
    cell = model._cell(start[2])
    r = model.fit_position(start, model.res, cell)
    F0, a, g = model.focus(r, model.res)
    model.objects.append({"r": r, "a": a, "g": g})
    model.res = model.res - a[:, None] * g
    std = model.uncertainty()[0]
    model.res = model.res + a[:, None] * g
    # A maximum: F falls a step of one standard deviation away along every axis (it falls
    # by ~ 1/(2 |a|^2/s^2 ...) there, far above rounding), and Nelder-Mead driven to a
    # thousandth of the standard deviation lands within the Gauss-Newton stop (a tenth
    # of it) of the same point.
    for j in range(3):
        for sgn in (-1, 1):
            e = np.zeros(3)
            e[j] = sgn * std[j]
            assert model.focus(r + e, model.res)[0] < F0
    from scipy.optimize import minimize

    res = minimize(lambda v: -model.focus(v, model.res)[0] / model.energy(model.res), r,
                   method="Nelder-Mead",
                   options={"initial_simplex": np.vstack([r] + [r + np.diag(std)[i]
                                                                for i in range(3)]),
                            "xatol": 1e-3 * float(std.min()), "fatol": 0, "maxiter": 2000})
    assert np.all(np.abs(res.x - r) <= 0.1 * std + 1e-3 * std)


def test_objects_image_is_the_frozen_migration_of_the_response(small):
    # The model images a response with the migration operator frozen on the original
    # hologram (its weights and SNR): migrate of the response with those settings
    # given explicitly. The backends sum a band's spectra before the inverse FFT, or
    # image each frequency; the same linear operations in another order: rounding.
    h, img, sand = small
    model = HologramModel(h, as_volume(img), sand, {})
    model.start()
    plan = model.migration.plan
    g = model.response(np.array([0.0, 0.01, 0.18]))
    fast = model.image(g)
    slow = migrate64(h.with_data(g.reshape(h.data.shape)), img.z, medium=sand, upsample=2,
                      equalize=plan.weights, snr_db=plan.snr_db, algorithm="frequency").data
    assert np.allclose(fast, slow, rtol=0, atol=1e-12 * np.abs(slow).max())
    # A plane: the model images that plane alone.
    plane = migrate64(h, float(img.z[5]), medium=sand, upsample=2)
    single = HologramModel(h, as_volume(plane), sand, {})
    single.start()
    assert single.image(g).shape == (1, *plane.data.shape)


def test_range_derivative_equals_numpy_gradient():
    a = _field((7, 5, 6), seed=6)
    z = 0.2 + np.arange(7) * 0.003
    # The same differences and spacings: equal to rounding (a few ulps of a / dz).
    assert np.allclose(nz_noise._dz(a, z), np.gradient(a, z, axis=0), rtol=1e-12,
                       atol=1e-12 * np.abs(a).max() / 0.003)
    zn = z + 0.0005 * np.arange(7) ** 2                # non-uniform planes: numpy's own
    assert np.array_equal(nz_noise._dz(a, zn), np.gradient(a, zn, axis=0))
