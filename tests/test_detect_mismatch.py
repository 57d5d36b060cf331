"""``detect(image, hologram=...)`` with a hologram that did not make the image: one
line naming the argument and what differs (frequencies, grid, source), before any
inversion."""

from __future__ import annotations

import pytest

import holoradar as hr
from holoradar.analysis.detect.errors import HologramFitError

Y = (0, 1, 0)


@pytest.fixture(scope="module")
def pair():
    dipole = hr.Dipole((-0.15, 0.0, 0.05), Y)
    scene = hr.Scene(hr.Medium.free_space(), dipole, [hr.PointTarget((0.0, 0.0, 0.3))])
    h = hr.simulate(scene, hr.Aperture.grid(12, 0.01, polarization=Y), [9e9, 10e9, 11e9],
                    snr_db=30, seed=0)
    return h, hr.migrate(h, [0.28, 0.30, 0.32])


def _one_line(err: pytest.ExceptionInfo) -> str:
    text = str(err.value)
    assert "\n" not in text and text.startswith("hologram does not match image")
    return text


def test_other_frequencies_are_named(pair):
    h, img = pair
    other = hr.Hologram(h.data[:2], h.x, h.y, h.frequencies[:2], source=h.source,
                        polarization=Y)
    with pytest.raises(HologramFitError) as err:
        hr.detect(img, hologram=other)
    text = _one_line(err)
    assert "2 frequencies 9-10 GHz" in text and "3 frequencies 9-11 GHz" in text
    assert err.value.reason == "frequency"


def test_another_grid_is_named(pair):
    h, img = pair
    shifted = hr.Hologram(h.data, h.x, h.y + 0.005, h.frequencies, source=h.source,
                          polarization=Y)
    with pytest.raises(ValueError) as err:
        hr.detect(img, hologram=shifted)
    assert "y grid" in _one_line(err) and err.value.reason == "grid"


def test_another_source_is_a_mismatch(pair):
    h, img = pair
    moved = hr.Hologram(h.data, h.x, h.y, h.frequencies,
                        source=hr.Dipole((0.15, 0.0, 0.05), Y), polarization=Y)
    with pytest.raises(ValueError) as err:
        hr.detect(img, hologram=moved)
    assert "another source" in _one_line(err) and err.value.reason == "mismatch"
