"""``holoradar view`` end to end: the page in headless Chromium against the Python API.

The page is driven as a user would (its widgets' values are set in the browser and
reach the server over the websocket); what it shows is read from the models it
draws (the peak readout, the glare report) and compared with the same settings
computed by holoradar's public functions in this process.

Data: gprMax's FDTD run C (independent full-wave data, tests/data/README.md): a
steel rod 10 cm deep in sand, lit by a y-directed dipole 10 cm above the sand and
20 cm to the side, with the sand's glare and the dipole's direct wave in the
hologram; and SMUTHI's metal sphere in sand seen under five plane-wave incidences.

Screenshots go to ``tmp_path``; with ``HOLORADAR_SCREENSHOTS=DIR`` (``make
screenshots``) also to DIR, for the documentation's gallery.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

import holoradar as hr
from holoradar.analysis.metrics import peak_position
from holoradar.app.view.browser import (
    ViewerProcess,
    click_button,
    find_chromium,
    headless_chromium,
    measure_slider,
    model_value,
    set_model,
    shown_db,
    wait_idle,
)

DATA = Path(__file__).parent / "data"
_, _, WHY = find_chromium()
pytestmark = [pytest.mark.browser,
              pytest.mark.skipif(bool(WHY), reason=f"no browser for the viewer tests: {WHY}")]

SIGMA = 0.0069  # S/m, the sand of the gprMax runs
PEAK = re.compile(r"peak: x = (-?[\d.]+) cm, y = (-?[\d.]+) cm,\s+depth = (-?[\d.]+) cm, "
                  r"\|E\| = (-?[\d.]+) dB")
# The page prints cm with 2 decimals and dB with 1: a shown number is the API's
# value rounded, so they agree to half the last digit (plus float noise).
CM_TOL = 0.005 + 1e-9
DB_TOL = 0.05 + 1e-9
# The picture itself travels as float32 dB: 24-bit mantissa, so |dB| < 200 is carried to
# 200 * 2**-24 = 1.2e-5 dB.
PICTURE_DB_TOL = 2e-5
# Both images are computed in single precision (the default), each within 1e-6 of the
# peak of double precision: a pixel a = 10^(dB/20) below the peak carries up to
# 2e-6 / a relative, 20 / ln 10 * 2e-6 / a dB.
SINGLE = 2e-6


def assert_db_close(shown, api_db, err_msg=""):
    """The picture's dB against the API's: float32 transport plus single precision."""
    shown, api_db = np.asarray(shown, float), np.asarray(api_db, float)
    tol = PICTURE_DB_TOL + 20 / np.log(10) * SINGLE * 10 ** (-api_db / 20)
    bad = np.abs(shown - api_db) > tol
    assert not bad.any(), f"{err_msg}: {int(bad.sum())} pixels off, worst " \
        f"{np.abs(shown - api_db)[bad].max():.3g} dB"


def _db(img, ref: float) -> np.ndarray:
    return 20 * np.log10(np.maximum(np.abs(img.data), 1e-300) / ref)


def _shot(driver, tmp_path: Path, name: str) -> Path:
    p = tmp_path / name
    assert driver.save_screenshot(str(p)), "the browser took no screenshot"
    assert p.stat().st_size > 10_000  # a page, not a blank
    gallery = os.environ.get("HOLORADAR_SCREENSHOTS")
    if gallery:
        shutil.copyfile(p, Path(gallery) / name)
    return p


@contextlib.contextmanager
def _page(browser, args):
    """``holoradar view ARGS`` served and open in the browser. On leaving, the browser
    leaves the page before the server stops: the closed websocket is not the next
    page's console error."""
    with ViewerProcess(args) as server:
        browser.get(server.url)
        wait_idle(browser)
        try:
            yield server
        finally:
            browser.get("about:blank")
            browser.get_log("browser")


def _console_errors(driver) -> list[dict]:
    return [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]


def _peak(driver) -> tuple[float, float, float, float]:
    text = model_value(driver, "peak")
    m = PEAK.search(text)
    assert m, f"no peak readout in {text!r}"
    x, y, d, level = map(float, m.groups())
    return x / 100, y / 100, d / 100, level


@pytest.fixture(scope="module")
def rod(tmp_path_factory):
    """Run C at 9.9 GHz as a holoradar file, with its dipole and sand."""
    d = tmp_path_factory.mktemp("rod")
    with np.load(DATA / "run_C_rod.npz") as c:
        fi = int(np.argmin(np.abs(c["freqs_hz"] - 9.9e9)))
        f = float(c["freqs_hz"][fi])
        h = hr.Hologram(c["Ey"][fi].astype(complex), c["x_m"], c["y_m"], f,
                        source=hr.PointSource((-0.20, 0.0, 0.20), axis=(0.0, 1.0, 0.0),
                                              dipole=True))
    sand = hr.Medium.half_space(0.30, hr.permittivity(2.5, sigma=SIGMA, frequency=f))
    return hr.save(h, d / "rod.nc"), h, sand


@pytest.fixture(scope="module")
def browser():
    driver = headless_chromium(1600, 1150)  # the whole page, for the screenshots
    yield driver
    driver.quit()


@pytest.fixture(scope="module")
def rod_page(rod, browser, tmp_path_factory):
    path, _, _ = rod
    out = tmp_path_factory.mktemp("exports")
    # the raw hologram first (the viewer would open with the glare removed)
    with _page(browser, [path, "--eps", "2.5", "--sigma", str(SIGMA), "--z-surface", "0.30",
                         "--depth", "0.05", "--glare", "off", "--export-dir", out]) as server:
        yield browser, server, out


_SWEEP_PEAK: dict[tuple[int, int], float] = {}


def _api_plane(h, sand, depth):
    """What the page images at a depth: holoradar.migrate with the page's defaults
    (4x upsampling, the full field of view), in dB re the depth sweep's peak (the
    sweep imaged once per hologram and ground: the module's fixtures)."""
    img = hr.migrate(h, 0.30 + depth, medium=sand, upsample=4, fov="full")
    key = (id(h), id(sand))
    if key not in _SWEEP_PEAK:
        sweep = hr.migrate(h, 0.30 + np.linspace(0.0, 0.25, 61), medium=sand, upsample=4,
                           fov="full")
        _SWEEP_PEAK[key] = float(np.abs(sweep.data).max())
    return img, _db(img, _SWEEP_PEAK[key])


def test_depth_slider_shows_the_apis_peak(rod, rod_page, tmp_path):
    _, h, sand = rod
    driver, _, _ = rod_page
    for depth_cm in (10.0, 7.5):
        set_model(driver, "depth", "value", depth_cm)
        x, y, d, level = _peak(driver)
        img, api_db = _api_plane(h, sand, depth_cm / 100)
        ax, ay, az = peak_position(img)
        assert abs(x - ax) < CM_TOL / 100 and abs(y - ay) < CM_TOL / 100
        assert abs(d - (az - 0.30)) < CM_TOL / 100
        assert abs(level - api_db.max()) < DB_TOL
        assert_db_close(shown_db(driver), api_db)
    _shot(driver, tmp_path, "viewer_rod_raw.png")
    assert not _console_errors(driver)


def test_glare_suppression_reports_the_apis_numbers(rod, rod_page, tmp_path):
    _, h, sand = rod
    driver, _, _ = rod_page
    set_model(driver, "depth", "value", 10.0)
    set_model(driver, "glare", "value", "image_source")
    report = model_value(driver, "glare_report")
    cleaned, rep = hr.suppress_surface(h, sand, h.source, "image_source")
    cells = re.findall(r"<td>([^<]*)</td>", report)
    assert cells[0] == "rod.nc", report
    assert abs(float(cells[1]) - rep.glare_removed_db) < DB_TOL
    assert abs(float(cells[2]) - rep.direct_removed_db) < DB_TOL
    assert abs(float(cells[3]) - rep.glare_suppression_db) < DB_TOL
    # eps shown as "eps' = re ± std (95 %: lo .. hi)", digits from the std
    m = re.match(r"eps' = ([\d.]+) ± ([\d.]+) \(95 %: ([\d.]+) \.\. ([\d.]+)\)", cells[4])
    assert m, cells[4]
    assert float(m.group(1)) == pytest.approx(rep.eps.real, abs=float(m.group(2)) / 10)
    assert float(m.group(2)) == pytest.approx(rep.eps_std[0], rel=0.05)
    # The image after suppression: the rod, where the API's cleaned hologram puts it.
    x, y, d, _ = _peak(driver)
    img = hr.migrate(cleaned, 0.40, medium=sand, upsample=4, fov="full")
    ax, ay, _ = peak_position(img)
    assert abs(x - ax) < CM_TOL / 100 and abs(y - ay) < CM_TOL / 100
    assert abs(d - 0.10) < CM_TOL / 100
    _shot(driver, tmp_path, "viewer_rod_glare.png")
    assert not _console_errors(driver)
    set_model(driver, "glare", "value", "off")


def test_mirror_source_plane_shows_the_glare_where_geometry_puts_it(rod, rod_page):
    # The dipole 10 cm above the sand (range 0.20 m) has its image in the surface (0.30 m)
    # at range 2 * 0.30 - 0.20 = 0.40 m, below the dipole at (-0.20, 0): the glare focuses
    # there. The mirror lies over the aperture's edge, where a focus is still found to
    # better than a quarter wavelength (0.76 cm).
    _, h, _ = rod
    driver, _, _ = rod_page
    set_model(driver, "glare", "value", "off")
    set_model(driver, "plane", "active", 1)
    try:
        m = re.search(r"range ([\d.]+) cm\npeak: x = (-?[\d.]+) cm, y = (-?[\d.]+) cm",
                      model_value(driver, "peak"))
        assert m, model_value(driver, "peak")
        assert abs(float(m[1]) - 40.0) < 0.005 + 1e-9
        quarter = 100 * hr.C0 / h.frequency / 4
        assert np.hypot(float(m[2]) + 20.0, float(m[3])) < quarter
        assert not _console_errors(driver)
    finally:
        set_model(driver, "plane", "active", 0)


def test_linear_scale_and_switching_the_ground_off(rod, rod_page):
    _, h, sand = rod
    driver, _, _ = rod_page
    set_model(driver, "depth", "value", 10.0)
    set_model(driver, "scale", "active", 1)  # linear: |E| / the sweep's peak
    try:
        _, api_db = _api_plane(h, sand, 0.10)
        lin = np.asarray(driver.execute_script(
            "return Array.from(Bokeh.documents[0].get_model_by_name('image_source')"
            ".data.lin[0])")).reshape(api_db.shape)
        # float32 carries 24 bits: 1e-7 of a ratio <= 1
        np.testing.assert_allclose(lin, 10 ** (api_db / 20), rtol=0, atol=1e-6)
    finally:
        set_model(driver, "scale", "active", 0)
    # Without a ground the slider reads range: the same plane stays in view (0.40 m),
    # now imaged through air.
    set_model(driver, "ground", "value", "air (no ground)")
    try:
        assert model_value(driver, "depth", "value") == pytest.approx(40.0)
        air = hr.migrate(h, 0.40, upsample=4, fov="full")
        sweep = hr.migrate(h, np.linspace(0.30, 0.55, 61), upsample=4, fov="full")
        assert_db_close(shown_db(driver), _db(air, np.abs(sweep.data).max()))
    finally:
        set_model(driver, "ground", "value", "half-space")
    assert model_value(driver, "depth", "value") == pytest.approx(10.0)
    assert not _console_errors(driver)


def test_exports_reproduce_the_look_in_batch(rod, rod_page, tmp_path):
    driver, _, out = rod_page
    set_model(driver, "depth", "value", 10.0)

    def shown() -> set[Path]:  # what a user sees: a file appears whole, under its name
        return {p for p in out.iterdir() if not p.name.startswith(".")}

    before = shown()
    for what in ("png", "netcdf", "settings"):
        click_button(driver, f"export_{what}")
    t0 = time.monotonic()
    while (len(shown() - before) < 3 or model_value(driver, "exported").count("wrote") < 1
           or any(p.name.startswith(".") for p in out.iterdir())) \
            and time.monotonic() - t0 < 30:
        time.sleep(0.05)
    new = sorted(shown() - before)
    assert sorted(p.suffix for p in new) == [".nc", ".png", ".toml"]
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary left
    toml = next(p for p in new if p.suffix == ".toml")
    image = hr.load(next(p for p in new if p.suffix == ".nc"))
    from click.testing import CliRunner

    from holoradar.app.cli import main

    res = CliRunner().invoke(main, ["render", str(toml), "-o", str(tmp_path / "again.nc")])
    assert res.exit_code == 0, res.output
    again = hr.load(tmp_path / "again.nc")
    np.testing.assert_array_equal(again.data, image.data)


def test_latency_of_the_slider_is_measured(rod_page):
    # Only that the measurement works (a number per move); its speed is the benchmark's.
    driver, _, _ = rod_page
    ms = measure_slider(driver, [6.0, 6.5])
    assert ms.shape == (2, 3) and np.all(ms > 0) and np.all(np.diff(ms, axis=1) >= 0)


@pytest.fixture(scope="module")
def sphere_files(tmp_path_factory):
    """SMUTHI's five views of the sphere, each with its plane wave (phase 0 at the
    aperture's centre: the fixture's phase reference is the sand surface, 0.30 m below)."""
    d = tmp_path_factory.mktemp("sphere")
    paths, views = [], []
    for inc in ("+00", "+20", "-20", "+40", "-40"):
        with np.load(DATA / f"S2_buried_sphere_metal_inc{inc}.npz") as z:
            f = float(z["f_hz"][0])
            th = np.radians(float(inc))
            ref = np.exp(1j * 2 * np.pi * f / hr.C0 * np.cos(th) * 0.30)
            h = hr.Hologram(z["E_scat"][1] * ref, z["x_m"], z["y_m"], f,
                            source=hr.PlaneWave(th, 0.0))
            eps = complex(z["sand_eps"][0])
        views.append(h)
        paths.append(hr.save(h, d / f"sphere{inc}.nc"))
    return paths, views, hr.Medium.half_space(0.30, eps), eps


def test_views_and_synthesis_mode_match_synthesize(sphere_files, browser, tmp_path):
    paths, views, sand, eps = sphere_files
    # A look saved as the page's settings export writes it: 2x upsampling and 21 planes
    # keep the five 64 x 64 views quick; the sand as a ground table.
    look = paths[0].parent / "look.toml"
    look.write_text(
        f'files = [{", ".join(repr(p.name) for p in paths)}]\n'
        "[image]\ndepth = 0.09\nupsample = 2\nplanes = 21\nsweep = [0.0, 0.2]\n"
        f'[ground]\nsurface = 0.30\neps = "{eps.real}{eps.imag:+}j"\n', encoding="utf-8")
    with _page(browser, ["--settings", look]):
        for use, mode in (([0, 1, 2, 3, 4], "coherent"), ([0, 3, 4], "coherent"),
                          ([0, 3, 4], "amplitude")):
            set_model(browser, "views", "active", use)
            set_model(browser, "mode", "value", mode)
            x, y, d, _ = _peak(browser)
            chosen = [views[i] for i in use]
            img = hr.synthesize(chosen, 0.39, medium=sand, mode=mode, upsample=2, fov="full")
            sweep = hr.synthesize(chosen, 0.30 + np.linspace(0.0, 0.2, 21), medium=sand,
                                  mode=mode, upsample=2, fov="full")
            ax, ay, az = peak_position(img)
            assert abs(x - ax) < CM_TOL / 100 and abs(y - ay) < CM_TOL / 100, (use, mode)
            assert abs(d - (az - 0.30)) < CM_TOL / 100
            assert_db_close(shown_db(browser), _db(img, np.abs(sweep.data).max()),
                            f"{use} {mode}")
        _shot(browser, tmp_path, "viewer_sphere_views.png")
        assert not _console_errors(browser)


def test_an_image_volume_shows_its_own_planes(rod, browser, tmp_path):
    # An image file: no imaging in the page, its planes and its colour scale (dB re the
    # volume's brightest voxel).
    _, h, sand = rod
    vol = hr.migrate(h, np.linspace(0.35, 0.45, 11), medium=sand, upsample=2)
    path = hr.save(vol, tmp_path / "rod_volume.nc")
    with _page(browser, [path]):
        set_model(browser, "depth", "value", 40.0)  # range from the array, cm
        plane = vol.plane(0.40)
        assert_db_close(shown_db(browser), _db(plane, np.abs(vol.data).max()))
        m = re.search(r"peak: x = (-?[\d.]+) cm, y = (-?[\d.]+) cm,\s+range = (-?[\d.]+) cm",
                      model_value(browser, "peak"))
        ax, ay, az = peak_position(plane)
        assert m and abs(float(m[1]) / 100 - ax) < CM_TOL / 100
        assert abs(float(m[2]) / 100 - ay) < CM_TOL / 100
        assert abs(float(m[3]) / 100 - az) < CM_TOL / 100
        assert not _console_errors(browser)


_BOXES_JS = """
const out = {};
for (const v of Bokeh.index.all_views()) {
  if (['plan', 'xz', 'yz', 'depth', 'glare', 'layout'].includes(v.model.name)) {
    const r = v.el.getBoundingClientRect();
    out[v.model.name] = [r.left, r.top, r.right, r.bottom];
  }
}
return out;
"""


def test_page_fits_a_1000_by_800_window_and_says_it_is_loading(rod_page, tmp_path):
    # At 1000 x 800 the controls, the plan view and both sections stand side by side,
    # none cut off; before the document arrives the page says it is loading, so a plain
    # headless screenshot (taken at the page's load) is not blank. The module's viewer
    # and browser, a new page of it at that viewport.
    import subprocess

    from matplotlib.image import imread

    driver, server, _ = rod_page
    try:
        driver.get("about:blank")   # the old page's closed websocket is not this one's error
        driver.get_log("browser")
        # The viewport itself 1000 x 800 (a window's size includes the browser's frame).
        driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
            "width": 1000, "height": 800, "deviceScaleFactor": 1, "mobile": False})
        driver.get(server.url)
        wait_idle(driver)
        scroll_w, inner_w = driver.execute_script(
            "return [document.documentElement.scrollWidth, window.innerWidth]")
        assert inner_w == 1000 and scroll_w <= inner_w  # nothing beyond the right edge
        boxes = driver.execute_script(_BOXES_JS)
        for name in ("plan", "xz", "yz", "depth", "glare"):
            left, _, right, bottom = boxes[name]
            assert left >= 0 and right <= 1000 and bottom <= 800, (name, boxes[name])
        assert boxes["plan"][2] <= boxes["xz"][0]  # the sections beside the plan view
        assert not driver.execute_script(
            "return document.getElementById('holoradar-loading') !== null")
        _shot(driver, tmp_path, "viewer_1000x800.png")
        assert not _console_errors(driver)
        chrome, _, _ = find_chromium()
        plain = tmp_path / "plain.png"
        subprocess.run([chrome, "--headless", "--no-sandbox", "--disable-gpu",
                        "--hide-scrollbars", "--window-size=1000,800",
                        f"--screenshot={plain}", server.url],
                       capture_output=True, timeout=120)
        pixels = imread(plain)[..., :3]
        assert (pixels.min(axis=-1) < 0.5).sum() > 200, "a blank page"
    finally:
        driver.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})
        driver.get("about:blank")
        driver.get_log("browser")


_ROWS_JS = """
const doc = Bokeh.documents[0];
const m = doc.get_model_by_name('objects');
const v = [...Bokeh.index.all_views()].find(v => v.model === m);
const root = v.shadow_el || v.el;
return [m.source.data.n.length, root.querySelectorAll('.slick-row').length];
"""


def _wait_objects(driver, timeout: float = 300.0) -> str:
    """The objects' note once no search is running."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        note = model_value(driver, "objects_note")
        if "..." not in note:
            return note
        time.sleep(0.1)
    raise TimeoutError("the page did not finish finding the objects")


@pytest.mark.slow
def test_objects_of_a_file_are_overlaid_and_listed(rod, browser, tmp_path):
    # A table as `holoradar detect -o objects.csv` writes it (three objects about the rod,
    # one of each kind): the page lists three rows and its glyphs carry them. (Slow: a
    # server of its own, 12-20 s; the glyphs' and the list's data are tested without a
    # browser in test_viewer.py.)
    import pandas as pd

    from holoradar.analysis.detect.table import COLUMNS
    from holoradar.io.detections import write as _write

    path, _, _ = rod
    nan = float("nan")
    rows = [{"kind": "point", "x": -0.005, "y": 0.03, "range": 0.40, "depth": 0.10,
             "snr_db": 14.3},
            {"kind": "line", "x": -0.005, "y": 0.0, "range": 0.40, "depth": 0.10,
             "length": 0.12, "width": 0.01, "x_start": -0.005, "y_start": -0.06,
             "x_end": -0.005, "y_end": 0.06, "snr_db": 15.2},
            {"kind": "area", "x": -0.16, "y": 0.0, "range": 0.42, "depth": 0.12,
             "length": 0.05, "width": 0.03, "azimuth_deg": 90.0, "snr_db": 11.4}]
    df = pd.DataFrame([{c: r.get(c, nan) for c in COLUMNS} for r in rows], columns=COLUMNS)
    table = tmp_path / "objects.csv"
    _write(table, df, {}, "scene")
    with _page(browser, [path, "--eps", "2.5", "--sigma", str(SIGMA), "--z-surface", "0.30",
                         "--depth", "0.10", "--glare", "off", "--objects", table]):
        n_data, n_shown = browser.execute_script(_ROWS_JS)
        assert (n_data, n_shown) == (3, 3)
        pts = browser.execute_script(
            "return Bokeh.documents[0].get_model_by_name('objects_points').data.x")
        assert pts == pytest.approx([-0.5])
        lines = browser.execute_script(
            "const d = Bokeh.documents[0].get_model_by_name('objects_lines').data;"
            "return [d.y0, d.y1];")
        assert lines == [pytest.approx([-6.0]), pytest.approx([6.0])]
        _shot(browser, tmp_path, "viewer_detections_file.png")
        assert not _console_errors(browser)


@pytest.mark.slow
def test_find_objects_lists_what_detect_finds(rod, browser, tmp_path):
    # --detect: holoradar.detect on the plane shown (the rod 10 cm deep, its glare
    # removed by the image-source method); the page lists exactly the API's objects.
    path, h, sand = rod
    with _page(browser, [path, "--eps", "2.5", "--sigma", str(SIGMA), "--z-surface", "0.30",
                         "--depth", "0.10", "--glare", "image_source", "--detect"]):
        note = _wait_objects(browser)
        cleaned, _ = hr.suppress_surface(h, sand, h.source, "image_source")
        img = hr.migrate(cleaned, 0.40, medium=sand, upsample=4, fov="full")
        api = hr.detect(img, medium=sand)
        assert f"{len(api)} object(s) in the plane at depth 10.0 cm" in note
        n_data, n_shown = browser.execute_script(_ROWS_JS)
        assert n_data == len(api) and n_shown == min(len(api), 5) and len(api) > 0
        xs = browser.execute_script(
            "return Bokeh.documents[0].get_model_by_name('objects_labels').data.x")
        np.testing.assert_allclose(xs, api["x"] * 100, rtol=0, atol=1e-9)
        _shot(browser, tmp_path, "viewer_detections.png")
        assert not _console_errors(browser)
