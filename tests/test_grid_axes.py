"""Element coordinates as scanners write them: an axis written from its high end is
reversed with its data; coordinates rounded to a text export's digits are snapped to the
uniform grid they mean (each said once); anything else is refused as before."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr

PITCH = 35e-3 / 6                       # 5.8333... mm: not representable in 4 decimals


def _point_hologram():
    scene = hr.Scene(targets=[hr.PointTarget((0.012, -0.018, 0.12))], source=hr.PlaneWave())
    return hr.simulate(scene, hr.Aperture.grid(24, PITCH), 10e9, snr_db=40, seed=2)


def test_an_axis_written_from_its_high_end_is_reversed_with_its_data():
    # The same samples given from the high end of x: the hologram is the original one,
    # and its image peaks at the same point (a flipped axis alone would mirror it).
    h = _point_hologram()
    with pytest.warns(hr.CoordinateWarning, match="x was written from its high end"):
        back = hr.Hologram(h.data[:, ::-1], h.x[::-1], h.y, h.frequency, source=h.source)
    np.testing.assert_array_equal(back.x, h.x)
    np.testing.assert_array_equal(back.data, h.data)
    with pytest.warns(hr.CoordinateWarning, match="y was written"):
        hr.Hologram(h.data[::-1], h.x, h.y[::-1], h.frequency)


def test_rounded_coordinates_are_snapped_to_their_grid():
    # Coordinates written in mm to four decimals (-64.1667): steps differ by 1e-7 m, which
    # the FFT's 1e-6 relative tolerance refuses. Each element moves by at most 5e-8 m:
    # a phase of 2 k d = 2e-5 rad at 10 GHz. The image equals the exact grid's to that
    # order (relative 1e-4 bounds it with room).
    h = _point_hologram()
    xr, yr = np.round(h.x * 1e3, 4) * 1e-3, np.round(h.y * 1e3, 4) * 1e-3
    with pytest.raises(ValueError, match="uniformly spaced"):
        hr.migrate(hr.Hologram(h.data, h.x + np.r_[0, 1e-4, np.zeros(22)], h.y, 10e9), 0.12)
    with pytest.warns(hr.CoordinateWarning, match="snapped to it"):
        r = hr.Hologram(h.data, xr, yr, h.frequency, source=h.source)
    assert np.max(np.abs(r.x - h.x)) < 1e-7
    a, b = hr.migrate(r, 0.12).data, hr.migrate(h, 0.12).data
    assert np.max(np.abs(a - b)) < 1e-4 * np.max(np.abs(b))


def test_coordinates_off_their_grid_are_not_snapped():
    # A real departure (a twentieth of a pitch) is not rounding: the grid stays as given
    # (and the FFT refuses it, naming the steps); no coordinate warning.
    x = np.arange(16) * 0.01
    x[5] += 0.0005
    with warnings.catch_warnings():
        warnings.simplefilter("error", hr.CoordinateWarning)
        h = hr.Hologram(np.ones((16, 16)), x, np.arange(16) * 0.01, 10e9)
    assert h.x[5] == x[5]
    with pytest.raises(ValueError, match="uniformly spaced"):
        hr.migrate(h, 0.2)


def test_an_unordered_axis_is_refused_with_the_way_out():
    x = np.arange(8) * 0.01
    x[[2, 3]] = x[[3, 2]]
    with pytest.raises(ValueError, match=r"strictly increasing .*sort the samples"):
        hr.Hologram(np.ones((8, 8)), x, np.arange(8) * 0.01, 10e9)
