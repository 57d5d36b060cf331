"""hr.detect on independent full-wave data: a metal sphere is one point, not a point
with a ring of further objects."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import holoradar as hr
from holoradar.analysis.detect.ringing import absorb_ringing

warnings.filterwarnings("ignore", category=hr.AliasingWarning)

DATA = Path(__file__).parent / "data"
SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)


def _sphere() -> hr.Hologram:
    # SMUTHI (T-matrix, layered-medium coupling): a metal sphere of radius 1.5 cm, its
    # centre 10 cm deep in sand (eps 2.5 + 0.0125i), lit by a plane wave (E along y) at
    # normal incidence, E_y on 64 x 64 receivers at 1 cm, 30 cm above the sand, 9.9 GHz.
    with np.load(DATA / "S2_buried_sphere_metal_inc+00.npz") as d:
        return hr.Hologram(d["E_scat"][1], d["x_m"], d["y_m"], float(d["f_hz"][0]))


def _cells(h: hr.Hologram) -> tuple[float, float]:
    L = SAND.apparent_distance(0.40)
    return (hr.theory.lateral_resolution(h.wavelength, L, 0.64),
            hr.theory.longitudinal_resolution(h.wavelength, L, 0.64))


def test_smuthi_sphere_is_one_point_at_its_centre_from_the_plane():
    # k_m a = 4.9: its image rings around it 23 dB and more below its peak (the point
    # response it is explained by is not a sphere's); that ring is not further objects.
    h = _sphere()
    df = hr.detect(hr.migrate(h, 0.385, medium=SAND, upsample=2), medium=SAND)
    assert list(df.kind) == ["point"], df[["kind", "x", "y", "amplitude_db", "snr_db"]]
    lateral, _ = _cells(h)
    assert abs(df.x[0]) < lateral / 4 and abs(df.y[0]) < lateral / 4


@pytest.mark.slow   # full-wave: the SMUTHI sphere's volume, 9 s (the plane case stays fast)
def test_smuthi_sphere_is_one_point_at_its_centre_from_the_volume():
    # With the hologram: the fitted range within a quarter of the one-frequency focus
    # (the longitudinal resolution) of the centre.
    h = _sphere()
    img = hr.migrate(h, np.arange(0.36, 0.46, 0.01), medium=SAND, upsample=2)
    df = hr.detect(img, medium=SAND, hologram=h)
    assert list(df.kind) == ["point"], df[["kind", "x", "y", "range", "amplitude_db"]]
    lateral, longitudinal = _cells(h)
    row = df.iloc[0]
    assert abs(row.x) < lateral / 4 and abs(row.y) < lateral / 4
    assert abs(row["range"] - 0.40) < longitudinal / 4


def test_weak_ring_around_a_compact_object_is_absorbed_but_not_a_bars_pieces():
    def pt(x, y, db):
        return {"kind": "point", "x": x, "y": y, "range": 0.4, "amplitude_db": db}

    cell = (0.017, 0.017, np.inf)
    # The sphere's measured ring (amplitudes relative to its peak, dB).
    ring = [pt(0, 0, 0), pt(0, 0.025, -23.2), pt(0, -0.022, -23.5), pt(0, 0.043, -32.5),
            pt(0, -0.043, -36.9), pt(0, 0.062, -40.7)]
    assert len(absorb_ringing(ring, cell)) == 1
    # A second object 3 cells off, 6 dB weaker: two objects and no ring.
    assert len(absorb_ringing([*ring, pt(0.05, 0.0, -6.0)], cell)) == 2
    # An object far from the ring (not linked to it): kept, however weak.
    assert len(absorb_ringing([*ring, pt(0.2, 0.2, -30.0)], cell)) == 2
    # A plate's pieces: several within 13.5 dB of the strongest, faint edges kept.
    plate = [pt(x, y, -3.0 * (abs(x) + abs(y)) / 0.02) for x in (-0.04, -0.02, 0, 0.02, 0.04)
             for y in (-0.02, 0, 0.02)]
    assert len(absorb_ringing(plate, cell)) == len(plate)


def test_smuthi_sphere_under_a_tilted_array_is_one_point():
    # SMUTHI S7: a metal sphere (radius 12 mm, centre 12 cm deep in sand) seen by a
    # 24 x 24 array at 15 mm tilted 40 degrees, its centre 0.5 m from the sphere along
    # its normal, one frequency; imaged in the ground frame on the plane of the
    # sphere's bright point (its surface facing the array, centre - r * the refracted
    # viewing direction; frames as in tests/test_oblique.py). One point there, within
    # a quarter of the array's lateral resolution lambda L / A (L = 0.5 m, A = 0.36 m).
    d = np.load(DATA / "S7_tilted_array_sphere.npz")
    surf, c = 0.4, d["centre_m"]
    pose = hr.Pose((c[0], c[1], surf - c[2]), tilt=np.radians(40), azimuth=np.radians(90))
    h = hr.Hologram(d["E_scat"][0], d["x_local_m"], d["y_local_m"], 9.9e9, pose=pose)
    eps = 2.5 + 0.0125j
    med = hr.Medium.half_space(surf, eps)
    sin_t = np.sin(np.radians(40)) / np.sqrt(eps.real)
    bright = np.array([-0.03, 0.02, surf + 0.12]) - 0.012 * np.array(
        [0.0, sin_t, np.sqrt(1 - sin_t**2)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        img = hr.migrate(h, bright[2], medium=med, frame="ground", upsample=3)
    df = hr.detect(img, medium=med)
    assert list(df.kind) == ["point"], df[["kind", "x", "y", "amplitude_db", "snr_db"]]
    quarter = hr.theory.lateral_resolution(hr.C0 / 9.9e9, 0.5, 0.36) / 4
    assert np.hypot(df.x[0] - bright[0], df.y[0] - bright[1]) < quarter
