"""hr.detect: planar reflectors and voids as areas with their outline."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from holoradar.analysis.detect import detect

warnings.filterwarnings("ignore", category=hr.AliasingWarning)


@pytest.mark.slow
def test_an_air_pocket_under_a_road_layer_is_one_area():
    # A road: 6 cm of asphalt (eps 5 + 0.1i) on a granular base (eps 8 + 0.3i), 30 cm
    # below a 32 x 32 array at 1.25 cm, one frequency. An air pocket 14 x 10 cm, 6 cm
    # into the base: its top reflects with the base-to-air Fresnel coefficient
    # (n - 1)/(n + 1) = +0.48 (opposite in sign to metal), physical optics.
    road = hr.Medium.layered([0.30, 0.36], [5 + 0.1j, 8 + 0.3j])
    n = np.sqrt(8 + 0.3j)
    z = 0.42
    void = hr.PlanarTarget.from_shape("rectangle", z, center=(0.02, -0.01),
                                      reflection=complex((n - 1) / (n + 1)),
                                      width=0.14, height=0.10)
    h = hr.simulate(hr.Scene(road, hr.PlaneWave(), [void]), hr.Aperture.grid(32, 0.0125),
                    9.9e9, include_surface=False, snr_db=30, seed=1)
    df = detect(hr.migrate(h, z, medium=road, upsample=4), medium=road)
    assert list(df.kind) == ["area"], df[["kind", "x", "y", "snr_db"]]
    # As for a metal plate (tests/test_detect_lines.py): the outline is the hull of the
    # components inside the edges, so extents within a cell, the area within the
    # perimeter times half a cell, the centroid within a quarter cell.
    cell = hr.theory.lateral_resolution(h.wavelength, road.apparent_distance(z), 0.40)
    row = df.iloc[0]
    assert abs(row.x - 0.02) < cell / 4 and abs(row.y + 0.01) < cell / 4
    assert abs(row.length - 0.14) < cell and abs(row.width - 0.10) < cell
    assert abs(row.area - 0.14 * 0.10) < 0.48 * cell / 2
    assert row.depth == pytest.approx(0.12, abs=1e-9)
