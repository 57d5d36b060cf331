"""Samples at scattered positions: the grid's imaging through non-uniform FFTs.

* Samples on a grid's points are that grid: the image is the grid's ``migrate`` with
  the same padding, to the non-uniform FFT's precision.
* The operator and its adjoint agree (dot test).
* A freehand scan (wobbling sweeps, jittered positions, an unscanned hole) of three
  points, its data the closed form ``exp(2ikR)/R^2`` (not holoradar's simulator): the
  image against the matched filter written out as a sum over samples and pixels, and
  the points where they are.
"""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from holoradar.imaging.samples import SamplesBox, image_axes

C0 = 299792458.0
F = np.linspace(8e9, 12e9, 6)
POINTS = [(0.0, 0.0, 0.10), (0.03, 0.025, 0.12), (-0.03, -0.02, 0.09)]


def _freehand(seed: int = 0) -> np.ndarray:
    """Ten wobbling sweeps along x over a 10 cm patch, a 3 mm step with 0.5 mm of
    jitter, the sweeps 1 cm apart wobbling by 2 mm, a 2 cm hole left unscanned."""
    rng = np.random.default_rng(seed)
    out = []
    for j, y0 in enumerate(np.linspace(-0.05, 0.05, 10)):
        x = np.arange(-0.05, 0.05, 0.003) + rng.normal(0, 0.0005, 34)
        y = y0 + 0.002 * np.sin(40 * x + j) + rng.normal(0, 0.0005, x.size)
        out.append(np.column_stack([x, y]))
    p = np.concatenate(out)
    return p[np.hypot(p[:, 0] - 0.02, p[:, 1] + 0.01) > 0.02]


def _point_data(p: np.ndarray, f: np.ndarray) -> np.ndarray:
    k = 2 * np.pi * f[:, None] / C0
    d = 0
    for px, py, pz in POINTS:
        R = np.sqrt((p[:, 0] - px) ** 2 + (p[:, 1] - py) ** 2 + pz**2)
        d = d + np.exp(2j * k * R) / R**2
    return d


def test_samples_on_a_grid_are_that_grid():
    sand = hr.Medium.half_space(0.05, 4.0)
    h = hr.simulate(hr.Scene(sand, targets=[hr.PointTarget((0.01, -0.02, 0.12))]),
                    hr.Aperture.grid(24, 0.004, monostatic=True), F, include_surface=False)
    X, Y = np.meshgrid(h.x, h.y)
    s = hr.Hologram.from_samples(h.data.reshape(F.size, -1),
                                 np.column_stack([X.ravel(), Y.ravel()]), F, monostatic=True)
    zs = np.linspace(0.08, 0.16, 9)
    img = hr.migrate(s, zs, medium=sand, x=h.x, y=h.y)
    box = SamplesBox.of(s, h.x, h.y)
    assert box.mx == box.my
    ref = hr.migrate(h, zs, medium=sand, pad=box.mx / h.x.size)
    # finufft's eps 1e-9 and complex64 images (rounding ~1e-7 a step over a few dozen
    # steps): 1e-5 of the peak is far above both and far below any physics error
    err = np.max(np.abs(img.data - ref.data)) / np.max(np.abs(ref.data))
    assert err < 1e-5, err
    np.testing.assert_allclose(img.x, h.x)


def test_the_operator_and_its_adjoint_agree():
    p = _freehand(1)
    s = hr.Hologram.from_samples(_point_data(p, F), p, F, monostatic=True)
    A = hr.migration_operator(s, [0.09, 0.1, 0.11])
    rng = np.random.default_rng(3)
    a = rng.standard_normal(A.shape[1]) + 1j * rng.standard_normal(A.shape[1])
    b = rng.standard_normal(A.shape[0]) + 1j * rng.standard_normal(A.shape[0])
    lhs, rhs = np.vdot(b, A @ a), np.vdot(A.H @ b, a)
    # complex128 throughout; finufft's type 1 and type 2 share their spreading kernel
    # and are adjoint to rounding: 1e-10 is rounding over ~1e5 terms
    assert abs(lhs - rhs) < 1e-10 * abs(lhs)


def test_a_freehand_scan_images_as_its_matched_filter_and_finds_its_points():
    p = _freehand(0)
    d = _point_data(p, F)
    s = hr.Hologram.from_samples(d, p, F, monostatic=True)
    xs = ys = np.linspace(-0.045, 0.045, 19)
    zs = np.linspace(0.08, 0.13, 6)
    img = hr.migrate(s, zs, x=xs, y=ys, dtype=np.complex128)
    # The back-propagation written out as a sum over samples and pixels: each frequency
    # weighted by 1 / its RMS (as migrate's equalize=True). The grid's transfer
    # exp(-i kz z), kz the round trip's (2k), is in space the Rayleigh-Sommerfeld kernel
    # -(1/2 pi) d/dz [exp(-2ikR)/R] = (ik/pi) (z/R) exp(-2ikR)/R (1 + i/(2kR)), the
    # last factor 1 within 1/(2kR) < 4 % here: the kernel (z/R^2) exp(-2ikR).
    k = 2 * np.pi * F / C0
    w = 1 / np.sqrt(np.mean(np.abs(d) ** 2, axis=1))
    Z, Yg, Xg = np.meshgrid(zs, ys, xs, indexing="ij")
    R = np.sqrt((Xg.ravel()[:, None] - p[:, 0]) ** 2 + (Yg.ravel()[:, None] - p[:, 1]) ** 2
                + Z.ravel()[:, None] ** 2)
    kernel = Z.ravel()[:, None] / R**2
    mf = sum(w[i] * k[i] * ((kernel * np.exp(-2j * k[i] * R)) @ d[i]) for i in range(F.size))
    a, b = np.abs(img.data.ravel()) ** 2, np.abs(mf) ** 2
    # What is left apart: the box's periodic sum (its copies 2x the extent away) and
    # the evanescent band the sum keeps and the transfer drops. The bound asked of the
    # method (against a matched filter): 0.98.
    assert np.corrcoef(a, b)[0, 1] >= 0.98
    fine = hr.migrate(s, np.arange(0.08, 0.13, 0.002), x=np.arange(-0.05, 0.05, 0.0015),
                      y=np.arange(-0.05, 0.05, 0.0015))
    lam = C0 / F.mean()
    cell = C0 / (2 * np.ptp(F))
    mag = np.abs(fine.data)
    for px, py, pz in POINTS:
        near = (np.abs(fine.x - px) < 0.01)[None, None, :] & \
            (np.abs(fine.y - py) < 0.01)[None, :, None] & \
            (np.abs(fine.z - pz) < 0.015)[:, None, None]
        iz, iy, ix = np.unravel_index(np.argmax(np.where(near, mag, 0)), mag.shape)
        assert abs(fine.x[ix] - px) <= lam / 10 and abs(fine.y[iy] - py) <= lam / 10
        assert abs(fine.z[iz] - pz) <= cell / 4


def test_default_grid_is_the_image_bands_nyquist_spacing():
    p = _freehand(0)
    s = hr.Hologram.from_samples(np.ones((F.size, len(p))), p, F, monostatic=True)
    x, y = image_axes(s)
    assert np.isclose(x[1] - x[0], C0 / F.max() / 4)
    assert x[0] >= p[:, 0].min() and x[-1] <= p[:, 0].max()
    assert y[0] >= p[:, 1].min() and y[-1] <= p[:, 1].max()


@pytest.mark.parametrize("args, kwargs, match", [
    ((np.ones(5), np.zeros((4, 2)) + np.arange(4)[:, None] * 0.01, 10e9), {},
     r"data must have shape \(nf, n\) = \(1, 4\)"),
    ((np.ones(3), [[0, 0], [np.nan, 0], [0.01, 0]], 10e9), {}, "1 of 3 hold NaN"),
    ((np.ones(3), [[0, 0], [0.01, 0], [0, 0]], 10e9), {}, "1 repeat an earlier position"),
    ((np.ones(3), [[0, 0], [120, 0], [240, 0]], 10e9), {}, "millimetres given as metres"),
    ((np.ones(2), [[0, 0], [0.01, 0]], 10e9), {"tx": np.zeros((2, 3))}, "tx: transmitter"),
    ((np.ones(2), [[0, 0], [0.01, 0]], 10e9), {"monostatic": True,
                                              "source": hr.PlaneWave()}, "source: a transceiver"),
])
def test_bad_samples_are_refused_by_name(args, kwargs, match):
    with pytest.raises(ValueError, match=match):
        hr.Hologram.from_samples(*args, **kwargs)


def test_grid_only_options_are_refused():
    p = _freehand(0)
    s = hr.Hologram.from_samples(np.ones((F.size, len(p))), p, F, monostatic=True)
    with pytest.raises(ValueError, match="upsample: scattered samples"):
        hr.migrate(s, 0.1, upsample=2)
    with pytest.raises(ValueError, match="x must be uniform"):
        hr.migrate(s, 0.1, x=[0.0, 0.01, 0.03])


def test_coverage_finds_the_hole_and_a_nyquist_grid_covers_everything():
    from holoradar.imaging.samples import coverage

    # A grid at exactly the band's Nyquist spacing (lambda_min / 4, a transceiver):
    # every pixel is within spacing / sqrt(2) of a sample.
    s = C0 / F.max() / 4
    g = np.arange(0, 0.08, s)
    X, Y = np.meshgrid(g, g)
    grid = hr.Hologram.from_samples(np.ones((F.size, X.size)),
                                    np.column_stack([X.ravel(), Y.ravel()]), F,
                                    monostatic=True)
    c = coverage(grid, x=np.linspace(0, g[-1], 41), y=np.linspace(0, g[-1], 41))
    assert c.fraction == 1.0
    # the freehand scan's 2 cm hole at (2, -1) cm is uncovered, its sweeps are not
    p = _freehand(0)
    c = coverage(hr.Hologram.from_samples(np.ones((F.size, len(p))), p, F, monostatic=True),
                 x=np.linspace(-0.04, 0.04, 33), y=np.linspace(-0.04, 0.04, 33))
    ix, iy = np.argmin(np.abs(c.x - 0.02)), np.argmin(np.abs(c.y + 0.01))
    assert not c.covered[iy, ix]
    # Sweeps 1.1 cm apart, 3 mm steps along them: a pixel is covered within
    # sqrt((6.25 / sqrt 2)^2 - 1.5^2) = 4.2 mm of a sweep, 8.3 mm of each 11.1 mm (0.75);
    # the hole takes pi 2^2 / 8^2 = 20 % of the patch: about 0.75 x 0.8 = 0.6
    assert 0.5 < c.fraction < 0.75


def test_a_stream_of_batches_is_the_image_of_all_its_samples():
    from holoradar.imaging.samples_stream import SampleStream

    p = _freehand(0)
    d = _point_data(p, F)
    xs = ys = np.linspace(-0.06, 0.06, 25)
    zs = [0.09, 0.1, 0.12]
    stream = SampleStream(F, zs, xs, ys, monostatic=True, dtype=np.complex128)
    for i in range(0, len(p), 97):    # batches as a tracker delivers them
        stream.add(d[:, i:i + 97], p[i:i + 97])
    s = hr.Hologram.from_samples(d, p, F, monostatic=True)
    ref = hr.migrate(s, zs, x=xs, y=ys, dtype=np.complex128)
    # the same box (the samples lie inside the grid's extent) and the same sum, taken in
    # batches: the transforms' rounding (finufft eps 1e-9)
    assert stream.n == len(p)
    err = np.max(np.abs(stream.image().data - ref.data)) / np.max(np.abs(ref.data))
    assert err < 1e-7, err
    with pytest.raises(ValueError, match="outside the image's box"):
        stream.add(np.ones((F.size, 2)), [[5.0, 0.0], [5.01, 0.0]])
