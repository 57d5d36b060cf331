"""``holoradar report``: the table is ``holoradar detect``'s for the same file and options;
several files are one report; outputs are never replaced unasked nor over an input; bad
options are one line naming the option, nothing written."""

from __future__ import annotations

import json

import pytest

import holoradar as hr
from cli_helpers import one_line_error, run

SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
GROUND = ["--eps", "2.5+0.0125j", "--z-surface", "0.3"]


@pytest.fixture(scope="module")
def image(tmp_path_factory):
    """One point 12 cm deep in sand under a 16 x 16 array at 1.25 cm, imaged on its plane
    (no history: the ground comes from the flags); its hologram beside it, holo.nc."""
    d = tmp_path_factory.mktemp("report_cli")
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((0.01, -0.01, 0.42))])
    h = hr.simulate(scene, hr.Aperture.grid(16, 0.0125), 9.9e9, include_surface=False,
                    snr_db=40, seed=2)
    hr.save(h, d / "holo.nc")
    return hr.save(hr.migrate(h, 0.42, medium=SAND, upsample=4), d / "img.nc")


def _html_files(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.endswith((".html", ".tmp")))


def test_two_files_one_report_numbered_as_detect(image, tmp_path):
    # The same file twice under two names: two sections, each numbered from 1 as
    # holoradar detect numbers it, with detect's values.
    other = tmp_path / "again.nc"
    other.write_bytes(image.read_bytes())
    out = tmp_path / "r.html"
    res = run("report", image, other, *GROUND, "--eps-interval", "2.2,2.8", "-o", out,
              "--json")
    doc = json.loads(res.stdout)
    det = json.loads(run("detect", image, *GROUND, "--eps-interval", "2.2,2.8",
                         "--json").stdout)["objects"]
    assert [s["name"] for s in doc["sources"]] == ["img.nc", "again.nc"]
    assert [s["n_objects"] for s in doc["sources"]] == [len(det)] * 2
    assert doc["out"] == str(out) and doc["bytes"] == out.stat().st_size
    text = out.read_text()
    assert text.count('<table class="objects"') == 2
    for k in (1, 2):
        for n, obj in enumerate(det, 1):
            assert f'<tr id="s{k}-object-{n}">' in text
            assert f'<td data-col="x" data-value="{obj["x"]!r}">' in text
    assert "given as --eps/--z-surface" in text and "2.2 to 2.8, given as --eps-interval" in text


def test_existing_output_kept_without_force(image, tmp_path):
    out = tmp_path / "r.html"
    out.write_text("precious")
    one_line_error(run("report", image, *GROUND, "-o", out, ok=False), "--out", "--force")
    assert out.read_text() == "precious"
    run("report", image, *GROUND, "-o", out, "--force", "-q")
    assert out.read_text().startswith("<!DOCTYPE html>")


def test_output_that_is_an_input_refused(tmp_path):
    scan = tmp_path / "scan.html"
    scan.write_text("data")
    one_line_error(run("report", scan, "-o", scan, "--force", ok=False), "--out",
                   "one of the inputs")
    assert scan.read_text() == "data"


def test_missing_file_refused(tmp_path):
    res = run("report", tmp_path / "gone.nc", "-o", tmp_path / "r.html", ok=False)
    one_line_error(res, "gone.nc", "does not exist")
    assert _html_files(tmp_path) == []


@pytest.mark.parametrize(("args", "needles"), [
    (["--eps-interval", "2.5"], ["--eps-interval", "LO,HI"]),
    (["--eps-interval", "2.8,2.2"], ["--eps-interval", "LO <= HI"]),
    (["--eps-interval", "0.5,2"], ["--eps-interval", ">= 1"]),
    (["--false-alarm", "0.5"], ["--false-alarm", "(0, 0.1]"]),
    (["--kinds", "point,blob"], ["--kinds", "point, line, area"]),
    (["--eps", "2.5"], ["--eps/--z-surface"]),
    (["--z", "0.3:0.5:0.01", *GROUND], ["--z", "one range"]),
    (["--z", "0.9", *GROUND], ["--z", "outside"]),
    (["--hologram", "IMG", *GROUND], ["--hologram", "image, not a hologram"]),
])
def test_bad_options_named_nothing_written(image, tmp_path, args, needles):
    args = [str(image) if a == "IMG" else a for a in args]
    one_line_error(run("report", image, *args, "-o", tmp_path / "r.html", ok=False), *needles)
    assert _html_files(tmp_path) == []


def test_output_suffix_and_eps_interval_without_ground(image, tmp_path):
    one_line_error(run("report", image, "-o", tmp_path / "r.pdf", ok=False), "--out", ".html")
    one_line_error(run("report", image, "--eps-interval", "2,3", "-o", tmp_path / "r.html",
                       ok=False), "--eps-interval", "ground")
    assert _html_files(tmp_path) == []


def test_hologram_planes_checked_against_the_array(image, tmp_path):
    # A hologram FILE is imaged on --z: centimetres typed for metres are refused as
    # holoradar image and detect refuse them, with the metres meant.
    res = run("report", image.parent / "holo.nc", "--z", "42", *GROUND, "-o",
              tmp_path / "r.html", ok=False)
    one_line_error(res, "--z", "centimetres given for metres", "--z 0.42")
    assert _html_files(tmp_path) == []
