"""``hr.detect`` with the hologram reads objects off the inverted reflectivity: equal
bars lit from beside the array are three equal lines (the adjoint image's levels fall
with the illumination), and the full-wave rod is one line.

Bounds: positions within a quarter of the lateral resolution cell ``lambda L / A``;
equal objects' Born amplitudes within 3 dB (each bar's model error, the cylinder's
vector response against the operator's points, is 5-15 % in amplitude, up to
+-1.2 dB each); the spacing of parallel bars within 5 % (a quarter cell over 9 cm).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr

warnings.filterwarnings("ignore", category=hr.AliasingWarning)

Y = (0, 1, 0)
CONCRETE = hr.Medium.half_space(0.20, 6.0 + 0.3j)
BARS_X = (-0.09, 0.0, 0.09)


@pytest.fixture(scope="module")
def bars() -> tuple[hr.Hologram, hr.Image]:
    """Three equal 12 mm bars along y, axes 5 cm under the concrete, lit by a y-dipole
    20 cm beside a 31 x 31 array at 1 cm, 8-12 GHz (3 frequencies), 30 dB."""
    dipole = hr.Dipole((-0.20, 0.0, 0.05), Y)
    targets = [hr.LineTarget((xb, -0.12, 0.25), (xb, 0.12, 0.25), radius=0.006)
               for xb in BARS_X]
    h = hr.simulate(hr.Scene(CONCRETE, dipole, targets), hr.Aperture.grid(31, 0.01,
                    polarization=Y), np.linspace(8e9, 12e9, 3), include_surface=False,
                    snr_db=30, seed=3)
    return h, hr.migrate(h, np.arange(0.23, 0.275, 0.01), medium=CONCRETE)


def test_equal_bars_beside_the_source_are_three_equal_lines(bars):
    h, img = bars
    a = np.abs(img.data)
    seen = [a[:, :, np.abs(img.x - xb) < 0.015].max() for xb in BARS_X]
    assert 20 * np.log10(min(seen) / max(seen)) < -4.0     # the adjoint: -5.5 dB measured
    df = hr.detect(img, hologram=h, medium=CONCRETE, eps_interval=(5.0, 7.0))
    lines = df[df.kind == "line"].sort_values("x")
    assert len(lines) == 3, df[["kind", "x", "y", "range", "amplitude_db"]]
    L = CONCRETE.apparent_distance(0.245)
    cell = hr.theory.lateral_resolution(hr.C0 / 10e9, L, 0.31)
    assert np.all(np.abs(lines.x.to_numpy() - np.array(BARS_X)) < cell / 4)
    assert np.all(np.abs(lines.azimuth_deg - 90.0) < np.degrees(np.arctan2(cell, 0.2)))
    assert np.ptp(lines.amplitude_db) < 3.0
    assert np.all(np.abs(lines.spacing - 0.09) < 0.05 * 0.09)
    # The bright line is the bar's top, 4.4 cm under the surface: inside the interval
    # the permittivity interval gives its depth.
    assert np.all((lines.depth_low <= 0.044 + 0.005) & (lines.depth_high >= 0.044 - 0.005))
    assert df.attrs["model"] == "reflectivity:sparse"


def test_the_illumination_is_what_makes_them_equal(bars):
    # Guard: with the source's field left out of the operator (illumination="none") the
    # bars' reflectivities keep the illumination's fall across them.
    h, _ = bars
    r = hr.invert(h, np.arange(0.23, 0.275, 0.01), medium=CONCRETE, illumination="none",
                  progress=False)
    a = np.abs(r.data)
    seen = [a[:, np.abs(r.y) < 0.08][:, :, np.abs(r.x - xb) < 0.015].max() for xb in BARS_X]
    assert 20 * np.log10(min(seen) / max(seen)) < -3.0


@pytest.mark.slow
def test_gprmax_rod_with_its_dipole_is_one_line():
    # gprMax FDTD (run C - run B): a PEC rod 15 mm across, 30 cm long along y at x = 0,
    # 10 cm deep in sand, lit by a y-dipole 20 cm beside the 41 x 41 array (1 cm), 21
    # frequencies 9-11 GHz; 31 s measured.
    from conftest import DATA

    with np.load(DATA / "run_B_background.npz") as b, np.load(DATA / "run_C_rod.npz") as c:
        f = b["freqs_hz"].astype(float)
        # The fixture's time convention, exp(-i omega t), is holoradar's.
        scat = c["Ey"].astype(complex) - b["Ey"].astype(complex)
        x, y = b["x_m"].copy(), b["y_m"].copy()
    sand = hr.Medium.half_space(0.30, hr.permittivity(2.5, sigma=0.0069, frequency=9.9e9))
    src = hr.PointSource((-0.2, 0.0, 0.2), axis=Y, dipole=True)
    h = hr.Hologram(scat, x, y, f, source=src)
    df = hr.detect(hr.migrate(h, np.arange(0.36, 0.46, 0.01), medium=sand), hologram=h,
                   medium=sand)
    assert list(df.kind) == ["line"], df[["kind", "x", "y", "range", "amplitude_db"]]
    cell = hr.theory.lateral_resolution(hr.C0 / 10e9, sand.apparent_distance(0.40), 0.41)
    row = df.iloc[0]
    assert abs(row.x) < cell / 4 and abs(row.azimuth_deg - 90.0) < 2.0
    assert abs(row.depth - 0.10) < 0.01


@pytest.mark.slow   # the fast suite's mat is the 3 x 3 one without its noise, below
def test_two_layer_mat_under_the_papers_array_with_its_noise_is_four_bars():
    # The paper's 16 x 16 array (2.5 cm: no evanescent band to estimate the noise from,
    # so it is given), 8-12 GHz, 11 frequencies, 30 dB: two bars along x under 4 cm of
    # concrete crossing two along y under 6 cm. Where they cross the sparse solution
    # gives the crossing to the upper bar; the lower bars' pieces are joined again.
    from test_detect_mat import CONCRETE as CONC
    from test_detect_mat import POL, Z0, _mat

    h = _mat(hr.Aperture.grid(16, 0.025, polarization=POL))
    img = hr.migrate(h, np.arange(Z0 + 0.02, Z0 + 0.085, 0.005), medium=CONC, upsample=4)
    sigma = np.sqrt(np.mean(np.abs(h.data) ** 2) / 10 ** 3)          # the 30 dB simulated
    df = hr.detect(img, hologram=h, medium=CONC, eps_interval=(5.5, 6.5), noise=sigma)
    assert list(df.kind) == ["line"] * 4, df[["kind", "x", "y", "depth", "length"]]
    along_x = df[(df.azimuth_deg < 10) | (df.azimuth_deg > 170)]
    along_y = df[(df.azimuth_deg - 90).abs() < 10]
    cell = hr.theory.lateral_resolution(hr.C0 / 10e9, CONC.apparent_distance(Z0 + 0.05), 0.40)
    assert sorted(along_x.y) == pytest.approx([-0.075, 0.075], abs=cell / 4)
    assert sorted(along_y.x) == pytest.approx([-0.075, 0.075], abs=cell / 4)
    assert df.spacing.to_numpy() == pytest.approx(0.15, rel=0.05)
    for rows, cover in ((along_x, 0.04), (along_y, 0.06)):
        assert (rows.depth_low <= cover).all() and (rows.depth_high >= cover).all(), rows


def test_noise_without_the_hologram_is_refused(bars):
    _, img = bars
    with pytest.raises(ValueError, match=r"noise .* needs hologram="):
        hr.detect(img, medium=CONCRETE, noise=1e-3)


@pytest.fixture(scope="module")
def mat_3x3(tmp_path_factory):
    """Three bars along x under 4 cm of concrete crossing three along y under 6 cm,
    12.5 cm apart, the paper's array (2.5 cm: the noise cannot be estimated and is not
    given), 8-12 GHz at 11 frequencies, 30 dB; its hologram and image (planes 1 cm apart,
    under the 1.5 cm range cell; two pixels per pitch) as files."""
    from test_detect_mat import CONCRETE as CONC
    from test_detect_mat import POL, RADIUS, Z0

    at = (-0.125, 0.0, 0.125)
    top = [hr.LineTarget((-0.3, y, Z0 + 0.04 + RADIUS), (0.3, y, Z0 + 0.04 + RADIUS), RADIUS)
           for y in at]
    bottom = [hr.LineTarget((x, -0.3, Z0 + 0.06 + RADIUS), (x, 0.3, Z0 + 0.06 + RADIUS),
                            RADIUS) for x in at]
    scene = hr.Scene(CONC, hr.PlaneWave(polarization=POL), top + bottom)
    h = hr.simulate(scene, hr.Aperture.grid(16, 0.025, polarization=POL),
                    np.linspace(8e9, 12e9, 11), include_surface=False, snr_db=30, seed=1)
    img = hr.migrate(h, np.arange(Z0 + 0.02, Z0 + 0.085, 0.01), medium=CONC, upsample=2)
    d = tmp_path_factory.mktemp("mat")
    return h, img, CONC, hr.save(h, d / "holo.nc"), hr.save(img, d / "img.nc")


def test_three_by_three_mat_without_its_noise_is_six_bars_on_every_path(mat_3x3):
    # Where bars cross 2 cm apart in depth (more than the range cell c/(2 n B) = 1.5 cm),
    # the range peaks of a column separate them; the noise comes from a first fit's
    # residual. Bounds as above: a quarter cell across, spacing within 5 %, each cover
    # within its 95 % interval.
    from cli_helpers import run

    _, _, conc, holo, image = mat_3x3
    # The library on the files as read back (what the command line reads).
    df = hr.detect(hr.load(image), hologram=hr.load(holo), medium=conc)
    assert list(df.kind) == ["line"] * 6, df[["kind", "x", "y", "depth", "length"]]
    along_x = df[(df.azimuth_deg < 10) | (df.azimuth_deg > 170)]
    along_y = df[(df.azimuth_deg - 90).abs() < 10]
    cell = hr.theory.lateral_resolution(hr.C0 / 10e9, conc.apparent_distance(0.25), 0.40)
    assert sorted(along_x.y) == pytest.approx([-0.125, 0.0, 0.125], abs=cell / 4)
    assert sorted(along_y.x) == pytest.approx([-0.125, 0.0, 0.125], abs=cell / 4)
    assert df.spacing.to_numpy() == pytest.approx(0.125, rel=0.05)
    for rows, cover in ((along_x, 0.04), (along_y, 0.06)):
        assert (rows.depth_low <= cover).all() and (rows.depth_high >= cover).all(), rows
    # The command line on the files gives the library's table on the loaded image.
    res = run("detect", image, "--hologram", holo, "--eps", "6+0.3j", "--z-surface", "0.2",
              "--json")
    import json

    got = json.loads(res.output)
    assert got["n_objects"] == 6
    assert [o["kind"] for o in got["objects"]] == list(df.kind)
    np.testing.assert_allclose([o["y"] for o in got["objects"]], df.y, rtol=0, atol=1e-12)


def test_cli_searches_a_wideband_volume_without_its_hologram_as_the_library(mat_3x3):
    # The library searches a wideband volume plane by plane; the command line does the
    # same job instead of refusing it.
    import json

    from cli_helpers import run

    _, _, conc, _, image = mat_3x3
    res = run("detect", image, "--eps", "6+0.3j", "--z-surface", "0.2", "--json")
    got = json.loads(res.output)
    ref = hr.detect(hr.load(image), medium=conc)
    assert got["n_objects"] == len(ref)
    assert got["metadata"]["model"] == ref.attrs["model"] == "window, by planes"
    # Six bars, or one line saying why none and what to pass.
    if got["n_objects"] != 6:
        note = got["metadata"]["note"]
        assert got["n_objects"] == 0 and "\n" not in note
        assert "image's own level" in note and "--hologram FILE" in note
        assert ref.attrs["note"] == note                 # the library says the same


def test_the_floor_is_the_model_error_of_what_was_found_at_most():
    # What the fit leaves beyond the noise bounds a spurious object's energy, but an
    # echo from beside the grid (which no voxel can explain) leaves more than the
    # model's error of the objects found, MODEL_ERROR^2 of their energy, can make.
    from holoradar.analysis.detect.reflectivity import MODEL_ERROR, _floor

    # a residual of model error only: its energy beyond the noise
    assert _floor(0.01, residual=0.2, noise_norm=0.1, found=10.0) == pytest.approx(0.03)
    # a residual far above what the found objects' error can be: capped there
    assert _floor(0.01, residual=3.0, noise_norm=0.1, found=1.0) == \
        pytest.approx(MODEL_ERROR**2)
    # never below the noise's threshold squared
    assert _floor(0.5, residual=0.1, noise_norm=0.1, found=1.0) == pytest.approx(0.25)


def test_fragments_join_a_bar_near_its_own_voxels_not_through_each_other():
    # A bar along x and a chain of weak pieces leaving it along y, each within a cell of
    # the one before: only the piece by the bar's own voxels is its fragment (a chain
    # would widen the bar along every bar that crosses it).
    from holoradar.analysis.detect.reflectivity import _merge_fragments

    cell, rc = 0.02, 0.015

    def ob(xs, ys, w):
        xs, ys = np.atleast_1d(xs).astype(float), np.atleast_1d(ys).astype(float)
        n = xs.size
        return {"w": np.full(n, w), "vals": np.full(n, np.sqrt(w) + 0j), "x": xs, "y": ys,
                "z": np.full(n, 0.25), "c": np.ones(n), "dx": 0.005, "dz": 0.005}

    bar = ob(np.arange(-0.15, 0.151, 0.005), np.zeros(61), 1.0)
    chain = [ob(0.0, 0.015 * (k + 1), 1e-3) for k in range(4)]   # 1.5 cm steps in y
    kept = _merge_fragments([bar, *chain], cell, rc)
    assert len(kept) == 4 and kept[0]["x"].size == 62     # the first piece only
