"""The report in headless Chromium: it loads with no console error, every picture is
decoded, and the objects' table the browser shows is ``hr.detect``'s.

The DOM is read in the browser (``document.querySelectorAll``), not by parsing the
file in Python: what is checked is what a reader sees.

Screenshots go to ``tmp_path``; with ``HOLORADAR_SCREENSHOTS=DIR`` also to DIR, for the
documentation (``docs/figures/report_page.png`` comes from the slow demo below).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import holoradar as hr
from holoradar.app.view.browser import find_chromium, headless_chromium

_, _, WHY = find_chromium()
pytestmark = [pytest.mark.browser,
              pytest.mark.skipif(bool(WHY), reason=f"no browser for the report tests: {WHY}")]

SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
# What the table shows of hr.detect's columns (metres, m^2, degrees, dB): the factor to
# the unit shown (cm, cm^2, degrees, dB) and the digits shown.
SHOWN = {"x": (100.0, 1), "y": (100.0, 1), "range": (100.0, 1), "depth": (100.0, 1),
         "depth_low": (100.0, 1), "depth_high": (100.0, 1), "length": (100.0, 1),
         "width": (100.0, 1), "azimuth_deg": (1.0, 0), "area": (1e4, 0),
         "amplitude_db": (1.0, 1), "snr_db": (1.0, 1)}

_ROWS_JS = """
return [...document.querySelectorAll('table.objects')].map(t =>
  [...t.tBodies[0].rows].map(tr => Object.fromEntries(
    [...tr.cells].map(td => [td.dataset.col, [td.dataset.value || '', td.textContent]]))));
"""
_IMAGES_JS = """
return [...document.images].map(i => [i.complete, i.naturalWidth, i.naturalHeight]);
"""


@pytest.fixture(scope="module")
def browser():
    driver = headless_chromium(1280, 2000)
    yield driver
    driver.quit()


def _open(driver, path: Path) -> list[dict]:
    """Open the file; the console's messages of that load."""
    driver.get(path.resolve().as_uri())
    driver.execute_script("return document.readyState")
    return driver.get_log("browser")


def _shot(driver, tmp_path: Path, name: str) -> Path:
    p = tmp_path / name
    assert driver.save_screenshot(str(p)), "the browser took no screenshot"
    assert p.stat().st_size > 10_000  # a page, not a blank
    gallery = os.environ.get("HOLORADAR_SCREENSHOTS")
    if gallery:
        shutil.copyfile(p, Path(gallery) / name)
    return p


def _same_table(rows: list[dict], df) -> None:
    """The browser's rows against hr.detect's table: numbered from 1 in its order, each
    value exactly (the cell's data-value is the float's repr) and as shown (the value
    in the column's unit with the digits shown)."""
    from test_report import assert_table_is_detects

    assert_table_is_detects(rows, df)


def test_report_in_the_browser(browser, tmp_path):
    # Two points 12 cm deep in sand (16 x 16 array at 1.25 cm), the plane image as a file.
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((-0.04, 0.03, 0.42), 1.0),
                                            hr.PointTarget((0.05, -0.04, 0.42), 0.3)])
    h = hr.simulate(scene, hr.Aperture.grid(16, 0.0125), 9.9e9, include_surface=False,
                    snr_db=40, seed=3)
    img = hr.save(hr.migrate(h, 0.42, medium=SAND, upsample=4), tmp_path / "img.nc")
    out = tmp_path / "report.html"
    # hr.report's own detection is hr.detect's (tests/test_report.py); here the table
    # is given, to check what the browser shows of it without detecting twice.
    ref = hr.detect(hr.load(img), medium=SAND, eps_interval=(2.2, 2.8))
    hr.report(img, out, medium=SAND, eps_interval=(2.2, 2.8), detections=ref)
    log = _open(browser, out)
    assert [e for e in log if e["level"] == "SEVERE"] == []
    # nothing fetched from anywhere: no resource but the page itself and its data: URIs
    fetched = browser.execute_script(
        "return performance.getEntriesByType('resource').map(e => e.name);")
    assert [u for u in fetched if not u.startswith(("data:", "file:"))] == []
    images = browser.execute_script(_IMAGES_JS)
    assert images and all(ok and w > 100 and h > 100 for ok, w, h in images), images
    (rows,) = browser.execute_script(_ROWS_JS)
    assert len(ref) >= 2
    _same_table(rows, ref)
    _shot(browser, tmp_path, "report_small.png")


@pytest.mark.slow
def test_demo_report_screenshot(browser, tmp_path):
    # The documentation's picture: concrete (eps 6 + 0.3i) 30 cm below a 32 x 32 array at
    # 1.25 cm recording E_y: a 12 mm bar along y and a metal plate 8 x 6 cm at 6 cm and
    # 10 cm, two small scatterers, 30 dB; the image's plane at 6 cm, searched alone.
    concrete = hr.Medium.half_space(0.30, 6 + 0.3j)
    plate = hr.PlanarTarget.from_shape("rectangle", 0.40, center=(0.07, -0.08), reflection=-1,
                                       width=0.08, height=0.06)
    targets = [hr.LineTarget((-0.09, -0.13, 0.36), (-0.09, 0.13, 0.36), 0.006),
               hr.PointTarget((0.07, 0.09, 0.35), 0.05), hr.PointTarget((0.0, 0.02, 0.38), 0.03),
               plate]
    h = hr.simulate(hr.Scene(concrete, hr.PlaneWave(polarization=(0, 1, 0)), targets),
                    hr.Aperture.grid(32, 0.0125, polarization=(0, 1, 0)), 9.9e9,
                    include_surface=False, snr_db=30, seed=1)
    hr.save(h, tmp_path / "slab.nc", history=[{"step": "simulate", "parameters": {
        "scene": "a bar, a plate and two scatterers in concrete"}}])
    step = {"step": "migrate", "input": "slab.nc", "parameters": {
        "z": "0.36", "method": "angular", "upsample": 4,
        "medium": {"z_interfaces": [0.3], "eps": ["(1+0j)", "(6+0.3j)"]}}}
    img = hr.save(hr.migrate(h, 0.36, medium=concrete, upsample=4), tmp_path / "slab_img.nc",
                  history=[*hr.io.read_history(tmp_path / "slab.nc"), step])
    out = tmp_path / "slab_report.html"
    hr.report(img, out, eps_interval=(5.5, 6.5), title="Inspection report: concrete slab")
    ref = hr.detect(hr.load(img), medium=concrete, eps_interval=(5.5, 6.5))
    assert {"line", "area", "point"} <= set(ref.kind)
    assert [e for e in _open(browser, out) if e["level"] == "SEVERE"] == []
    (rows,) = browser.execute_script(_ROWS_JS)
    _same_table(rows, ref)
    _shot(browser, tmp_path, "report_page.png")
    # the lower half: the ground, the detection, the device, the history, the warnings
    browser.execute_script("[...document.querySelectorAll('h3')].find(h => h.textContent === "
                           "'Ground').scrollIntoView();")
    _shot(browser, tmp_path, "report_details.png")
    assert np.isfinite(ref.depth).all()
