"""Migration of closed-form fields: point-source focus, resolution, spectral window.

Paper sections 3.1 and the spectral-window theory (Eqs. 5-7).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from conftest import F0, migrate64
from holoradar import theory
from holoradar.analysis.metrics import main_lobe_width, peak_position

LAM = hr.C0 / F0
K = 2 * np.pi / LAM


def point_hologram(src, n, pitch):
    """The exact spherical wave exp(ikR)/R of a point source sampled on the aperture."""
    ap = hr.Aperture.grid(n, pitch)
    R = np.linalg.norm(ap.points - np.asarray(src), axis=1)
    return hr.Hologram((np.exp(1j * K * R) / R).reshape(n, n), ap.x, ap.y, F0)


def test_point_source_focuses_at_its_position():
    # lambda/2 grid, 96 x 96 (1.45 m) at 0.5 m: Fresnel number a^2/(lambda z) = 35, where
    # the paraxial focal shift is 0.2 mm (theory.focal_shift), far below the bounds:
    # lateral lambda/20 (issue), range lambda/4 (quarter-wave focus criterion).
    src = np.array([0.0123, -0.0071, 0.5])
    h = point_hologram(src, 96, LAM / 2)
    A = 96 * LAM / 2
    assert theory.fresnel_number(A, LAM, 0.5) > 30
    img = migrate64(h, np.linspace(0.47, 0.53, 61), upsample=4)
    x, y, z = peak_position(img)
    assert np.hypot(x - src[0], y - src[1]) < LAM / 20
    assert abs(z - src[2]) < LAM / 4


def test_main_lobe_width_is_lambda_z_over_a():
    # Paraxial geometry (a/z = 0.25: sin and tan of the edge angle differ by 3%) at
    # 2 m, 66 elements at lambda/2: the first null of sin(mu x)/x lies at lambda z/A.
    # The 1/R taper of the spherical wave and the sin/tan difference widen the lobe by
    # a few percent; the bound is 10%.
    z, n = 2.0, 66
    src = np.array([0.0, 0.0, z])
    h = point_hologram(src, n, LAM / 2)
    img = migrate64(h, z, upsample=8)
    iy = int(np.argmin(np.abs(img.y - src[1])))
    delta = main_lobe_width(img.data[iy], img.x) / 2
    expected = theory.lateral_resolution(LAM, z, n * LAM / 2)
    assert abs(delta / expected - 1) < 0.10
    ix = int(np.argmin(np.abs(img.x - src[0])))
    delta_y = main_lobe_width(img.data[:, ix], img.y) / 2
    assert abs(delta_y / expected - 1) < 0.10


def test_fresnel_agrees_with_angular_in_paraxial_regime():
    # 14 x 14 at lambda/2 (21 cm) imaged at 3 m. The Fresnel kernel's phase error
    # k rho^4/(8 z^3) is 0.8% rad and its amplitude error rho^2/z^2 is 1% at the largest
    # element-to-pixel distance rho = sqrt(2)*A; both are far smaller over most of the
    # aperture, so the images agree to better than 1% (rms).
    z = 3.0
    h = point_hologram([0.01, -0.005, z], 14, LAM / 2)
    a = migrate64(h, z).data
    f = migrate64(h, z, method="fresnel").data
    assert np.linalg.norm(a - f) / np.linalg.norm(a) < 0.01


def test_fresnel_differs_outside_paraxial_regime():
    # 40 x 40 at lambda/2 (61 cm) at 0.3 m: the paraxial phase error at the corner is
    # hundreds of radians, so the paraxial image must differ grossly (> 10%).
    z = 0.3
    h = point_hologram([0.0, 0.0, z], 40, LAM / 2)
    a = migrate64(h, z).data
    f = migrate64(h, z, method="fresnel").data
    assert np.linalg.norm(a - f) / np.linalg.norm(a) > 0.1


@pytest.mark.parametrize("tilt_deg", [(12.0, -6.0), (0.0, 0.0), (-8.0, 15.0)])
def test_spectral_window_of_tilted_illumination(tilt_deg):
    # Paper Eqs. 5-7: for an object f lit at (p0, q0), the chirped image with the
    # incident phase removed, g~ conj(E0), has spectrum F~(p, q) on the rectangle
    # |p + p0| <= mu, |q + q0| <= nu. A 40 cm patch of random (white) reflectivity fills
    # that rectangle; its speckle is averaged over 4 realisations and over the other
    # axis. Paraxial geometry (a/dist = 0.24: k a/dist and k sin(atan(a/dist)) differ
    # by 1 rad/m); the edges must match theory to one bin 2*pi/A of the image's FFT.
    dist, n, dx = 1.0, 32, LAM / 2
    a0, b0 = np.radians(tilt_deg[0]), np.radians(tilt_deg[1])
    src = hr.PlaneWave(a0, b0)
    ap = hr.Aperture.grid(n, dx)
    X, Y = np.meshgrid(ap.x, ap.y)
    p0, q0 = src.wavenumbers(K)
    u = np.arange(-40, 41) * 0.005
    m = 8 * n  # zero-padded FFT: interpolates the spectrum, the bin stays 2*pi/A
    power = np.zeros((m, m))
    for seed in range(4):
        rng = np.random.default_rng(seed)
        refl = rng.standard_normal((81, 81)) + 1j * rng.standard_normal((81, 81))
        scene = hr.Scene(source=src, targets=[hr.PlanarTarget(refl, u, u, dist)])
        g = migrate64(hr.simulate(scene, ap, F0), dist).data
        gt = g * np.exp(1j * K * (X**2 + Y**2) / (2 * dist)) * np.exp(-1j * (p0 * X + q0 * Y))
        power += np.abs(np.fft.fftshift(np.fft.fft2(gt, s=(m, m)))) ** 2
    p = np.fft.fftshift(np.fft.fftfreq(m, dx)) * 2 * np.pi
    w = theory.spectral_window(F0, n * dx, dist, alpha0=a0, beta0=b0)
    bin_ = 2 * np.pi / (n * dx)
    for prof, (lo, hi) in ((power.mean(axis=0), w.p_range), (power.mean(axis=1), w.q_range)):
        plateau = np.median(prof[prof > 0.5 * prof.max()])
        inside = np.nonzero(prof > 0.5 * plateau)[0]
        assert abs(p[inside[0]] - lo) <= bin_
        assert abs(p[inside[-1]] - hi) <= bin_


def test_paper_resolution_check():
    # Paper: lambda = 3 cm, l = 60 cm, A = 40 cm -> delta = 4.5 cm.
    assert theory.lateral_resolution(0.03, 0.60, 0.40) == pytest.approx(0.045)
    w = theory.spectral_window(hr.C0 / 0.03, 0.40, 0.60)
    assert np.pi / w.mu == pytest.approx(0.045)


def test_longitudinal_resolution_matches_migrated_point():
    # On-axis intensity of a migrated point against range: its FWHM is the theory's
    # (Fresnel-integral) value; a/z = 0.25 keeps it paraxial. The 1/z amplitude makes
    # the curve slightly asymmetric (the focal shift, 6% of the FWHM here); allow 10%.
    z, n = 2.0, 66
    h = point_hologram([0.0, 0.0, z], n, LAM / 2)
    A = n * LAM / 2
    fw = theory.longitudinal_resolution(LAM, z, A)
    zs = np.linspace(z - 1.2 * fw, z + 1.2 * fw, 241)
    img = migrate64(h, zs)
    on_axis = np.abs(img.data[:, n // 2, n // 2]) ** 2  # even n: the sample nearest 0
    on_axis /= on_axis.max()
    above = zs[on_axis >= 0.5]
    assert abs((above[-1] - above[0]) / fw - 1) < 0.10


def test_upsample_interpolates_exactly():
    # Zero-padding the spectrum interpolates: every u-th output sample is the original.
    h = point_hologram([0.01, 0.0, 0.4], 24, LAM / 2)
    a = migrate64(h, 0.4).data
    b = migrate64(h, 0.4, upsample=4).data
    np.testing.assert_allclose(b[::4, ::4], a, atol=1e-10 * np.abs(a).max())


def test_scalar_and_sequence_shapes():
    h = point_hologram([0.0, 0.0, 0.4], 16, LAM / 2)
    assert migrate64(h, 0.4).data.shape == (16, 16)
    img = migrate64(h, [0.3, 0.4])
    assert img.data.shape == (2, 16, 16)
    assert img.z.tolist() == [0.3, 0.4]
    batch = h.with_data(np.stack([h.data, 2 * h.data]))
    assert migrate64(batch, [0.3, 0.4, 0.5]).data.shape == (2, 3, 16, 16)
    np.testing.assert_allclose(migrate64(batch, 0.4).data[1], 2 * migrate64(h, 0.4).data)


def test_odd_and_rectangular_grids_focus():
    ap = hr.Aperture.grid(41, LAM / 2, ny=33)
    src = np.array([-0.013, 0.021, 0.35])
    R = np.linalg.norm(ap.points - src, axis=1)
    h = hr.Hologram((np.exp(1j * K * R) / R).reshape(33, 41), ap.x, ap.y, F0)
    img = migrate64(h, np.linspace(0.32, 0.38, 31), upsample=4)
    x, y, _ = peak_position(img)
    assert np.hypot(x - src[0], y - src[1]) < LAM / 20


def test_input_is_not_modified():
    data = np.ones((8, 8), complex)
    x = np.arange(8) * 0.01
    h = hr.Hologram(data, x, x, F0)
    data[0, 0] = 5
    assert h.data[0, 0] == 1
    before = h.data.copy()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        migrate64(h, 0.3)
    np.testing.assert_array_equal(h.data, before)


def test_full_field_of_view_sees_beside_the_array():
    # A point 5 cm beyond the edge of a 24 cm array: fov="full" images the padded grid
    # centred on the aperture and finds it there. Seen from one side only, its image is
    # a one-sided focus whose peak may move by a fraction of the resolution cell
    # lambda*z/A (3.8 cm): require a quarter. The default view is a crop of the same.
    src = np.array([0.165, -0.03, 0.3])
    h = point_hologram(src, 24, 0.01)
    full = migrate64(h, [0.3], fov="full", upsample=2)
    x, y, _ = peak_position(full)
    assert x > h.x[-1]  # outside the aperture, where the default view cannot look
    assert np.hypot(x - src[0], y - src[1]) < theory.lateral_resolution(LAM, 0.3, 0.24) / 4
    crop = migrate64(h, [0.3], upsample=2)
    ix = int(np.argmin(np.abs(full.x - crop.x[0])))
    iy = int(np.argmin(np.abs(full.y - crop.y[0])))
    np.testing.assert_allclose(full.data[0, iy:iy + crop.y.size, ix:ix + crop.x.size],
                               crop.data[0], atol=1e-12 * np.abs(crop.data).max())


@pytest.mark.parametrize("pitch_over_lambda", [0.5, 0.25, 0.125])
def test_default_padding_holds_at_long_range(pitch_over_lambda):
    """A 21 cm aperture focused at 2 m (Fresnel number ~0.7): plain 2x padding
    left 45% errors there (too few spectral samples across the band it sees).
    ``pad=True`` must match a 16x padded grid, which samples every transfer phase
    many times over. The aperture sees the point within 3 degrees of the axis;
    what ``pad=True`` drops (components steeper than its grid spans) carries
    none of that, so the images differ by the band-limit edge only: < 2%."""
    lam = hr.C0 / F0
    k = 2 * np.pi / lam
    dx = pitch_over_lambda * lam
    n = round(0.21 / dx)
    x = (np.arange(n) - n / 2) * dx
    X, Y = np.meshgrid(x, x)
    R = np.sqrt(X**2 + Y**2 + 2.0**2)
    h = hr.Hologram(np.exp(1j * k * R) / R, x, x, F0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        img = migrate64(h, 2.0).data
        ref = migrate64(h, 2.0, pad=16.0).data
    assert np.linalg.norm(img - ref) / np.linalg.norm(ref) < 0.02


def test_unasked_progress_bar_only_on_a_terminal(monkeypatch):
    """progress=None: a bar for long work (over 2e8 output pixels) on a terminal only; in
    a pipe or a log file none (a bar's redraws are noise there)."""
    import sys
    from types import SimpleNamespace

    from holoradar.imaging.migration.backends.planes import _Progress

    plan = SimpleNamespace(settings=SimpleNamespace(progress=None, upsample=1),
                           z=np.zeros(1000), grid=(512, 512))
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    assert _Progress(plan, 1).bar is None
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    p = _Progress(plan, 1)
    assert p.bar is not None
    p.close()
    plan.settings.progress = False
    assert _Progress(plan, 1).bar is None
