"""Line scans (B-scans) and antennas on the ground.

A line scan is a hologram of one row (``Hologram(data[f, x], x, frequency=f)``); it
images into an x-z section by the exact 2-D migration (fields that do not vary along
y: the row's spectrum has the one component ky = 0, which a grid of identical rows,
periodic in y, holds too). A ground whose surface is at range 0 has the antennas on
it (ground-coupled). The I/Q sign check keeps what is the same at every position of
a scan (the antenna's coupling, the flat surface's echo) out of its focus criterion.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from holoradar.data.hologram import C0

F = np.linspace(0.98e9, 2.0e9, 48)
EPS = 6.0
PITCH = 0.0213
BARS = ((-0.30, 0.10), (0.0, 0.12), (0.25, 0.13))   # (x, axis range) of bars along y
RADIUS = 0.008


@pytest.fixture(scope="module")
def bscan() -> hr.Hologram:
    """A ground-coupled transceiver's B-scan across three bars in concrete (simulate's
    bars: rows of induced dipoles, 6 m long: a line scan sees them as infinite)."""
    ground = hr.Medium.half_space(0.0, EPS)
    bars = [hr.LineTarget((x, -3.0, z), (x, 3.0, z), RADIUS) for x, z in BARS]
    ap = hr.Aperture.grid(60, PITCH, ny=1, monostatic=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return hr.simulate(hr.Scene(ground, targets=bars), ap, F, include_surface=False,
                           snr_db=30, seed=1)


def test_a_line_scan_is_one_row_and_says_so():
    x = np.arange(5) * 0.02
    h = hr.Hologram(np.ones((3, 5)), x, frequency=[1e9, 1.5e9, 2e9], monostatic=True)
    assert h.is_line and h.data.shape == (3, 1, 5) and h.pitch == pytest.approx((0.02, 0.02))
    one = hr.Hologram(np.ones(5), x, frequency=1e9)
    assert one.is_line and one.data.shape == (1, 5)
    assert not hr.Hologram(np.ones((2, 5)), x, [0.0, 0.02], 1e9).is_line
    with pytest.raises(ValueError, match="frequency is needed"):
        hr.Hologram(np.ones(5), x)


def test_the_line_migration_is_the_grids_for_a_field_constant_along_y(rng):
    # Identical rows on a grid periodic in y (pad=False) hold only ky = 0: every row of
    # its image is the line's image, to rounding (the same transfer at ky = 0).
    nx, ny = 40, 8
    x, y = np.arange(nx) * 0.02, np.arange(ny) * 0.02
    row = rng.standard_normal((F.size, nx)) + 1j * rng.standard_normal((F.size, nx))
    grid = hr.Hologram(np.repeat(row[:, None, :], ny, axis=1), x, y, F, monostatic=True)
    line = hr.Hologram(row, x, frequency=F, monostatic=True)
    ground = hr.Medium.half_space(0.0, EPS)
    zs = np.linspace(0.02, 0.3, 15)
    a = hr.migrate(grid, zs, medium=ground, pad=False, algorithm="frequency").data
    b = hr.migrate(line, zs, medium=ground, pad=False, algorithm="frequency").data
    assert b.shape == (zs.size, 1, nx)
    np.testing.assert_allclose(a, np.repeat(b, ny, axis=1), atol=1e-12 * np.abs(b).max())


def test_a_line_operator_is_a_pair(rng):
    x = np.arange(30) * PITCH
    h = hr.Hologram(np.zeros((F.size, 30), complex), x, frequency=F, monostatic=True)
    A = hr.migration_operator(h, np.linspace(0.02, 0.3, 12),
                              medium=hr.Medium.half_space(0.0, EPS))
    r = rng.standard_normal(A.shape[1]) + 1j * rng.standard_normal(A.shape[1])
    d = rng.standard_normal(A.shape[0]) + 1j * rng.standard_normal(A.shape[0])
    # sums of ~1e4 products in float64 through FFTs: 1e-12 relative is rounding
    assert abs(np.vdot(A @ r, d) - np.vdot(r, A.H @ d)) <= 1e-12 * abs(np.vdot(A @ r, d))


def test_bars_under_a_ground_coupled_b_scan_are_where_they_lie(bscan):
    ground = hr.Medium.half_space(0.0, EPS)
    zs = np.arange(0.005, 0.3, 0.005)
    img = hr.migrate(bscan, zs, medium=ground)
    a = np.abs(img.data[:, 0, :])
    # Bounds: one pitch across (the scan's sampling), a quarter of the range cell
    # c / (2 B n) = 6.0 cm in depth (the bar's echo comes from its top, a radius of
    # 8 mm above the axis, well inside 1.5 cm).
    quarter = C0 / (2 * np.ptp(F) * np.sqrt(EPS)) / 4
    for xb, zb in BARS:
        near = np.abs(img.x - xb) < 0.08
        iz, ix = np.unravel_index(np.argmax(a[:, near]), a[:, near].shape)
        assert abs(img.x[near][ix] - xb) <= PITCH
        assert abs(zs[iz] - zb) <= quarter


def test_the_b_scan_image_agrees_with_delay_and_sum(bscan):
    # An independent image: delay-and-sum of the round trip through the ground
    # (straight rays, the antennas on the surface), written out in NumPy. Both put
    # each bar within one pitch and a quarter range cell of the other's.
    ground = hr.Medium.half_space(0.0, EPS)
    zs = np.arange(0.005, 0.3, 0.005)
    img = np.abs(hr.migrate(bscan, zs, medium=ground, upsample=1).data[:, 0, :])
    x, k, d = bscan.x, 2 * np.pi * F / C0, bscan.data[:, 0, :]
    das = np.empty((zs.size, x.size))
    for iz, z in enumerate(zs):
        R = np.hypot(x[None, :] - x[:, None], z)
        das[iz] = np.abs(np.einsum("fpa,fa->p", np.exp(-2j * np.sqrt(EPS) * k[:, None, None]
                                                       * R[None]), d))
    # Each image's peak lies on its nearest plane, up to half a plane step (5 mm)
    # from its own maximum: the two may differ by one step more than the quarter cell.
    quarter = C0 / (2 * np.ptp(F) * np.sqrt(EPS)) / 4
    step = float(zs[1] - zs[0])
    for xb, _ in BARS:
        near = np.abs(x - xb) < 0.08
        p = [np.unravel_index(np.argmax(m[:, near]), m[:, near].shape) for m in (img, das)]
        assert abs(x[near][p[0][1]] - x[near][p[1][1]]) <= PITCH
        assert abs(zs[p[0][0]] - zs[p[1][0]]) <= quarter + step


@pytest.mark.parametrize("delay", [-0.02, 0.0, 0.03])
def test_the_sign_check_on_a_b_scan_is_not_fooled_by_the_antennas_coupling(bscan, delay):
    # A coupling 30 times the scene's RMS, the same at every position, at a delay behind,
    # at or in front of the antenna: as recorded and conjugated, the check answers the
    # truth (or abstains) and iq_convention answers the truth. Judged with the coupling
    # in, the conjugate wins or ties in most of these (the bug this guards).
    ground = hr.Medium.half_space(0.0, EPS)
    zs = np.arange(0.005, 0.3, 0.005)
    k = 2 * np.pi * F / C0
    amp = np.sqrt(np.mean(np.abs(bscan.data) ** 2))
    coupling = 30 * amp * np.exp(2j * k * np.sqrt(EPS) * delay)[:, None, None]
    true = bscan.with_data(bscan.data + coupling)
    for sign, rec in (("I+iQ", true), ("I-iQ", hr.conjugate(true))):
        assert hr.check_iq_sign(rec, zs, medium=ground).sign in (sign, None)
        assert hr.iq_convention(rec, zs, medium=ground) == sign


def test_the_sign_check_abstains_on_a_line_without_ranges(bscan):
    res = hr.check_iq_sign(bscan)
    assert res.sign is None and "line scan" in res.reason


def test_antennas_on_the_ground():
    g = hr.Medium.half_space(0.0, EPS)
    assert g.on_surface(0.0) and not g.on_surface(0.01)
    with pytest.raises(ValueError, match=">= 0 m"):
        hr.Medium.half_space(-0.01, EPS)
    # On the surface the transfer is the limit of a vanishing air gap: the gap's own
    # factor exp(i kz0 g) tends to 1 (here g = 1e-9 m: a phase of 4e-8 rad).
    kappa2 = np.linspace(0, 100.0**2, 7)
    on = g.vertical_transfer(40.0, kappa2, 0.0, 0.1)
    near = hr.Medium.half_space(1e-9, EPS).vertical_transfer(40.0, kappa2, 0.0, 0.1)
    np.testing.assert_allclose(on, near, rtol=1e-6)


def test_a_b_scan_file_through_the_layout_and_the_command_line(bscan, tmp_path):
    import scipy.io

    from cli_helpers import run

    f = tmp_path / "bscan.mat"
    scipy.io.savemat(f, {"F": np.conj(bscan.data[:, 0, :]), "f": F, "da": bscan.x - bscan.x[0]})
    h = hr.load(f, layout="data=F,frequency=f,x=da,axes=fx,iq_sign=I-iQ")
    assert h.is_line and h.monostatic and h.nf == F.size   # a line scan: a transceiver's
    np.testing.assert_allclose(h.data, bscan.data)
    out = tmp_path / "b.nc"
    run("image", f, "--layout", "data=F,frequency=f,x=da,axes=fx,iq_sign=I-iQ", "--eps", "6",
        "--z-surface", "0", "--z", "0.005:0.3:0.005", "-o", out)
    img = hr.load(out)
    assert img.data.shape[1] == 1 and out.with_suffix(".png").exists()


def test_bars_across_a_b_scan_are_counted_with_their_spacing_and_cover():
    # Five bars 15 cm apart, axes 10 cm deep (radius 8 mm: tops at 9.2 cm), under a
    # ground-coupled scan: detect on the section finds five lines across the scan, and
    # rebar_layers one layer. Bounds: spacing within 5 % (the spots' positions to a
    # fraction of the 2 cm lateral cell over 15 cm), cover within a quarter of the
    # range cell c / (2 B n) = 6.0 cm of the bars' tops.
    ground = hr.Medium.half_space(0.0, EPS)
    bars = [hr.LineTarget((x, -3.0, 0.10), (x, 3.0, 0.10), RADIUS)
            for x in (-0.3, -0.15, 0.0, 0.15, 0.3)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        h = hr.simulate(hr.Scene(ground, targets=bars),
                        hr.Aperture.grid(64, PITCH, ny=1, monostatic=True),
                        np.linspace(0.98e9, 2.0e9, 48), include_surface=False, snr_db=30,
                        seed=1)
    img = hr.migrate(h, np.arange(0.01, 0.25, 0.005), medium=ground)
    df = hr.detect(img, medium=ground)
    assert len(df) == 5 and set(df.kind) == {"line"} and np.allclose(df.azimuth_deg, 90.0)
    layers = hr.rebar_layers(df)
    assert len(layers) == 1 and int(layers.bars[0]) == 5
    assert abs(layers.spacing[0] - 0.15) <= 0.05 * 0.15
    quarter = C0 / (2 * 1.02e9 * np.sqrt(EPS)) / 4
    assert abs(layers.cover[0] - (0.10 - RADIUS)) <= quarter


def test_evenly_spaced_lines_are_one_grid_migrated_in_3d(rng):
    # Rows of one grid given as lines: stacked, the volume is the grid's migration,
    # bit for bit (the same hologram, made again from its rows).
    x, y = np.arange(24) * 0.02, np.arange(6) * 0.03
    data = rng.standard_normal((F.size, 6, 24)) + 1j * rng.standard_normal((F.size, 6, 24))
    grid = hr.Hologram(data, x, y, F, monostatic=True)
    lines = [hr.Hologram(data[:, j, :], x, frequency=F, monostatic=True) for j in range(6)]
    zs = np.linspace(0.02, 0.2, 7)
    ground = hr.Medium.half_space(0.0, EPS)
    vol = hr.stack_lines(lines[::-1], y[::-1], zs, medium=ground)   # any order
    assert vol.method == "lines:3d"
    np.testing.assert_array_equal(vol.data, hr.migrate(grid, zs, medium=ground).data)


def test_uneven_lines_with_their_own_starts_show_a_bar_across_them(bscan):
    # Three lines at uneven y, each starting elsewhere, over the same bars (along y):
    # each line's section shows every bar at its x on the common grid, within a pitch.
    ground = hr.Medium.half_space(0.0, EPS)
    zs = np.arange(0.02, 0.2, 0.005)
    shifts = (0, 5, 11)   # traces cut from the start
    lines = [hr.Hologram(bscan.data[:, 0, s:], bscan.x[s:], frequency=F, monostatic=True)
             for s in shifts]
    vol = hr.stack_lines(lines, [0.0, 0.07, 0.31], zs, medium=ground)
    assert vol.method == "lines:2d" and vol.data.shape[1] == 3
    a = np.abs(vol.data)
    for j in range(3):
        for xb, _ in BARS:
            near = np.abs(vol.x - xb) < 0.08
            ix = np.argmax(a[:, j, near].max(axis=0))
            assert abs(vol.x[near][ix] - xb) <= PITCH
    with pytest.raises(ValueError, match="one distinct position per line"):
        hr.stack_lines(lines, [0.0, 0.0, 0.1], zs)


def test_line_scans_go_into_a_survey_store_and_its_map_has_a_row_per_line(tmp_path):
    # Three lines at uneven y, each starting elsewhere (their poses), through the batch
    # into a store: the map at the bars' depth holds one row per line, at the line's
    # y, each bar within a pitch of its x.
    ground = hr.Medium.half_space(0.0, EPS)
    bars = [hr.LineTarget((x, -3.0, 0.10), (x, 3.0, 0.10), RADIUS) for x in (-0.2, 0.0, 0.2)]
    f = np.linspace(0.98e9, 2.0e9, 16)
    paths = []
    for i, (x0, y0) in enumerate(((0.0, 0.0), (0.05, 0.1), (-0.03, 0.25))):
        ap = hr.Aperture.grid(40, PITCH, ny=1, monostatic=True, pose=hr.Pose((x0, y0, 0.0)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            h = hr.simulate(hr.Scene(ground, targets=bars), ap, f, include_surface=False,
                            snr_db=30, seed=i)
        paths.append(hr.save(h, tmp_path / f"line{i}.nc"))
    s = hr.survey.run_batch(paths, tmp_path / "s.zarr", z=np.arange(0.02, 0.2, 0.005),
                            medium=ground, scheduler="synchronous")
    assert s["done"] == 3 and not s["skipped"]
    m = hr.survey.mosaic(tmp_path / "s.zarr", 0.09)
    np.testing.assert_allclose(m.y, [0.0, 0.1, 0.25])
    for row in m.data:
        for xb in (-0.2, 0.0, 0.2):
            near = np.abs(m.x - xb) < 0.05
            assert abs(m.x[near][np.argmax(row[near])] - xb) <= PITCH


def test_the_layout_keys_a_transceiver_on_the_axes_not_on_one_row(tmp_path):
    # A grid file with one row is a receiver array's unless it says otherwise; a line
    # declared by its axes (fx, or x alone at one frequency) is a transceiver's.
    x = np.arange(8) * 0.01
    np.savez(tmp_path / "row.npz", E=np.ones((1, 8)) + 0j, x=x, y=[0.05], frequency=9.9e9)
    assert not hr.load(tmp_path / "row.npz", layout="data=E", check=False).monostatic
    np.savez(tmp_path / "line.npz", E=np.ones(8) + 0j, x=x, frequency=9.9e9)
    h = hr.load(tmp_path / "line.npz", layout="data=E,axes=x", check=False)
    assert h.is_line and h.monostatic and h.data.shape == (1, 8)


def test_a_flat_scan_has_no_sign_and_a_one_frequency_section_no_objects():
    # Data the same at every position hold nothing compact once the flat part is out:
    # the sharpness is 0 on both sides (not NaN), and the tie reads as recorded.
    x = np.arange(16) * 0.01
    h = hr.Hologram(np.full((16, 16), 1 + 1j), x, x, 9.9e9, monostatic=True)
    assert hr.iq_convention(h, [0.1, 0.2]) == "I+iQ"
    line = hr.Hologram(np.ones(16) + 0j, x, frequency=9.9e9, monostatic=True)
    img = hr.migrate(line, np.linspace(0.05, 0.3, 6))
    with pytest.raises(ValueError, match="no range focus"):
        hr.detect(img)
