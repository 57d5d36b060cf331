"""A survey's objects once each: the frames' rows of one object joined in survey
coordinates (a bar's extent the union of its frames'), the frames it was seen in
listed."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pandas as pd
import pytest

import holoradar as hr
from holoradar.survey.merge import merge

CELL = 0.05


def _line(frame, x0, x1, y=0.0, off=0.05, amp=-10.0):
    return {"kind": "line", "x": (x0 + x1) / 2, "y": y, "x_start": x0, "y_start": y,
            "x_end": x1, "y_end": y, "length": x1 - x0, "width": 0.01, "azimuth_deg": 0.0,
            "amplitude_db": amp, "snr_db": 30.0, "depth": 0.1, "frame": frame, "_off": off,
            "_cell": CELL}


def _point(frame, x, y, off=0.05, amp=-20.0):
    return {"kind": "point", "x": x, "y": y, "x_start": np.nan, "y_start": np.nan,
            "x_end": np.nan, "y_end": np.nan, "length": 0.0, "width": 0.0,
            "azimuth_deg": np.nan, "amplitude_db": amp, "snr_db": 20.0, "depth": 0.1,
            "frame": frame, "_off": off, "_cell": CELL}


def test_a_bar_across_frames_is_one_line_with_its_ends_and_frames():
    rows = [_point("f0", -0.27, 0.0), _line("f1", -0.2, 0.0), _point("f2", 0.0, 0.002),
            _line("f3", -0.01, 0.2, off=0.01), _point("f4", 0.27, 0.0),
            # a second bar 15 cm across, in two frames; a point beside both bars
            _line("f1", -0.2, 0.0, y=0.15), _line("f3", 0.0, 0.2, y=0.15),
            _point("f2", 0.0, 0.075)]
    t = merge(pd.DataFrame(rows))
    lines = t[t.kind == "line"].sort_values("y")
    assert len(lines) == 2 and len(t) == 3
    a = lines.iloc[0]
    # The ends are the extreme ends of the rows joined (the end points' positions).
    assert (a.x_start, a.x_end) == pytest.approx((-0.27, 0.27))
    assert a.length == pytest.approx(0.54) and a.frames == "f0;f1;f2;f3;f4"
    assert a.frame == "f3"                       # kept from the line nearest its centre
    assert lines.spacing.to_numpy() == pytest.approx([0.15, 0.15])
    b = lines.iloc[1]
    assert (b.x_start, b.x_end, b.frames) == (pytest.approx(-0.2), pytest.approx(0.2), "f1;f3")
    assert "_off" not in t and "_cell" not in t


def test_rows_of_one_frame_and_separate_objects_stay_apart():
    # Two points of one frame a cell apart are the frame's own decision; a point two
    # cells beyond a line's end along its axis and three cells across are objects.
    rows = [_point("f0", 0.0, 0.0), _point("f0", 0.03, 0.0), _line("f1", 0.2, 0.4),
            _point("f2", 0.2, 0.16)]
    t = merge(pd.DataFrame(rows))
    assert len(t) == 4 and all(";" not in f for f in t.frames)


def test_parallel_bars_a_cell_apart_across_are_not_joined():
    t = merge(pd.DataFrame([_line("f0", -0.2, 0.0, y=0.0), _line("f1", 0.0, 0.2, y=0.06)]))
    assert len(t) == 2


@pytest.mark.slow
def test_pipe_across_seven_frames_is_one_line_in_survey_coordinates(tmp_path):
    # A 60 cm pipe (2 cm across, 12 cm deep in sand, along x at y = 0.1 m) under seven
    # 20 cm frames 10 cm apart, 8-12 GHz at 11 frequencies: holoradar detect on the
    # store finds one line, across within a quarter cell, each end within a cell of the
    # pipe's (a frame holding its end sees the end's tip, a few centimetres inside),
    # seen in all seven frames.
    from cli_helpers import run

    warnings.filterwarnings("ignore", category=hr.AliasingWarning)
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    pol = (1, 0, 0)
    scene = hr.Scene(sand, hr.PlaneWave(polarization=pol),
                     [hr.LineTarget((-0.3, 0.1, 0.43), (0.3, 0.1, 0.43), 0.01)])
    paths = []
    for i, x0 in enumerate(np.arange(-0.3, 0.31, 0.1)):
        ap = hr.Aperture.grid(16, 0.0125, pose=hr.Pose((x0, 0.1, 0.0)), polarization=pol)
        h = hr.simulate(scene, ap, np.linspace(8e9, 12e9, 11), include_surface=False,
                        snr_db=30, seed=i)
        paths.append(hr.save(h, tmp_path / f"f{i}.nc"))
    hr.survey.run_batch(paths, tmp_path / "s.zarr", z=list(np.arange(0.36, 0.50, 0.01)),
                        medium=sand, upsample=4, scheduler="synchronous")
    out = tmp_path / "o.json"
    run("detect", tmp_path / "s.zarr", "-o", out, "-q")
    objs = json.loads(out.read_text())["objects"]
    assert [o["kind"] for o in objs] == ["line"], objs
    o = objs[0]
    cell = hr.theory.lateral_resolution(hr.C0 / 10e9, sand.apparent_distance(0.43), 0.2)
    assert abs(o["y"] - 0.1) < cell / 4
    assert sorted([o["x_start"], o["x_end"]]) == pytest.approx([-0.3, 0.3], abs=cell)
    assert o["frames"] == ";".join(f"f{i}.nc" for i in range(7))


def test_progress_bars_only_on_a_terminal(monkeypatch):
    # A bar redraws its line with carriage returns: on a terminal only, never with -q.
    import sys

    from holoradar.app.cli.common import Reporter

    monkeypatch.setattr(sys.stderr, "isatty", lambda: False, raising=False)
    assert Reporter(False, False).progress is False
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    assert Reporter(False, False).progress is True
    assert Reporter(False, True).progress is False


def test_a_survey_store_opens_in_xarray_without_a_warning(tmp_path):
    # Consolidated metadata written at the end of each run: xarray.open_zarr finds every
    # array in one document and says nothing; a second run that adds frames writes it
    # again (xarray sees them).
    import xarray as xr

    x = (np.arange(8) - 3.5) * 0.01
    paths = [hr.save(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9, pose=hr.Pose((0.05 * i, 0, 0))),
                     tmp_path / f"f{i}.nc") for i in range(3)]
    store = tmp_path / "s.zarr"
    hr.survey.run_batch(paths[:2], store, z=[0.2], scheduler="synchronous")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        n2 = xr.open_zarr(store)["frame_path"].size
    hr.survey.run_batch(paths, store, z=[0.2], scheduler="synchronous")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        n3 = xr.open_zarr(store)["frame_path"].size
    assert n3 > n2 or n3 >= 3


def test_a_damaged_chunk_is_named_by_its_frames_not_a_crash(tmp_path):
    # Every image chunk carries a CRC-32C (after Blosc): a flipped byte is found before
    # the decompressor sees it. mosaic and detect answer with the damaged frame's name
    # and exit 2; the frames of intact chunks still read.
    import glob

    from cli_helpers import one_line_error, run

    x = (np.arange(8) - 3.5) * 0.01
    paths = [hr.save(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9, pose=hr.Pose((0.05 * i, 0, 0))),
                     tmp_path / f"f{i}.nc") for i in range(4)]
    store = tmp_path / "s.zarr"
    hr.survey.run_batch(paths, store, z=[0.2], scheduler="synchronous")
    chunks = sorted(glob.glob(str(store / "image" / "c" / "*" / "*" / "*" / "*" / "*")))
    assert chunks
    b = bytearray(open(chunks[0], "rb").read())
    b[len(b) // 2] ^= 0xFF
    open(chunks[0], "wb").write(bytes(b))
    res = run("mosaic", store, "--range", "0.2", "-o", tmp_path / "m.nc", ok=False)
    one_line_error(res, "damaged", "f0.nc")
    assert not (tmp_path / "m.nc").exists()
    one_line_error(run("detect", store, "--z", "0.2", ok=False), "damaged", "f0.nc")
    # info names it among the damaged frames, by its checksum
    info = hr.survey.describe_store(store)
    assert [d["name"] for d in info["damaged"]] == ["f0.nc"] and \
        "CRC-32C" in info["damaged"][0]["reason"]
    res = run("info", store, ok=False)
    assert res.exit_code == 2 and "f0.nc" in res.output
    # a rerun images the damaged frame again: the store is whole
    s = hr.survey.run_batch(paths, store, z=[0.2], scheduler="synchronous")
    assert s["done"] >= 1 and hr.survey.describe_store(store)["damaged"] == []
    run("mosaic", store, "--range", "0.2", "-o", tmp_path / "m.nc")
    # a missing chunk: named by mosaic, not drawn as a blank hole
    import os

    os.remove(chunks[-1])
    one_line_error(run("mosaic", store, "--range", "0.2", "-o", tmp_path / "m2.nc",
                       ok=False), "damaged", "f3.nc", "missing")


def test_bars_stacked_in_depth_and_objects_one_frame_told_apart_stay_apart():
    # A bar over another (4 and 20 cm deep, depth intervals apart), both seen by two
    # frames: two bars. Two points one frame tells apart, a point of another frame
    # between them: still two objects.
    def deep(row, depth):
        return {**row, "depth": depth, "depth_low": depth - 0.005, "depth_high": depth + 0.005}

    rows = [deep(_line("a", -0.3, 0.0), 0.04), deep(_line("b", -0.05, 0.3), 0.04),
            deep(_line("a", -0.3, 0.0, y=0.005), 0.20),
            deep(_line("b", -0.05, 0.3, y=0.005), 0.20)]
    t = merge(pd.DataFrame(rows))
    assert sorted(t.depth) == [0.04, 0.20] and list(t.frames) == ["a;b", "a;b"]
    pts = [_point("a", 0.0, 0.0), _point("a", 0.035, 0.0), _point("b", 0.018, 0.0)]
    assert len(merge(pd.DataFrame(pts))) == 2


def test_spacing_is_between_bars_side_by_side_not_end_to_end():
    rows = [_line("a", -0.3, -0.1), _line("a", -0.3, -0.1, y=0.15), _line("b", 0.1, 0.3)]
    t = merge(pd.DataFrame(rows)).sort_values(["x", "y"])
    assert t.spacing.tolist()[:2] == pytest.approx([0.15, 0.15])
    assert np.isnan(t.spacing.tolist()[2])


def test_two_frames_seeing_points_at_one_place_and_two_depths_keep_two_rows():
    # One frame sees a point 10 cm deep, another a point at the same (x, y) 30 cm deep:
    # their 95 % depth intervals (a centimetre each) are 18 cm apart, so they are two
    # objects, one above the other, not one seen twice.
    def deep(row, depth):
        return {**row, "depth": depth, "depth_low": depth - 0.01, "depth_high": depth + 0.01}

    t = merge(pd.DataFrame([deep(_point("f0", 0.0, 0.0), 0.10),
                            deep(_point("f1", 0.001, 0.0), 0.30)]))
    assert sorted(t.depth) == [0.10, 0.30] and list(t.frames) == ["f0", "f1"]
