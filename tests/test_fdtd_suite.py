"""Imaging and detection on the project's own full-wave cases (gprMax FDTD, the G suite
in tests/data): fields holoradar's model did not make.

Bounds, from the geometry and the band (not from the results):
- lateral: a bar's axis within a quarter of the lateral resolution cell
  ``lambda L / A`` (L the apparent range of its depth, A the 24 cm aperture: 1.3 cm at
  3 cm cover, so 3.3 mm), and never more than the 1 cm a rebar locator must meet;
- spacing within 5 % (a quarter cell on either bar over 7 cm is 4.7 %);
- depth: between the bar's top (the cover) and its axis, each widened by a quarter
  of the range cell (see the test);
- equal bars' reflectivities within 3 dB (each bar's model error, the cylinder's
  vector response against the operator's points, is 5-15 % in amplitude: up to
  1.2 dB each, 2.4 dB apart; FDTD's staircased cross-sections add a few %);
- the FDTD's own accuracy (numerical dispersion in concrete at 11 GHz: 2.3 % phase
  speed, 0.7 mm over a 3 cm cover) lies well inside these.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.signal import find_peaks

import holoradar as hr
from fdtd_suite import load

warnings.filterwarnings("ignore", category=hr.AliasingWarning)

APERTURE = 0.24


def _cell(case, depth: float) -> float:
    return hr.C0 / 10e9 * case.ground.apparent_distance(case.surface + depth) / APERTURE


def _mat_from_above(every: int):
    case = load("G_mat1_top", every=every)
    zs = np.arange(case.surface + 0.01, case.surface + 0.07, 0.0025)
    img = hr.migrate(case.hologram, zs, medium=case.ground)
    return case, hr.detect(img, hologram=case.hologram, medium=case.ground, progress=False)


def _four_bars(case, df) -> None:
    bars = [ob["axis_x_m"] for ob in case.meta["objects_rel"]]
    cover = -case.meta["objects_rel"][0]["axis_z_m"] - \
        case.meta["objects_rel"][0]["diameter_m"] / 2
    assert list(df.kind) == ["line"] * 4, df[["kind", "x", "y", "depth", "length"]]
    assert np.all(np.abs(df.azimuth_deg - 90) < 5)
    tol = min(_cell(case, cover) / 4, 0.01)
    assert sorted(df.x) == pytest.approx(sorted(bars), abs=tol)
    assert df.spacing.to_numpy() == pytest.approx(0.07, rel=0.05)
    # A conducting cylinder's echo comes from its face towards the array: its top at
    # large k a, its axis in the Rayleigh limit (these bars: k_g a = 2.8 at 10 GHz);
    # each depth is read to a quarter of the range cell c / (2 B n) = 3.35 cm, so it
    # lies between the cover and the axis, each widened by that quarter. (The
    # reported 95 % interval does not always hold the cover: it misses it by 1-5 mm,
    # since the range model does not carry the bar's radius.)
    axis = -case.meta["objects_rel"][0]["axis_z_m"]
    quarter = hr.C0 / (2 * 2e9 * np.sqrt(5.0)) / 4
    assert ((df.depth >= cover - quarter) & (df.depth <= axis + quarter)).all(), \
        df[["x", "depth"]]
    # The surface multiples at twice the cover under the bars nearest the source are
    # recognised as such, not listed.
    for m in df.attrs["multiples"]:
        assert m["depth"] == pytest.approx(2 * m["of_depth"], abs=0.5 * hr.C0 / (
            2 * 2e9 * np.sqrt(5.0)))


def test_a_mat_lit_from_above_is_four_lines_every_other_frequency():
    # 11 of the 21 frequencies (9-11 GHz in 200 MHz steps): the same band and range
    # cell, an alias c/(2 df) = 33 cm of path (far beyond the 7 cm searched).
    case, df = _mat_from_above(every=2)
    _four_bars(case, df)


@pytest.mark.slow
def test_a_mat_lit_from_above_is_four_lines():
    case, df = _mat_from_above(every=1)
    _four_bars(case, df)


def test_the_adjoint_image_places_the_upper_bars_of_a_two_layer_mat():
    # The upper layer's bars along y (x = -0.10, 0, +0.10) under 5 cm of concrete, lit by
    # a y-dipole 18 cm beside the array: in the adjoint image's plane at their cover,
    # summed along y over |y| <= 5 cm, the across-x profile peaks at each bar.
    case = load("G_mat2_ydip", every=2)
    cover = 0.05
    zs = case.surface + np.array([cover])
    img = hr.migrate(case.hologram, zs, medium=case.ground, upsample=4)
    a = np.abs(img.data[0] if img.data.ndim == 3 else img.data) ** 2
    prof = a[np.abs(img.y) <= 0.05].sum(0)
    peaks, _ = find_peaks(prof, height=0.01 * prof.max())
    xs = img.x[peaks]
    tol = _cell(case, cover) / 4
    for xb in (-0.10, 0.0, 0.10):
        assert np.min(np.abs(xs - xb)) < tol, (xb, xs)


def test_the_inversion_gives_a_mat_lit_from_above_equal_bars():
    # hr.invert's reflectivity: the four equal bars' peaks within 3 dB of each other
    # (module notes; measured 1.9 dB). Lit from above, the bars are almost equally lit
    # (the adjoint image's peaks: 2.8 dB apart; the inversion without the illumination:
    # 2.6 dB), so this checks the inversion on full-wave data, not the illumination's
    # division; the side-lit two-layer mat, which would, is not yet within 3 dB.
    case = load("G_mat1_top", every=2)
    zs = np.arange(case.surface + 0.02, case.surface + 0.055, 0.0025)
    r = hr.invert(case.hologram, zs, medium=case.ground, progress=False)
    a = np.abs(r.data)
    X, Y = np.meshgrid(r.x, r.y)
    levels = []
    for ob in case.meta["objects_rel"]:
        on_bar = (np.abs(X - ob["axis_x_m"]) < 0.01) & (np.abs(Y) < 0.05)
        levels.append(20 * np.log10(float(a[:, on_bar].max())))
    assert np.ptp(levels) < 3.0, levels
