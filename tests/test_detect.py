"""hr.analysis.detect: threshold from the image's noise, CLEAN, unbiased positions."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from holoradar.analysis.detect import detect
from holoradar.analysis.detect.noise import (
    box_resels,
    expected_false_peaks,
    threshold,
)

warnings.filterwarnings("ignore", category=hr.AliasingWarning)


def _noise_images(n_images: int, false_alarm: float, seed: int) -> tuple[int, float]:
    """Objects reported on noise-only images of the paper's array (one plane, 50 cm
    away, 4 pixels per pitch), and the number the nominal rate predicts."""
    ap = hr.Aperture.paper()
    rng = np.random.default_rng(seed)
    found, expected = 0, 0.0
    for _ in range(n_images):
        d = rng.normal(size=(16, 16)) + 1j * rng.normal(size=(16, 16))
        img = hr.migrate(hr.Hologram(d, ap.x, ap.y, 9.9e9), 0.5, upsample=4)
        df = detect(img, false_alarm=false_alarm, kinds=("point",))
        found += len(df)
        expected += false_alarm * max(df.attrs["n_cells"], 1.0)
    return found, expected


def test_threshold_solves_the_expected_euler_characteristic():
    # 16 x 16 cells: the threshold puts 1e-3 false maxima per cell; with an exactly
    # known variance it tends to the chi^2_2 tail e^-t times the EC polynomial.
    t = threshold(1e-3, (16.0, 16.0, 0.0))
    assert expected_false_peaks(t, box_resels((16.0, 16.0, 0.0))) == pytest.approx(0.256, 1e-9)
    # The variance estimated from N cells raises the tail (CFAR): a higher threshold.
    assert threshold(1e-3, (16.0, 16.0, 0.0), 100.0) > t


def test_false_alarm_rate_on_noise_only_images_quick():
    # 60 images at 1e-2 per cell: about 50 expected. Poisson: 4 standard deviations
    # (sqrt of the expectation) either way; a factor 2 error in the rate fails it.
    found, expected = _noise_images(60, 1e-2, seed=7)
    assert abs(found - expected) <= 4 * np.sqrt(expected), (found, expected)


@pytest.mark.slow
def test_false_alarm_rate_on_noise_only_images():
    # 1200 images at 1e-3 per cell (about 90 false objects expected): the count is
    # binomial (Poisson) about the nominal rate; 3 standard deviations.
    found, expected = _noise_images(1200, 1e-3, seed=11)
    assert abs(found - expected) <= 3 * np.sqrt(expected), (found, expected)


def _two_points() -> tuple[hr.Hologram, hr.Medium]:
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    scene = hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget((-0.06, 0.03, 0.42), 1.0),
                                            hr.PointTarget((0.08, -0.05, 0.42), 0.1)])
    h = hr.simulate(scene, hr.Aperture.paper(), 9.9e9, include_surface=False, snr_db=40,
                    seed=3)
    return h, sand


def test_strong_and_weak_point_20_db_apart_both_found_nothing_else():
    h, sand = _two_points()
    img = hr.migrate(h, 0.42, medium=sand, upsample=4)
    df = detect(img, hologram=h, medium=sand)
    assert len(df) == 2                      # no sidelobe (13 dB down) reported
    # Quarter of the lateral resolution lambda L / A (L the apparent distance).
    cell = hr.theory.lateral_resolution(h.wavelength, sand.apparent_distance(0.42), 0.40)
    strong, weak = df.iloc[0], df.iloc[1]
    assert abs(strong.x + 0.06) < cell / 4 and abs(strong.y - 0.03) < cell / 4
    assert abs(weak.x - 0.08) < cell / 4 and abs(weak.y + 0.05) < cell / 4
    # 20 dB apart in amplitude (equal ranges, nearly equal paths; the sinc envelope of
    # the lateral offsets only changes it by a fraction of a dB).
    assert strong.amplitude_db - weak.amplitude_db == pytest.approx(20.0, abs=1.0)
    assert (df.depth - 0.12).abs().max() < 0.01


def test_window_model_plane_finds_the_strong_point():
    # Without the hologram: the spectral window's sinc; the brightest is the point.
    h, sand = _two_points()
    img = hr.migrate(h, 0.42, medium=sand, upsample=4)
    df = detect(img, medium=sand)
    cell = hr.theory.lateral_resolution(h.wavelength, sand.apparent_distance(0.42), 0.40)
    assert abs(df.x.iloc[0] + 0.06) < cell / 4 and abs(df.y.iloc[0] - 0.03) < cell / 4


def test_unbiased_range_at_one_frequency():
    # A point 10 cm deep in sand under a level 32 x 32 array at 1.25 cm, 50 cm above
    # the sand, one frequency: the image's brightest plane lies 9 cm short of the
    # point (the adjoint's 1/r weighting over a focus 30 cm long); the fit has no such
    # pull. Quarter of the resolution cell in every direction (lateral lambda L/A,
    # along range the monochromatic depth response's FWHM).
    sand = hr.Medium.half_space(0.50, 2.5 + 0.0125j)
    ap = hr.Aperture.grid(32, 0.0125)
    truth = np.array([0.01, -0.005, 0.60])
    scene = hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget(tuple(truth))])
    h = hr.simulate(scene, ap, 9.9e9, include_surface=False, snr_db=30, seed=2)
    img = hr.migrate(h, np.arange(0.50, 0.75, 0.02), medium=sand, upsample=4)
    L = sand.apparent_distance(0.60)
    lateral = hr.theory.lateral_resolution(h.wavelength, L, 0.40)
    longitudinal = hr.theory.longitudinal_resolution(h.wavelength, L, 0.40)
    assert truth[2] - img.peak()[2] > longitudinal / 4   # the bias this guards against
    df = detect(img, hologram=h, medium=sand)
    assert len(df) == 1
    row = df.iloc[0]
    assert abs(row.x - truth[0]) < lateral / 4 and abs(row.y - truth[1]) < lateral / 4
    assert abs(row["range"] - truth[2]) < longitudinal / 4
    assert abs(row.depth - 0.10) < longitudinal / 4
    # The stated uncertainty covers the error (noise only: the model is exact).
    assert abs(row["range"] - truth[2]) < 4 * row.range_std + 1e-4


def test_unbiased_position_across_a_band():
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    truth = np.array([0.02, 0.01, 0.42])
    scene = hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget(tuple(truth))])
    f = np.linspace(9e9, 11e9, 5)
    h = hr.simulate(scene, hr.Aperture.paper(), f, include_surface=False, snr_db=30, seed=4)
    img = hr.migrate(h, np.arange(0.36, 0.49, 0.01), medium=sand, upsample=4)
    df = detect(img, hologram=h, medium=sand)
    assert len(df) == 1
    L = sand.apparent_distance(0.42)
    lateral = hr.theory.lateral_resolution(hr.C0 / 10e9, L, 0.40)
    depth_cell = hr.theory.range_resolution(2e9, 2.5, monostatic=False)
    row = df.iloc[0]
    assert abs(row.x - truth[0]) < lateral / 4 and abs(row.y - truth[1]) < lateral / 4
    assert abs(row["range"] - truth[2]) < depth_cell / 4


def test_depth_interval_from_the_permittivity_interval():
    h, sand = _two_points()
    img = hr.migrate(h, 0.42, medium=sand, upsample=4)
    df = detect(img, hologram=h, medium=sand, eps_interval=(2.0, 3.0))
    # One frequency fixes the apparent depth d/n: d' = d sqrt(eps'/eps).
    d = df.depth.iloc[0]
    assert df.depth_low.iloc[0] <= d * np.sqrt(2.0 / 2.5) + 1e-9
    assert df.depth_high.iloc[0] >= d * np.sqrt(3.0 / 2.5) - 1e-9


@pytest.mark.parametrize("kwargs, message", [
    ({"false_alarm": 0.5}, "false_alarm"),
    ({"false_alarm": "x"}, "false_alarm"),
    ({"kinds": "point"}, "kinds"),
    ({"kinds": ("blob",)}, "kinds"),
    ({"eps_interval": (3.0, 2.0), "medium": hr.Medium.half_space(0.3, 2.5)}, "eps_interval"),
    ({"eps_interval": (2.0, 3.0)}, "medium"),
    ({"eps_interval": "wide", "medium": hr.Medium.half_space(0.3, 2.5)}, "eps_interval"),
    ({"max_objects": 0}, "max_objects"),
    ({"max_objects": "x"}, "max_objects"),
])
def test_bad_input_names_the_argument(kwargs, message):
    img = hr.Image(np.ones((5, 5), complex), np.arange(5) * 0.01, np.arange(5) * 0.01,
                   np.array([0.4]), 9.9e9, has_z_axis=False)
    with pytest.raises(ValueError, match=message):
        detect(img, **kwargs)


def test_image_without_coordinates_is_refused():
    class Bare:
        data = np.ones((4, 4))

    with pytest.raises(ValueError, match="coordinates"):
        detect(Bare())


def test_hologram_that_did_not_make_the_image_is_refused():
    h, sand = _two_points()
    img = hr.migrate(h, 0.42, medium=sand, upsample=4)
    with pytest.raises(ValueError, match="image is not migrate"):
        detect(img, hologram=h)              # migrated through sand, checked in air


def test_reference_noise_of_an_image_smaller_than_the_guard_box():
    """A frame's image smaller than the guard cells around a candidate: the reference is
    the image's own mean power (finite, never 0/0)."""
    from holoradar.analysis.detect.reference import candidate_noise

    r = np.full((1, 5, 5), 2.0 + 0j)
    s2, n = candidate_noise(r, np.zeros((5, 5), bool), (0, 2, 2), np.arange(5.0) * 0.01,
                            np.arange(5.0) * 0.01, (0.05, 0.05, np.inf))
    assert s2 == 4.0 and n >= 1.0


def test_an_eps_interval_that_excludes_the_images_eps_warns():
    """Depths are read off a focus made at the ground's eps'; an interval that does not
    hold it describes another focus: said (with the CLI's one warning line), and an
    interval about it is quiet."""
    import warnings

    sand = hr.Medium.half_space(0.3, 2.5)
    sc = hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget((0.0, 0.0, 0.42))])
    h = hr.simulate(sc, hr.Aperture.grid(24, 0.0125), 9.9e9, include_surface=False,
                    snr_db=40, seed=0)
    img = hr.migrate(h, 0.42, medium=sand, upsample=2)
    with pytest.warns(hr.PermittivityIntervalWarning, match=r"\[5\.5, 6\.5\] excludes .*2\.5"):
        hr.detect(img, medium=sand, eps_interval=(5.5, 6.5))
    with warnings.catch_warnings():
        warnings.simplefilter("error", hr.PermittivityIntervalWarning)
        hr.detect(img, medium=sand, eps_interval=(2.2, 2.8))
