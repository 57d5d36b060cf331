"""``hr.report``: one self-contained HTML file whose table is ``hr.detect``'s, numbered as
``holoradar detect`` numbers it, with the ground, device, history and warnings of each
source; bad arguments are refused by name with nothing written."""

from __future__ import annotations

import html.parser
import math
import warnings

import numpy as np
import pandas as pd
import pytest

import holoradar as hr
from holoradar.reporting.table import MISSING

SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
# What the table shows of hr.detect's columns (metres, m^2, degrees, dB): the factor to
# the unit shown (cm, cm^2, degrees, dB) and the digits shown.
SHOWN = {"x": (100.0, 1), "y": (100.0, 1), "range": (100.0, 1), "depth": (100.0, 1),
         "depth_low": (100.0, 1), "depth_high": (100.0, 1), "length": (100.0, 1),
         "width": (100.0, 1), "azimuth_deg": (1.0, 0), "area": (1e4, 0),
         "amplitude_db": (1.0, 1), "snr_db": (1.0, 1)}


class _Page(html.parser.HTMLParser):
    """What the tests read of a report: every tag's attributes, the objects' tables."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str]]] = []
        self.tables: list[list[dict[str, tuple[str, str]]]] = []
        self._cell: tuple[str, str] | None = None
        self._text: list[str] = []
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = {k: v or "" for k, v in attrs}
        self.tags.append((tag, a))
        if tag == "table" and a.get("class") == "objects":
            self.tables.append([])
        elif tag == "tr" and self.tables and "id" in a:
            self.tables[-1].append({})
        elif tag == "td" and self.tables and self.tables[-1] and "data-col" in a:
            self._cell = (a["data-col"], a.get("data-value", ""))
            self._text = []

    def handle_data(self, data):
        if self._cell is not None:
            self._text.append(data)

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            col, value = self._cell
            self.tables[-1][-1][col] = (value, "".join(self._text))
            self._cell = None


def assert_table_is_detects(rows: list[dict[str, tuple[str, str]]], df: pd.DataFrame) -> None:
    """The report's rows against ``hr.detect``'s table: the same objects in the same order
    (numbered from 1), each value exactly (``data-value`` is the float's repr) and as
    shown (the value in the column's unit, rounded to the digits shown: equal to the
    text, so within half the last digit)."""
    assert len(rows) == len(df)
    for n, (row, rec) in enumerate(zip(rows, df.to_dict("records"), strict=True), 1):
        assert row["number"][1] == str(n) and row["kind"][1] == rec["kind"]
        for col, (factor, digits) in SHOWN.items():
            value, shown = row[col]
            want = float(rec[col])
            if math.isnan(want):
                assert value == "nan" and shown == MISSING
            elif rec["kind"] == "point" and col in ("length", "width"):
                # not defined for a point: blank, as the footnote says, the value kept
                assert float(value) == want and shown == MISSING
            else:
                assert float(value) == want            # repr reads back to the same double
                w = round(want * factor, digits) + 0.0  # never "-0.0"
                if col == "azimuth_deg":
                    w = w % 180.0                       # an axis: 180 deg is 0 deg
                assert shown == f"{w:.{digits}f}"


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """Two points 12 cm deep in sand under a 16 x 16 array at 1.25 cm, imaged on their
    plane into a file whose history records the ground (as ``holoradar image`` does), and
    its report with the ground from that history and an eps interval."""
    d = tmp_path_factory.mktemp("report")
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((-0.04, 0.03, 0.42), 1.0),
                                            hr.PointTarget((0.05, -0.04, 0.42), 0.3)])
    h = hr.simulate(scene, hr.Aperture.grid(16, 0.0125), 9.9e9, include_surface=False,
                    snr_db=40, seed=3)
    step = {"step": "migrate", "input": "holo.nc", "parameters": {
        "z": "0.42", "method": "angular", "upsample": 4,
        "medium": {"z_interfaces": [0.3], "eps": ["(1+0j)", "(2.5+0.0125j)"]}}}
    img = hr.save(hr.migrate(h, 0.42, medium=SAND, upsample=4), d / "img.nc", history=[step])
    out = d / "report.html"
    summary = hr.report(img, out, eps_interval=(2.2, 2.8))
    ref = hr.detect(hr.load(img), medium=SAND, eps_interval=(2.2, 2.8))
    return {"dir": d, "img": img, "out": out, "summary": summary, "ref": ref, "h": h,
            "text": out.read_text(encoding="utf-8")}


def test_table_is_detects(made):
    page = _Page(made["text"])
    assert len(page.tables) == 1
    assert len(made["ref"]) >= 2       # the two points (and what else detect finds)
    assert_table_is_detects(page.tables[0], made["ref"])
    for head in ("x (cm)", "depth 95 % low (cm)", "azimuth (deg)", "area (cm²)",
                 "amplitude (dB)", "SNR (dB)"):
        assert f"<th>{head}</th>" in made["text"]
    assert made["summary"]["n_objects"] == len(made["ref"])


def test_self_contained(made):
    # No address outside the file: pictures are data: URIs, links are fragments, and
    # there is no script, style sheet or frame to fetch.
    page = _Page(made["text"])
    for tag, attrs in page.tags:
        assert tag not in ("script", "link", "iframe", "object", "embed"), tag
        for key in ("src", "href"):
            if key in attrs:
                assert attrs[key].startswith(("data:image/png;base64,", "#")), attrs[key]
    assert "http://" not in made["text"] and "https://" not in made["text"]
    assert sum(tag == "img" for tag, _ in page.tags) >= 1


def test_ground_device_history_shown(made):
    text = made["text"]
    assert "the image&#x27;s history: the ground it was imaged through" in text
    # Found on one plane from the image alone: no depth has an interval to widen, and
    # the report says so instead of claiming it widened them.
    assert "2.2 to 2.8, given as eps_interval: no depth here has an interval" in text
    assert "widens the depths" not in text
    assert "2.5 + 0.0125j" in text and "at range 30.0 cm from the array" in text
    assert "<b>migrate</b>" in text and "<b>save</b>" in text      # the file's history
    img = hr.load(made["img"])
    step = (img.x[1] - img.x[0]) * 100                                # 1.25 cm / 4
    assert f"{img.x.size} x {img.y.size} pixels at {step:.3g} x {step:.3g} cm" in text
    assert "plan view at range 42.0 cm, depth 12.0 cm below the surface" in text


def test_detections_given_are_used_as_they_are(made, tmp_path):
    # A table from hr.detect is reported as given (here: its first row only).
    img = hr.load(made["img"])
    one = made["ref"].iloc[:1].copy()
    out = tmp_path / "one.html"
    s = hr.report(img, out, medium=SAND, detections=one)
    assert s["n_objects"] == 1
    assert_table_is_detects(_Page(out.read_text()).tables[0], one)


def test_warnings_are_kept_in_the_report(made, tmp_path):
    # An image volume searched on one plane with an aliased hologram source: the
    # migration's AliasingWarning (2.5 cm pitch > lambda/2 at 9.9 GHz) is issued to the
    # caller and written in the report.
    x = (np.arange(8) - 3.5) * 0.025
    h = hr.Hologram(made["h"].data[::2, ::2], x, x, 9.9e9)
    out = tmp_path / "warned.html"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s = hr.report(h, out, medium=SAND, z=[0.42])
    assert any(issubclass(w.category, hr.AliasingWarning) for w in caught)
    assert any(t.startswith("AliasingWarning: ") for t in s["sources"][0]["warnings"])
    assert '<ul class="warnings"><li>AliasingWarning: ' in out.read_text()


@pytest.mark.parametrize(("kwargs", "needles"), [
    ({"eps_interval": (2.8, 2.2)}, ["eps_interval", "lo <= hi"]),
    ({"eps_interval": 2.5}, ["eps_interval", "(lo, hi)"]),
    ({"false_alarm": 0.5}, ["false_alarm", "(0, 0.1]"]),
    ({"kinds": ("point", "blob")}, ["kinds"]),
    ({"medium": "sand"}, ["medium", "Medium"]),
])
def test_bad_arguments_named_nothing_written(made, tmp_path, kwargs, needles):
    out = tmp_path / "never.html"
    with pytest.raises(ValueError) as err:
        hr.report(made["img"], out, **kwargs)
    for n in needles:
        assert n in str(err.value), str(err.value)
    assert list(tmp_path.iterdir()) == []


def test_bad_sources_and_outputs_refused(made, tmp_path):
    out = tmp_path / "r.html"
    with pytest.raises(ValueError, match="does not exist"):
        hr.report(tmp_path / "missing.nc", out)
    with pytest.raises(ValueError, match=r"must end in \.html"):
        hr.report(made["img"], tmp_path / "r.pdf")
    with pytest.raises(ValueError, match="a volume of 3 planes"):
        hr.report(hr.migrate(made["h"], [0.41, 0.42, 0.43], medium=SAND), out)
    with pytest.raises(ValueError, match="is a hologram: give z"):
        hr.report(made["h"], out)
    with pytest.raises(ValueError, match="eps_interval needs a ground"):
        hr.report(made["h"], out, z=[0.42], eps_interval=(2, 3))
    assert list(tmp_path.iterdir()) == []
    out.write_text("precious")
    with pytest.raises(ValueError, match=r"pass force=True"):   # the argument's name
        hr.report(made["img"], out)
    assert out.read_text() == "precious"
    same = tmp_path / "scan.html"           # an input that is the output
    same.write_text("data")
    with pytest.raises(ValueError, match="one of the inputs"):
        hr.report(same, same, force=True)
    assert same.read_text() == "data"


@pytest.mark.slow
def test_survey_report_is_detects_in_survey_coordinates(tmp_path):
    # Two overlapping frames (16 x 16 at 1.25 cm, 10 cm apart) over one point 12 cm deep
    # at world (0.04, 0.11): the report's table is holoradar detect's for the store (one
    # stored plane from the images alone), in survey coordinates, the object once; the
    # plan view is the survey's mosaic.
    from cli_helpers import run

    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((0.04, 0.11, 0.42))])
    paths = []
    for i, x0 in enumerate((0.0, 0.1)):
        ap = hr.Aperture.grid(16, 0.0125, pose=hr.Pose((x0, 0.1, 0.0)))
        h = hr.simulate(scene, ap, 9.9e9, include_surface=False, snr_db=40, seed=i)
        paths.append(hr.save(h, tmp_path / f"frame{i}.nc"))
    store = tmp_path / "s.zarr"
    hr.survey.run_batch(paths, store, z=[0.42], medium=SAND, upsample=4,
                        scheduler="synchronous")
    out = tmp_path / "survey.html"
    s = hr.report(store, out, z=0.42)
    import json

    det = pd.DataFrame(json.loads(run("detect", store, "--z", "0.42", "--json").stdout)
                       ["objects"]).fillna(np.nan)
    page = _Page(out.read_text())
    assert s["sources"][0]["kind"] == "survey"
    assert_table_is_detects(page.tables[0], det)
    rows = page.tables[0]
    # The report names every frame an object was seen in (detect's "frames", ";"-joined
    # there), not only the frame its numbers came from ("frame").
    assert [r["frame"][1] for r in rows] == [f.replace(";", ", ") for f in det["frames"]]
    cell = hr.theory.lateral_resolution(hr.C0 / 9.9e9, SAND.apparent_distance(0.42), 0.2)
    # the point, once, where it lies in the world (within a quarter cell: detect's own
    # survey test's bound, the window fit's bias well inside it)
    near = det[np.hypot(det.x - 0.04, det.y - 0.11) < cell / 4]
    assert len(near) == 1
    assert "mosaic at 42.0 cm from the arrays (survey coordinates)" in out.read_text()
