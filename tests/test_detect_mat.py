"""hr.detect on wideband volumes without the hologram: a rebar mat, depth from the range
focus, false objects on noise-only volumes."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from holoradar.analysis.detect import detect, rebar_layers
from holoradar.analysis.detect.grid import Volume
from holoradar.analysis.detect.stack import _merge, _place, range_cell

warnings.filterwarnings("ignore", category=hr.AliasingWarning)
warnings.filterwarnings("ignore", category=hr.IlluminationWarning)

Z0 = 0.20                                   # the concrete's surface, 20 cm below the array
CONCRETE = hr.Medium.half_space(Z0, 6 + 0.3j)
RADIUS = 0.006                              # 12 mm bars
BAND = np.linspace(8e9, 12e9, 11)
POL = (0, 1, 0)


def _mat(aperture: hr.Aperture, snr_db: float = 30.0) -> hr.Hologram:
    # Two layers 15 cm apart each way: bars along x under 4 cm of cover, bars along y
    # under 6 cm (cover: concrete over the bar, so the axes lie a radius deeper).
    top = [hr.LineTarget((-0.3, y, Z0 + 0.04 + RADIUS), (0.3, y, Z0 + 0.04 + RADIUS), RADIUS)
           for y in (-0.075, 0.075)]
    bottom = [hr.LineTarget((x, -0.3, Z0 + 0.06 + RADIUS), (x, 0.3, Z0 + 0.06 + RADIUS), RADIUS)
              for x in (-0.075, 0.075)]
    scene = hr.Scene(CONCRETE, hr.PlaneWave(polarization=POL), top + bottom)
    return hr.simulate(scene, aperture, BAND, include_surface=False, snr_db=snr_db, seed=1)


def _check_mat(df, cell: float) -> None:
    assert list(df.kind) == ["line"] * 4, df[["kind", "x", "y", "depth", "snr_db"]]
    along_x = df[(df.azimuth_deg < 10) | (df.azimuth_deg > 170)]
    along_y = df[(df.azimuth_deg - 90).abs() < 10]
    assert len(along_x) == 2 and len(along_y) == 2
    # Across each bar within a quarter of the lateral cell.
    assert sorted(along_x.y) == pytest.approx([-0.075, 0.075], abs=cell / 4)
    assert sorted(along_y.x) == pytest.approx([-0.075, 0.075], abs=cell / 4)
    # Spacing within the 5 % an inspector's rebar map needs.
    assert df.spacing.to_numpy() == pytest.approx(0.15, rel=0.05)
    # Cover within the depth interval (the range's 95 % and the permittivity's
    # interval): a bar's echo comes from its top, at the cover depth.
    for rows, cover in ((along_x, 0.04), (along_y, 0.06)):
        assert (rows.depth_low <= cover).all() and (rows.depth_high >= cover).all(), rows
    # and the depth itself within a quarter of the range cell c0 / (2 n B).
    cz = range_cell(BAND, 6.0)
    assert along_x.depth.to_numpy() == pytest.approx(0.04, abs=cz / 4)
    assert along_y.depth.to_numpy() == pytest.approx(0.06, abs=cz / 4)
    # The mat per direction: two layers of two bars, 15 cm apart, 4 and 6 cm cover.
    layers = rebar_layers(df).sort_values("cover")
    assert layers.bars.tolist() == [2, 2]
    assert layers.spacing.to_numpy() == pytest.approx(0.15, rel=0.05)
    assert (layers.cover_low.to_numpy() <= [0.04, 0.06]).all()
    assert (layers.cover_high.to_numpy() >= [0.04, 0.06]).all()


@pytest.mark.slow
def test_rebar_mat_under_the_papers_array_across_a_band():
    # The paper's 16 x 16 array (2.5 cm, aliased at 12 GHz), 8-12 GHz, 11 frequencies;
    # the volume from 2 to 8.5 cm deep, searched without the hologram.
    h = _mat(hr.Aperture.grid(16, 0.025, polarization=POL))
    img = hr.migrate(h, np.arange(Z0 + 0.02, Z0 + 0.085, 0.005), medium=CONCRETE, upsample=4)
    df = detect(img, medium=CONCRETE, eps_interval=(5.5, 6.5))
    cell = hr.theory.lateral_resolution(hr.C0 / 10e9, CONCRETE.apparent_distance(Z0 + 0.05),
                                        0.40)
    _check_mat(df, cell)


@pytest.mark.slow
def test_rebar_mat_under_a_scanned_transceiver():
    # A transceiver scanned over 32 x 32 positions at 1.25 cm (40 cm), the same band.
    h = _mat(hr.Aperture.grid(32, 0.0125, monostatic=True, polarization=POL))
    img = hr.migrate(h, np.arange(Z0 + 0.02, Z0 + 0.085, 0.005), medium=CONCRETE, upsample=2)
    df = detect(img, medium=CONCRETE, eps_interval=(5.5, 6.5))
    cell = hr.theory.lateral_resolution(hr.C0 / 10e9, CONCRETE.apparent_distance(Z0 + 0.05),
                                        0.40) / 2        # two-way: half the receive-only cell
    _check_mat(df, cell)


def _noise_volumes(n: int, false_alarm: float, seed: int) -> tuple[int, float]:
    ap = hr.Aperture.paper()
    rng = np.random.default_rng(seed)
    found, expected = 0, 0.0
    for _ in range(n):
        d = rng.normal(size=(BAND.size, 16, 16)) + 1j * rng.normal(size=(BAND.size, 16, 16))
        img = hr.migrate(hr.Hologram(d, ap.x, ap.y, BAND), np.arange(0.40, 0.52, 0.005),
                         upsample=4)
        df = detect(img, false_alarm=false_alarm, kinds=("point",))
        found += len(df)
        expected += false_alarm * df.attrs["n_cells"]
    return found, expected


def test_false_objects_on_noise_only_wideband_volumes_quick():
    # 3 volumes at 1e-2 per cell: about 8 expected; Poisson, 3 sigma above. Searching
    # each plane at the volume's rate instead gave 2.4 times the nominal number.
    found, expected = _noise_volumes(3, 1e-2, seed=0)
    assert found <= expected + 3 * np.sqrt(expected), (found, expected)


@pytest.mark.slow
def test_false_objects_on_noise_only_wideband_volumes():
    # Measured: 99 on 30 volumes for 80.5 nominal (+2 sigma; the planes' maxima of one
    # noise maximum sometimes lie more than a cell apart and count twice). Poisson
    # bounds at 3 sigma.
    found, expected = _noise_volumes(30, 1e-2, seed=1)
    assert abs(found - expected) <= 3 * np.sqrt(expected), (found, expected)


def _row(kind, x, y, amp, **kw):
    base = {"kind": kind, "x": x, "y": y, "range": 0.3, "amplitude_db": amp, "snr_db": 30.0,
            "length": 0.0, "width": 0.0, "azimuth_deg": np.nan, "x_start": np.nan,
            "y_start": np.nan, "x_end": np.nan, "y_end": np.nan}
    base.update(kw)
    return base


def test_rows_of_one_object_in_several_planes_are_one():
    cell = 0.02
    line = {"length": 0.3, "azimuth_deg": 90.0}
    found = [(2, _row("line", 0.0, 0.0, 0.0, **line)),
             (3, _row("line", 0.004, 0.01, 3.0, **line)),      # the same bar, brighter
             (5, _row("line", 0.15, 0.0, 1.0, **line)),        # a parallel bar 15 cm off
             (4, _row("point", 0.002, 0.1, 6.0)),              # on the first bar: a piece
             (4, _row("point", 0.05, 0.1, 6.0)),               # beside it: an object
             (1, _row("point", 0.051, 0.101, 2.0))]            # that object again
    kept = _merge(found, cell)
    assert [(iz, r["kind"], r["x"]) for iz, r in kept] == \
        [(4, "point", 0.05), (3, "line", 0.004), (5, "line", 0.15)]


def test_range_from_the_range_profile():
    # A Gaussian range profile centred between planes: the parabola through the
    # logarithm of three samples is exact for it.
    z = np.arange(0.30, 0.40, 0.005)
    x = y = np.arange(-0.05, 0.051, 0.01)
    prof = np.exp(-0.5 * ((z - 0.3437) / 0.008) ** 2)
    data = prof[:, None, None] * np.ones((z.size, y.size, x.size))
    vol = Volume(data.astype(complex), x, y, z, BAND, False)
    out = _place(8, _row("point", 0.0, 0.0, 0.0), vol, 0.03, CONCRETE, None)
    assert out["range"] == pytest.approx(0.3437, abs=1e-9)
    # Cramer-Rao of a peak: sqrt(3 / (2 SNR)) c_z / pi at 30 dB.
    assert out["range_std"] == pytest.approx(np.sqrt(3 / 2e3) * 0.03 / np.pi)
    assert out["depth"] == pytest.approx(0.3437 - Z0)


def test_one_frequency_volume_still_needs_the_hologram():
    ap = hr.Aperture.paper()
    h = hr.Hologram(np.ones((16, 16), complex), ap.x, ap.y, 9.9e9)
    img = hr.migrate(h, np.array([0.40, 0.45, 0.50]), upsample=2)
    with pytest.raises(ValueError, match="one frequency needs hologram="):
        detect(img)


def test_rebar_layers_groups_directions_across_0_and_180_degrees():
    import pandas as pd

    rows = [{"kind": "line", "x": 0.0, "y": y, "azimuth_deg": az, "depth": 0.05}
            for y, az in ((-0.1, 179.0), (0.0, 1.0), (0.12, 0.5))]
    rows.append({"kind": "point", "x": 0.3, "y": 0.3, "azimuth_deg": np.nan, "depth": 0.1})
    t = rebar_layers(pd.DataFrame(rows))
    assert t.bars.tolist() == [3]
    assert t.azimuth_deg[0] == pytest.approx(0.1667, abs=1e-3)
    assert (t.spacing_min[0], t.spacing_max[0]) == pytest.approx((0.1, 0.12), abs=2e-3)
    with pytest.raises(ValueError, match="angle_tol_deg"):
        rebar_layers(pd.DataFrame(rows), angle_tol_deg=95)
    with pytest.raises(ValueError, match="objects must be"):
        rebar_layers([1, 2])


def test_rebar_layers_split_one_direction_by_depth():
    # A top and a bottom mat both along x, 4 and 10 cm deep: their depth intervals do not
    # overlap, so they are two layers; bars of one layer whose intervals overlap stay one.
    import pandas as pd

    rows = [{"kind": "line", "x": 0.0, "y": y, "azimuth_deg": 0.0, "depth": d,
             "depth_low": d - 0.004, "depth_high": d + 0.004}
            for y, d in ((-0.15, 0.040), (0.0, 0.043), (0.15, 0.041), (-0.1, 0.10), (0.1, 0.10))]
    t = rebar_layers(pd.DataFrame(rows))
    assert t.bars.tolist() == [3, 2]
    assert t.cover.tolist() == pytest.approx([0.041, 0.10])
    assert (t.cover_min[0], t.cover_mean[0], t.cover_max[0]) == pytest.approx(
        (0.040, 0.0413333, 0.043))
    assert (t.spacing_mean[0], t.spacing[1]) == pytest.approx((0.15, 0.2))


def test_an_area_seen_on_several_planes_is_one_area():
    # Each plane explains a disk by other components: the points and smaller areas
    # within a cell of the brightest area's outline are that area; a point two cells
    # beyond its edge is another object.
    cell = 0.02
    ring = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
    found = [(5, _row("area", 0.0, 0.0, 6.0, outline=ring, width=0.08)),
             (4, _row("point", 0.03, 0.01, 3.0)),                  # inside
             (6, _row("point", 0.055, 0.0, 2.0)),                  # 1.5 cm off its edge
             (3, _row("area", 0.01, 0.0, 1.0, outline=ring, width=0.06)),
             (4, _row("point", 0.09, 0.0, 2.5))]                   # 2.5 cells off its edge
    kept = _merge(found, cell)
    assert [(r["kind"], r["x"]) for _, r in kept] == [("area", 0.0), ("point", 0.09)]
