"""``hr.unbiased_peak``: the object's position by the point-response fit, not the
image's biased maximum (``Image.peak()``, the brightest voxel); tilted arrays refused."""

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
    # The brightest voxel is all Image.peak gives: the fit is named in its refusal.
    with pytest.raises(ValueError, match=r"holoradar\.unbiased_peak"):
        img.peak(unbiased=True, hologram=h)
    with pytest.raises(ValueError, match=r"holoradar\.unbiased_peak"):
        img.peak(hologram=h)
    other = hr.Hologram(h.data[::-1, ::-1].conj(), h.x, h.y, h.frequency)
    with pytest.raises(ValueError, match="not the migration of hologram"):
        hr.unbiased_peak(img, other, SAND)


def test_tilted_array_refused(level):
    # The fit's point response is tabulated for a level aperture: the same array tilted
    # 35 degrees is refused with the reason (docs/detect.md), never answered with a
    # wrong position. (The refusal looks at the geometry only: the level case's data
    # under the tilted pose stand for the tilted array's.)
    h, img = level
    tilted = hr.Hologram(h.data, h.x, h.y, h.frequency, pose=hr.Pose(tilt=np.radians(35.0)))
    with pytest.raises(ValueError, match=r"level aperture.*tilted arrays are not supported"):
        hr.unbiased_peak(img, tilted, SAND)
