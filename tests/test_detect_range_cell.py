"""The range cell ``c / (2 B n)`` that ``detect`` joins and separates objects by.

The data are simulated by holoradar's own Born point model (the model the inversion
inverts): these tests check the range cell's formula and that detection honours it,
not how well the model fits the world (the full-wave cases do that).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr

warnings.filterwarnings("ignore", category=hr.AliasingWarning)

EPS = 6.0
GROUND = hr.Medium.half_space(0.20, EPS)
BAND = np.linspace(8e9, 12e9, 11)
# Worked out here, not taken from holoradar: a band B = 4 GHz in a ground of refractive
# index n = sqrt(6) resolves c / (2 B n) = 299792458 / (2 * 4e9 * 2.449) = 1.530 cm.
RANGE_CELL = 299_792_458.0 / (2 * 4e9 * np.sqrt(EPS))


@pytest.fixture(scope="module")
def two_in_one_column():
    """Two equal points at one (x, y), 0.75 of a range cell apart, under a scanned
    transceiver (16 x 16 at 1 cm), 30 dB; the noise given."""
    z1 = 0.26
    z2 = z1 + 0.75 * RANGE_CELL
    targets = [hr.PointTarget((0.0, 0.0, z1)), hr.PointTarget((0.0, 0.0, z2))]
    h = hr.simulate(hr.Scene(GROUND, hr.PlaneWave(), targets),
                    hr.Aperture.grid(16, 0.01, monostatic=True), BAND,
                    include_surface=False, snr_db=30, seed=1)
    sigma = float(np.sqrt(np.mean(np.abs(h.data) ** 2) / 1000))   # the 30 dB simulated
    img = hr.migrate(h, np.arange(0.245, 0.29, 0.0025), medium=GROUND)
    return hr.detect(img, hologram=h, medium=GROUND, noise=sigma), (z1, z2)


def test_the_range_cell_is_c_over_2_b_n(two_in_one_column):
    assert RANGE_CELL == pytest.approx(0.01530, abs=5e-6)
    df, _ = two_in_one_column
    assert df.attrs["resolution_cell"][2] == pytest.approx(RANGE_CELL, rel=1e-9)


def test_two_points_three_quarters_of_a_range_cell_apart_are_two(two_in_one_column):
    # Objects join when their range peaks lie within half a range cell: 0.75 apart they
    # stay two (with the cell taken one-way, c / (B n), they would be 0.375 apart: one),
    # one on each side of their midpoint, both on the column.
    df, (z1, z2) = two_in_one_column
    assert len(df) == 2, df[["kind", "x", "y", "range"]]
    lo, hi = sorted(df.range)
    assert lo < (z1 + z2) / 2 < hi
    # laterally on the column: within a quarter of the lateral cell lambda L / A
    cell = hr.C0 / 10e9 * GROUND.apparent_distance(0.265) / 0.16
    assert np.all(np.hypot(df.x, df.y) < cell / 4)
