"""The report's rebar part, as concrete scanners give it: layers with count, spacing and
cover, the cover against a specified minimum, a plan by cover; the inspection's fields;
and the report's details (blank where undefined, no -0.0, one azimuth per axis)."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pandas as pd
import pytest

import holoradar as hr
from cli_helpers import one_line_error, run
from holoradar.analysis.detect.table import COLUMNS

SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)


def _bar(x0, y0, x1, y1, depth, half=0.003):
    r = {c: np.nan for c in COLUMNS}
    az = np.degrees(np.arctan2(y1 - y0, x1 - x0)) % 180.0
    r.update(kind="line", x=(x0 + x1) / 2, y=(y0 + y1) / 2, range=0.3 + depth, depth=depth,
             depth_low=depth - half, depth_high=depth + half, length=np.hypot(x1 - x0, y1 - y0),
             width=0.012, azimuth_deg=az, x_start=x0, y_start=y0, x_end=x1, y_end=y1,
             amplitude_db=-10.0, snr_db=30.0)
    return r


@pytest.fixture(scope="module")
def mat(tmp_path_factory):
    """A plane image to draw on and a mat's table: three bars along x under 3.0, 4.0
    and 4.2 cm (the first below a 3.5 cm minimum), 15 cm apart; two along y under 6 cm,
    20 cm apart; one azimuth written as 179.99 deg, one position at -0.4 mm (shown 0.0,
    not -0.0)."""
    d = tmp_path_factory.mktemp("rebar")
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((0.0, 0.0, 0.42))])
    h = hr.simulate(scene, hr.Aperture.grid(16, 0.0125), 9.9e9, include_surface=False,
                    snr_db=40, seed=1)
    img = hr.save(hr.migrate(h, 0.42, medium=SAND, upsample=4), d / "img.nc")
    rows = [_bar(-0.2, -0.15, 0.2, -0.15, 0.030), _bar(0.2, -0.0004, -0.2, -0.0004, 0.040),
            _bar(-0.2, 0.15, 0.2, 0.15, 0.042, half=0.004),
            _bar(-0.1, -0.2, -0.1, 0.2, 0.060), _bar(0.1, -0.2, 0.1, 0.2, 0.060)]
    rows[1]["azimuth_deg"] = 179.99
    point = {c: np.nan for c in COLUMNS}
    point.update(kind="point", x=0.05, y=0.05, range=0.42, depth=0.12, depth_low=0.11,
                 depth_high=0.13, length=0.0, width=0.0, amplitude_db=-20.0, snr_db=20.0)
    df = pd.DataFrame([*rows, point], columns=COLUMNS)
    df.attrs["eps_interval"] = [2.2, 2.8]
    return {"dir": d, "img": img, "df": df}


def _text(html: str) -> str:
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", html))


def test_layers_spacing_cover_and_the_minimum_cover(mat, tmp_path):
    out = tmp_path / "r.html"
    hr.report(mat["img"], out, medium=SAND, detections=mat["df"], min_cover="35mm",
              meta={"site": "Bridge 7", "operator": "A. N. Other", "scan": 12})
    html = out.read_text()
    table = html[html.index('<table class="rebar"'):html.index("</table>",
                                                              html.index('table class="rebar"'))]
    rows = [_text(r).split() for r in re.findall(r"<tr[^>]*>(.*?)</tr>", table)[1:]]
    # layer 1: three bars along x, numbers 1-3, spacing 15.0 (mean, min, max), cover
    # 3.0 / 3.7 / 4.2 cm, interval 2.7 to 4.6, one below 3.5 cm, one uncertain.
    assert rows[0] == ["1", "along", "x", "(0", "deg)", "3", "1,", "2,", "3", "15.0", "15.0",
                       "15.0", "3.0", "3.7", "4.2", "2.7", "to", "4.6", "1", "0"]
    assert rows[1][:5] == ["2", "along", "y", "(90", "deg)"]
    assert rows[1][5:] == ["2", "4,", "5", "20.0", "20.0", "20.0", "6.0", "6.0", "6.0", "5.7",
                           "to", "6.3", "0", "0"]
    # The objects' table checks each bar; the bar below is marked.
    objects = html[html.index('<table class="objects"'):html.index('<table class="rebar"')]
    checks = re.findall(r'data-col="cover_check">([^<]*)<', objects)
    assert checks == ["below", "ok", "ok", "ok", "ok", "–"]
    assert objects.count('class="below"') == 1
    # A plan of the bars by cover, and the inspection's fields first.
    assert '<figure class="rebar">' in html
    assert html.index("Bridge 7") < html.index("<h2>")
    assert "<th>operator</th><td>A. N. Other</td>" in html


def test_uncertain_cover_where_the_interval_reaches_below(mat, tmp_path):
    out = tmp_path / "r.html"
    # 3.9 cm: bar 2 (4.0 cm, interval from 3.7) and bar 3 (4.2 cm, from 3.8) lie above
    # it, their intervals reach below it.
    hr.report(mat["img"], out, medium=SAND, detections=mat["df"], min_cover=0.039)
    checks = re.findall(r'data-col="cover_check">([^<]*)<', out.read_text())
    assert checks == ["below", "uncertain", "uncertain", "ok", "ok", "–"]


def test_details_blank_zero_and_azimuth(mat, tmp_path):
    out = tmp_path / "r.html"
    hr.report(mat["img"], out, medium=SAND, detections=mat["df"])
    html = out.read_text()
    assert ">-0.0<" not in html and ">180<" not in html
    point = re.search(r'<tr id="s1-object-6">(.*?)</tr>', html).group(1)
    assert re.search(r'data-col="length" data-value="0.0">–<', point)
    assert re.search(r'data-col="width" data-value="0.0">–<', point)
    # The table was found with an eps interval: the report says so, not "none given".
    assert "2.2 to 2.8, the one the objects&#x27; table was found with" in html


def test_an_image_read_back_keeps_its_history(mat, tmp_path):
    out = tmp_path / "r.html"
    hr.report(hr.load(mat["img"]), out, medium=SAND, detections=mat["df"])
    html = out.read_text()
    assert "No processing history" not in html and "<b>save</b>" in html


def test_a_loaded_image_gives_its_ground_from_the_history_it_carries(mat, tmp_path):
    # No medium given: the image holoradar image made through the sand, read back into
    # memory, says so in its history; the table's eps interval then widens the depths.
    x = (np.arange(16) - 7.5) * 0.0125
    holo = hr.save(hr.Hologram(np.ones((16, 16), complex), x, x, 9.9e9), tmp_path / "h.nc")
    run("image", holo, "--z", "0.42", "--eps", "2.5+0.0125j", "--z-surface", "0.30",
        "-o", tmp_path / "i.nc", "--no-png", "-q", "--no-check")
    out = tmp_path / "r.html"
    hr.report(hr.load(tmp_path / "i.nc"), out, detections=mat["df"])
    html = out.read_text()
    assert "the image&#x27;s history: the ground it was imaged through" in html
    assert "2.2 to 2.8, the one the objects&#x27; table was found with" in html


def test_the_images_warnings_travel_in_its_history(tmp_path):
    # holoradar image warns of the 2.5 cm pitch (aliased at 9.9 GHz); the report of the
    # image file lists that warning, from the file's history.
    x = (np.arange(8) - 3.5) * 0.025
    holo = hr.save(hr.Hologram(np.ones((8, 8), complex), x, x, 9.9e9), tmp_path / "h.nc")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run("image", holo, "--z", "0.4", "-o", tmp_path / "i.nc", "--no-png", "-q",
            "--no-check")
    out = tmp_path / "r.html"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = hr.report(tmp_path / "i.nc", out)
    assert any(t.startswith("AliasingWarning") and "when migrate made it" in t
               for t in s["sources"][0]["warnings"])
    assert "Warnings</h3><p class=\"none\">None." not in out.read_text()


def test_command_line_rebar_options_and_bad_input(mat, tmp_path):
    meta = tmp_path / "meta.toml"
    meta.write_text('site = "Bridge 7"\nelement = "deck S3"\n', encoding="utf-8")
    table = tmp_path / "t.csv"
    out = tmp_path / "r.html"
    # bad --min-cover, bad --meta: named, nothing written
    one_line_error(run("report", mat["img"], "-o", out, "--min-cover", "deep", ok=False),
                   "--min-cover", "35mm")
    one_line_error(run("report", mat["img"], "-o", out, "--min-cover", "35", ok=False),
                   "--min-cover", "at most 1 m")
    bad = tmp_path / "bad.toml"
    bad.write_text("[site]\nname = 1\n", encoding="utf-8")
    one_line_error(run("report", mat["img"], "-o", out, "--meta", bad, ok=False), "--meta")
    assert not out.exists() and not table.exists()
    run("report", mat["img"], "-o", out, "--min-cover", "3.5cm", "--meta", meta,
        "--operator", "A. N. Other", "-q")
    html = out.read_text()
    assert "<th>site</th><td>Bridge 7</td>" in html
    assert "<th>operator</th><td>A. N. Other</td>" in html
    assert "cover ≥ 3.5 cm?" in html
