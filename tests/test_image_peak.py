"""``hr.unbiased_peak``: the object's position by the point-response fit, not the
image's biased maximum (``Image.peak()``, the brightest voxel), level and tilted arrays."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr

pytestmark = pytest.mark.filterwarnings("ignore::holoradar.AliasingWarning")

SAND = hr.Medium.half_space(0.50, 2.5 + 0.0125j)
TRUTH = np.array([0.01, -0.005, 0.60])   # 10 cm deep in the sand


@pytest.fixture(scope="module")
def level() -> tuple[hr.Hologram, hr.Image]:
    """One frequency, a level 32 x 32 array at 1.25 cm, 50 cm above the sand, 30 dB."""
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget(tuple(TRUTH))])
    h = hr.simulate(scene, hr.Aperture.grid(32, 0.0125), 9.9e9, include_surface=False,
                    snr_db=30, seed=2)
    return h, hr.migrate(h, np.arange(0.50, 0.75, 0.02), medium=SAND, upsample=4)


def test_unbiased_peak_at_one_frequency(level):
    h, img = level
    L = SAND.apparent_distance(TRUTH[2])
    lateral = hr.theory.lateral_resolution(h.wavelength, L, 0.40)
    longitudinal = hr.theory.longitudinal_resolution(h.wavelength, L, 0.40)
    plain = img.peak()
    assert TRUTH[2] - plain[2] > longitudinal / 4 and TRUTH[2] - plain[2] > 0.07  # ~9 cm short
    p = hr.unbiased_peak(img, h, SAND)
    x, y, z = p                                           # still an (x, y, z) tuple
    assert abs(x - TRUTH[0]) < lateral / 4 and abs(y - TRUTH[1]) < lateral / 4
    assert abs(z - TRUTH[2]) < longitudinal / 4
    # Its standard deviations: finite, and they cover the error (the model is exact here).
    assert all(np.isfinite(p.std)) and p.std[2] > p.std[0]
    assert np.all(np.abs(np.array(p) - TRUTH) < 4 * np.array(p.std) + 1e-4)
    assert 0.9 < p.focus_fraction <= 1.0


def test_unbiased_peak_from_one_plane_fits_the_range(level):
    # One plane, cut out of the volume where the image is brightest (9 cm short): the
    # range comes from the hologram's wave front, not from the plane.
    h, img = level
    plane = img.plane(img.peak()[2])
    z = hr.unbiased_peak(plane, h, SAND)[2]
    longitudinal = hr.theory.longitudinal_resolution(
        h.wavelength, SAND.apparent_distance(TRUTH[2]), 0.40)
    assert abs(z - TRUTH[2]) < longitudinal / 4


def test_plain_peak_unchanged_and_bad_calls_refused(level):
    h, img = level
    a = np.abs(img.data)
    iz, iy, ix = np.unravel_index(np.argmax(a), a.shape)
    assert img.peak() == (float(img.x[ix]), float(img.y[iy]), float(img.z[iz]))
    with pytest.raises(ValueError, match="hologram="):
        hr.unbiased_peak(img, None)
    # The brightest voxel is all Image.peak gives (the data layer does not reach up to
    # the fit): the fit is named in its refusal.
    with pytest.raises(ValueError, match=r"holoradar\.unbiased_peak"):
        img.peak(unbiased=True, hologram=h)
    with pytest.raises(ValueError, match=r"holoradar\.unbiased_peak"):
        img.peak(hologram=h)
    other = hr.Hologram(h.data[::-1, ::-1].conj(), h.x, h.y, h.frequency)
    with pytest.raises(ValueError, match="not the migration of hologram"):
        hr.unbiased_peak(img, other, SAND)


def test_tilted_array_needs_its_ground_frame_image(level):
    # A posed array's objects are found on world planes: an image in the array's own
    # frame is refused with the way out, never answered with a wrong position. (The
    # refusal looks at the geometry only: the level case's data under the tilted pose
    # stand for the tilted array's.)
    h, img = level
    tilted = hr.Hologram(h.data, h.x, h.y, h.frequency, source=hr.PlaneWave(),
                         pose=hr.Pose(tilt=np.radians(35.0)))
    with pytest.raises(ValueError, match=r"ground frame.*frame='ground'"):
        hr.unbiased_peak(img, tilted, SAND)


def test_unbiased_peak_under_a_tilted_array_from_the_reflectivity():
    # A 24 x 24 array at 1.25 cm tilted 35 degrees, a point 12 cm deep in sand, one
    # frequency, imaged in the ground frame: the adjoint's maximum lies short of the
    # point along the line of sight; the strongest object of the inverted reflectivity
    # is the point, within a quarter of the lateral cell across and of the one-frequency
    # depth response ``4.97 lambda (L / A)^2`` along range.
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    truth = np.array([0.0, 0.05, 0.42])
    ap = hr.Aperture.grid(24, 0.0125, pose=hr.Pose((0.0, -0.15, 0.05), tilt=np.radians(35),
                                                    azimuth=np.radians(90)))
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget(tuple(truth))]), ap,
                    9.9e9, include_surface=False, snr_db=30, seed=4)
    img = hr.migrate(h, np.arange(0.34, 0.53, 0.02), medium=sand, frame="ground",
                     x=np.arange(-0.08, 0.0801, 0.01), y=np.arange(-0.03, 0.1301, 0.01))
    p = hr.unbiased_peak(img, h, sand)
    L = sand.apparent_distance(truth[2]) + 0.15       # the slant path, roughly
    lateral, depth = h.wavelength * L / 0.30, 4.97 * h.wavelength * (L / 0.30) ** 2
    err = np.abs(np.array(p) - truth)
    assert err[0] < lateral / 4 and err[1] < lateral / 4 and err[2] < depth / 4, err
    assert all(np.isfinite(p.std))
