"""Wideband and scanned-transceiver (monostatic) holograms: frequency axis, round trip.

A point target of a monostatic scan returns a * G(r, r_t)^2 (simulate, exact layered
Green's function). The exact per-frequency sum (migrate) must put it at its 3-D
position, with the range resolution c/(2 B Re n) of holoradar.theory.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from conftest import migrate64
from holoradar.analysis.metrics import main_lobe_width, peak_position

FREQS = np.linspace(8e9, 12e9, 11)  # 4 GHz in 400 MHz steps: unambiguous 37 cm in air


@pytest.mark.parametrize("eps", [1.0, 2.5, 6.0])
def test_monostatic_point_is_found_in_3d_with_the_range_resolution(eps):
    # 40 x 40 scan at 6.2 mm (lambda_min/4 = 6.2 mm at 12 GHz: unaliased). The bound on
    # position is a quarter of the resolution cell: laterally lambda_c L/(2 A) (the round
    # trip halves lambda z/A), in range c/(2 B Re n)/4. The range response's first null
    # (half main lobe) must be within 15% of c/(2 B Re n): the band's discrete sampling
    # (11 frequencies: c/(2 n N df) is 9% below c/(2 n B)) and the spread of the
    # aperture's angles (the range cell grows as 1/cos(theta)) move it by several %.
    medium = hr.Medium.free_space() if eps == 1.0 else hr.Medium.half_space(0.15, eps)
    target = (0.012, -0.007, 0.25)
    ap = hr.Aperture.grid(40, 0.0062, monostatic=True)
    h = hr.simulate(hr.Scene(medium, targets=[hr.PointTarget(target)]), ap, FREQS)
    assert h.monostatic and h.data.shape == (11, 40, 40)
    zs = np.linspace(0.21, 0.29, 81)
    img = migrate64(h, zs, medium=None if eps == 1.0 else medium, upsample=2)
    x, y, z = peak_position(img)
    res = hr.theory.range_resolution(4e9, eps)
    lam_c = hr.C0 / 10e9
    cell = lam_c * medium.apparent_distance(target[2]) / (2 * 40 * 0.0062)
    assert np.hypot(x - target[0], y - target[1]) < cell / 4
    assert abs(z - target[2]) < res / 4
    prof = np.abs(img.data[:, np.argmin(abs(img.y - y)), np.argmin(abs(img.x - x))])
    assert abs(main_lobe_width(prof, zs) / 2 / res - 1) < 0.15


def test_a_single_frequency_has_no_range_resolution():
    # Sanity of the combination: the same scan at one frequency focuses in range only
    # through the aperture (depth of focus ~ lambda (L/A)^2), far wider than the band's.
    ap = hr.Aperture.grid(40, 0.0062, monostatic=True)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.25))]), ap, FREQS)
    zs = np.linspace(0.15, 0.35, 81)
    wide = np.abs(migrate64(h, zs).data).max(axis=(1, 2))
    mono = np.abs(migrate64(h.at_frequency(5), zs).data).max(axis=(1, 2))
    assert main_lobe_width(wide, zs) < 0.5 * main_lobe_width(mono, zs)


def test_combine_options_and_equalisation():
    ap = hr.Aperture.grid(16, 0.0062, monostatic=True)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.2))]), ap, FREQS)
    kept = migrate64(h, [0.19, 0.2], combine="none")
    assert kept.data.shape == (11, 2, 16, 16)
    coh = migrate64(h, [0.19, 0.2], equalize=False, algorithm="frequency")
    raw = migrate64(h, [0.19, 0.2], combine="none", equalize=False).data
    np.testing.assert_allclose(coh.data, raw.sum(axis=0), rtol=1e-12)
    inc = migrate64(h, 0.2, combine="incoherent", equalize=False)
    parts = migrate64(h, 0.2, combine="none", equalize=False).data
    np.testing.assert_allclose(inc.data, np.sqrt((np.abs(parts) ** 2).sum(axis=0)), rtol=1e-12)
    # equalize=True: each frequency's hologram scaled to unit RMS
    eq = migrate64(h, 0.2, combine="none").data
    rms = np.sqrt(np.mean(np.abs(h.data) ** 2, axis=(1, 2)))
    np.testing.assert_allclose(eq, parts / rms[:, None, None], rtol=1e-12)
    with pytest.raises(ValueError, match="equalize must be"):
        migrate64(h, 0.2, equalize=[1.0, 2.0])
    with pytest.raises(ValueError, match="combine must be"):
        migrate64(h, 0.2, combine="sum")


def test_array_geometry_frequencies_add_after_the_incident_phase():
    # A receiver array lit by a plane wave: each frequency's image carries the incident
    # phase exp(i k z) at the target; with the source known it is removed and the
    # coherent sum focuses in range at the target (within a quarter of c/(2B)).
    # Without a source a normal plane wave is assumed, with a warning.
    ap = hr.Aperture.grid(40, 0.0124)
    target = (0.0, 0.0, 0.25)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget(target)]), ap, FREQS)
    assert h.source is not None and not h.monostatic
    zs = np.linspace(0.21, 0.29, 81)
    img = migrate64(h, zs, upsample=2)
    assert abs(peak_position(img)[2] - target[2]) < hr.theory.range_resolution(
        4e9, monostatic=False) / 4
    with pytest.warns(hr.IlluminationWarning, match="plane wave at normal incidence"):
        migrate64(h.replace(source=None), 0.25)


def test_full_field_of_view_over_a_band_shares_one_grid():
    # fov="full" shows the padded grid, which grows with the wavelength and the depth:
    # the frequencies of a band must share the largest one, and still focus on the target
    # (same criterion as above: a quarter of the range resolution c/(2B)). With a pitch
    # above lambda/2 the padding needed, lambda z / dx^2, differs across 8-12 GHz.
    ap = hr.Aperture.grid(20, 0.02)
    target = (0.0, 0.0, 0.50)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget(target)]), ap, FREQS)
    zs = np.linspace(0.46, 0.54, 81)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)  # the pitch, on purpose
        img = migrate64(h, zs, fov="full")
        aperture = migrate64(h, zs)
    assert img.data.shape[-1] > aperture.data.shape[-1]
    assert abs(peak_position(img)[2] - target[2]) < hr.theory.range_resolution(
        4e9, monostatic=False) / 4


def test_wideband_bad_input():
    x = np.arange(8) * 0.005
    with pytest.raises(ValueError, match="frequency axis third from last"):
        hr.Hologram(np.zeros((3, 8, 8)), x, x, [9e9, 10e9])
    with pytest.raises(ValueError, match="strictly increasing"):
        hr.Hologram(np.zeros((2, 8, 8)), x, x, [10e9, 9e9])
    with pytest.raises(ValueError, match="has no separate source"):
        hr.Hologram(np.zeros((8, 8)), x, x, 9e9, source=hr.PlaneWave(), monostatic=True)
    w = hr.Hologram(np.zeros((2, 8, 8)), x, x, [9e9, 10e9])
    with pytest.raises(ValueError, match="has 2 frequencies"):
        _ = w.k
    with pytest.raises(ValueError, match="planar targets are not modelled"):
        hr.simulate(hr.Scene(targets=[hr.PlanarTarget.from_shape("disk", 0.3, diameter=0.05)]),
                    hr.Aperture.grid(8, 0.005, monostatic=True), 9e9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # a transceiver at lambda/4 pitch is not aliased; at lambda/2 it is
        with pytest.raises(hr.AliasingWarning, match="lambda/4"):
            migrate64(hr.Hologram(np.ones((8, 8)), x * 2.4, x * 2.4, 12e9, monostatic=True),
                       0.2)


def test_measured_data_habits():
    # A scan whose device adds a DC offset per frequency, a phase response, and I - iQ.
    ap = hr.Aperture.grid(24, 0.0062, monostatic=True)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.01, 0.0, 0.2))]), ap, FREQS)
    phase = 0.3 + 2e-9 * (FREQS - 8e9)  # a linear phase response: 8 rad over the band
    offset = (0.5 + 0.2j) * np.abs(h.data).max()
    recorded = hr.conjugate(h.with_data((h.data + offset) * np.exp(1j * phase)[:, None, None]))
    zs = [0.18, 0.2, 0.22]
    assert hr.iq_convention(recorded, zs) == "I-iQ"
    fixed = hr.conjugate(recorded)
    table_f = np.linspace(7.5e9, 12.5e9, 41)
    calibrated = hr.apply_calibration(fixed, table_f, 0.3 + 2e-9 * (table_f - 8e9))
    np.testing.assert_allclose(calibrated.data, h.data + offset, rtol=1e-9, atol=1e-12)
    clean = hr.remove_mean(calibrated)
    np.testing.assert_allclose(clean.data.mean(axis=(1, 2)), 0, atol=1e-12)
    np.testing.assert_allclose(clean.data, hr.remove_mean(h).data, rtol=1e-9, atol=1e-12)
    assert hr.iq_convention(clean, zs) == "I+iQ"
    with pytest.raises(ValueError, match="must cover every frequency"):
        hr.apply_calibration(fixed, np.linspace(9e9, 12e9, 5), np.zeros(5))


@pytest.mark.parametrize(("geometry", "medium"), [
    ("monostatic", hr.Medium.free_space()), ("monostatic", hr.Medium.half_space(0.15, 2.5)),
    ("monostatic", hr.Medium.layered([0.10, 0.13], [5.0, 8.0])),
    ("array", hr.Medium.half_space(0.15, 2.5))])
def test_wavenumber_domain_sum_equals_the_per_frequency_sum(geometry, medium):
    # The same coherent sum computed two ways: frequency by frequency (angular spectrum,
    # one inverse FFT per frequency and plane) and carried from plane to plane in the
    # wavenumber domain (one per plane). On the same FFT grid (pad=3) they are the same
    # sum, term by term, so only rounding separates them: relative difference < 1e-10
    # (measured ~5e-14).
    mono = geometry == "monostatic"
    ap = hr.Aperture.grid(24, 0.0062 if mono else 0.0124, monostatic=mono)
    h = hr.simulate(hr.Scene(medium, targets=[hr.PointTarget((0.01, 0.0, 0.25))]), ap, FREQS,
                    include_surface=False)
    zs = np.linspace(0.16, 0.30, 29)
    med = None if medium.is_free_space else medium
    a = migrate64(h, zs, medium=med, algorithm="kspace", pad=3.0, upsample=2)
    b = migrate64(h, zs, medium=med, algorithm="frequency", pad=3.0, upsample=2)
    assert np.linalg.norm(a.data - b.data) < 1e-10 * np.linalg.norm(b.data)
    with pytest.raises(ValueError, match="algorithm='kspace' needs"):
        migrate64(h, [0.2, 0.21, 0.23], medium=med, algorithm="kspace")


def test_monostatic_loss_compensation_keeps_the_range():
    # Round trip through lossy ground (eps 4 + 0.4i: 2 x 18 dB over 10 cm at 10 GHz): the
    # compensated image (both legs' absorption undone where above the noise) puts the
    # point where the lossless ground of the same Re(n) does, to a tenth of the range
    # resolution; the plain adjoint's double decay pulls it up.
    eps = 4.0 + 0.4j
    n = np.sqrt(eps)
    ap = hr.Aperture.grid(24, 0.0062, monostatic=True)
    zs = np.linspace(0.19, 0.31, 49)
    peaks = {}
    for name, e in (("lossy", eps), ("lossless", n.real**2)):
        medium = hr.Medium.half_space(0.15, e)
        h = hr.simulate(hr.Scene(medium, targets=[hr.PointTarget((0.0, 0.0, 0.25))]), ap, FREQS,
                        include_surface=False)
        for comp in (True, False):
            img = migrate64(h, zs, medium=medium, compensate_loss=comp, equalize=False)
            peaks[name, comp] = peak_position(img)[2]
    res = hr.theory.range_resolution(4e9, eps)
    assert abs(peaks["lossy", True] - peaks["lossless", True]) < res / 10


def test_wideband_views_synthesise():
    # Two receiver-array views lit by plane waves at -+15 degrees, 11 frequencies each:
    # every frequency's incident phase is removed per view, so views and frequencies
    # all add in phase at the point (3-D position within a quarter of the cells).
    ap = hr.Aperture.grid(32, 0.0124)
    target = (0.01, -0.005, 0.25)
    views = [hr.simulate(hr.Scene(source=hr.PlaneWave(a, 0.0), targets=[hr.PointTarget(target)]),
                         ap, FREQS) for a in np.radians([-15, 15])]
    zs = np.linspace(0.22, 0.28, 25)
    img = hr.synthesize(views, zs, upsample=2)
    x, y, z = peak_position(img)
    cell = hr.C0 / 10e9 * 0.25 / (32 * 0.0124)
    assert np.hypot(x - target[0], y - target[1]) < cell / 4
    assert abs(z - target[2]) < hr.theory.range_resolution(4e9, monostatic=False) / 4
    other = views[1].replace(data=views[1].data[:10], frequency=FREQS[:10])
    with pytest.raises(ValueError, match="views must share their frequencies"):
        hr.synthesize([views[0], other], zs)


@pytest.mark.parametrize(("monostatic", "medium"), [
    (False, None), (False, hr.Medium.half_space(0.1, 2.5)),
    (True, hr.Medium.layered([0.10, 0.13], [5.0, 8.0]))])
def test_one_frequency_phase_step_equals_plane_by_plane(monostatic, medium):
    # One frequency on uniform planes in the deepest region: one transfer and a phase
    # step per plane (the default for volumes too big to cache) against a transfer
    # function built for every plane
    # (algorithm="frequency"). The same field, term by term: < 1e-10 (measured 1e-14),
    # frames and upsampling included.
    rng = np.random.default_rng(1)
    x = np.arange(24) * 0.006
    h = hr.Hologram(rng.standard_normal((2, 24, 24)) + 1j * rng.standard_normal((2, 24, 24)),
                    x, x, 10e9, monostatic=monostatic)
    zs = np.linspace(0.15, 0.30, 16)
    a = migrate64(h, zs, medium=medium, upsample=2, algorithm="kspace")
    b = migrate64(h, zs, medium=medium, upsample=2, algorithm="frequency")
    assert a.data.shape == b.data.shape == (2, 16, 47, 47)
    assert np.linalg.norm(a.data - b.data) < 1e-10 * np.linalg.norm(b.data)


@pytest.mark.parametrize("medium", [None, hr.Medium.half_space(0.2, 2.5 + 0.1j)])
def test_normal_plane_wave_phasor_is_one_pixel_broadcast_exactly(medium):
    # A normal plane wave's incident phase is the same across a plane (its lateral
    # factor is exactly 1), so the frequencies' sum takes it on one pixel per plane
    # and broadcasts it: it must equal the phasor computed at every pixel, bit for bit.
    from holoradar.imaging.migration import illumination
    from holoradar.imaging.migration.plan import make_plan
    from holoradar.physics.incident import incident_phasors

    med = medium if medium is not None else hr.Medium.free_space()
    x = np.linspace(-0.2, 0.2, 21)
    zs = np.array([0.1, 0.25, 0.4])
    h = hr.Hologram(np.ones((2, 21, 21)), x, x, [9.9e9, 10e9], source=hr.PlaneWave())
    plan = make_plan(h, zs, medium, hr.MigrationSettings())
    k = 2 * np.pi * 9.9e9 / hr.C0
    got = illumination.on_planes(plan, 0, x, x)
    full = incident_phasors([hr.PlaneWave()], k, med, x, x, zs)[0]
    assert got.shape == full.shape
    np.testing.assert_array_equal(got, full)
    # the per-plane values the band's summed spectra use are the same numbers
    np.testing.assert_array_equal(illumination.uniform(plan, 0), full[:, 0, 0])
    # a tilted wave is not uniform: computed at every pixel
    tilted = make_plan(h.replace(source=hr.PlaneWave(0.2, 0.0)), zs, medium,
                       hr.MigrationSettings())
    assert not illumination.is_uniform(tilted)
    phasor = illumination.on_planes(tilted, 0, x, x)
    assert not np.allclose(phasor[0], phasor[0, 0, 0])
