"""``holoradar detect``: each output format parses back to ``hr.detect``'s table; outputs are
never replaced unasked; bad options are one line naming the option, nothing written."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pandas as pd
import pytest

import holoradar as hr
from cli_helpers import one_line_error, run
from holoradar.io.detections import geojson

warnings.filterwarnings("ignore", category=hr.AliasingWarning)
pytestmark = pytest.mark.filterwarnings("ignore::holoradar.AliasingWarning")

SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
GROUND = ["--eps", "2.5+0.0125j", "--z-surface", "0.3"]






@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Two points 20 dB apart, 12 cm deep in sand, under the paper's array; its hologram,
    its image (with the history ``holoradar image`` writes, which records the ground) and
    the reference table ``hr.detect`` gives."""
    d = tmp_path_factory.mktemp("detect")
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((-0.06, 0.03, 0.42), 1.0),
                                            hr.PointTarget((0.08, -0.05, 0.42), 0.1)])
    h = hr.simulate(scene, hr.Aperture.paper(), 9.9e9, include_surface=False, snr_db=40,
                    seed=3)
    holo = hr.save(h, d / "holo.nc")
    step = {"step": "migrate", "input": "holo.nc", "parameters": {
        "z": "0.42", "method": "angular", "frame": "aperture", "upsample": 4, "layout": None,
        "medium": {"z_interfaces": [0.3], "eps": ["(1+0j)", "(2.5+0.0125j)"]}}}
    hr.save(hr.migrate(h, 0.42, medium=SAND, upsample=4), d / "img.nc", history=[step])
    img = hr.load(d / "img.nc")
    ref = hr.detect(img, hologram=h, medium=SAND)
    assert len(ref) == 2
    return {"dir": d, "holo": holo, "img": d / "img.nc", "h": h, "ref": ref}


def _same(table: pd.DataFrame, ref: pd.DataFrame) -> None:
    pd.testing.assert_frame_equal(table.reset_index(drop=True), ref.reset_index(drop=True),
                                  check_dtype=False, rtol=1e-12, atol=0)


def _from_records(records: list[dict]) -> pd.DataFrame:
    return pd.DataFrame(records).fillna(np.nan).infer_objects()


def test_csv_is_detects_table(files):
    out = files["dir"] / "objects.csv"
    res = run("detect", files["img"], "--hologram", files["holo"], "-o", out, "--force")
    _same(pd.read_csv(out), files["ref"])
    # The terminal: one line per object (kind, x, y, depth with its interval, amp, SNR).
    rows = [ln for ln in res.output.splitlines() if ln.strip().startswith(("1 ", "2 "))]
    assert len(rows) == 2 and all("point" in r for r in rows)
    assert "-6.0" in rows[0] and "12.0 [" in rows[0]
    assert "ground from img.nc's history" in res.output


def test_json_holds_the_records_and_the_metadata(files):
    out = files["dir"] / "objects.json"
    run("detect", files["img"], "--hologram", files["holo"], "-o", out, "--force")
    doc = json.loads(out.read_text())
    _same(_from_records(doc["objects"])[files["ref"].columns], files["ref"])
    meta = doc["metadata"]
    assert meta["threshold"] == pytest.approx(files["ref"].attrs["threshold"])
    assert meta["n_cells"] == pytest.approx(files["ref"].attrs["n_cells"])
    assert meta["model"] == "reflectivity:sparse" and meta["source"] == str(files["img"])
    assert meta["medium"]["z_interfaces_m"] == [0.3]
    assert meta["eps_interval"] is None and meta["false_alarm"] == 1e-3


UTM33 = "EPSG:32633"
# Web Mercator: a projected CRS in metres whose area of use holds a scene's local
# metres near (0, 0) (UTM's does not: x = 0 there is 500 km west of its meridian, and
# such positions are refused).
LOCAL = "EPSG:3857"


def test_geojson_is_longitude_latitude_that_geopandas_reads_back(files):
    # RFC 7946: WGS 84 longitude, latitude. geopandas reads the file as EPSG:4326 and,
    # reprojected to the positions' CRS, every point lies where the table says (PROJ's
    # round trip is exact to far below a millimetre; 1 cm is what a survey needs).
    gpd = pytest.importorskip("geopandas")
    out = files["dir"] / "objects.geojson"
    run("detect", files["img"], "--hologram", files["holo"], "-o", out, "--force", "-q",
        "--crs", LOCAL)
    doc = json.loads(out.read_text())
    assert doc["type"] == "FeatureCollection" and "crs" not in doc
    assert doc["crs_of_properties"]["crs"].startswith("EPSG:3857")
    feats = doc["features"]
    assert [f["geometry"]["type"] for f in feats] == ["Point", "Point"]
    _same(_from_records([f["properties"] for f in feats])[files["ref"].columns], files["ref"])
    g = gpd.read_file(out)
    assert g.crs.to_epsg() == 4326
    back = g.to_crs(LOCAL)
    np.testing.assert_allclose(back.geometry.x, files["ref"].x, rtol=0, atol=0.01)
    np.testing.assert_allclose(back.geometry.y, files["ref"].y, rtol=0, atol=0.01)


def test_geojson_of_a_known_point_is_its_longitude_and_latitude():
    # UTM zone 33N's false origin: (500000 m, 0 m) is longitude 15 E on the equator.
    df = pd.DataFrame([{"kind": "point", "x": 500000.0, "y": 0.0}])
    (f,) = geojson(df, {}, "survey", UTM33)["features"]
    assert f["geometry"]["coordinates"] == pytest.approx([15.0, 0.0], abs=1e-9)


def test_geojson_without_a_crs_is_refused_with_the_way_out(files, tmp_path):
    with pytest.raises(ValueError, match=r"--crs EPSG.*\.csv or \.json"):
        geojson(pd.DataFrame([{"kind": "point", "x": 0.0, "y": 0.0}]), {}, "scene")
    out = tmp_path / "o.geojson"
    one_line_error(run("detect", files["img"], "--hologram", files["holo"], "-o", out,
                       ok=False), "--out", "--crs", ".csv")
    one_line_error(run("detect", files["img"], "--crs", "EPSG:99999", "-o", out, ok=False),
                   "--crs", "EPSG:99999")
    one_line_error(run("detect", files["img"], "--crs", "EPSG:4326", "-o", out, ok=False),
                   "--crs", "projected")
    assert not list(tmp_path.iterdir())


def test_geojson_lines_and_areas():
    df = pd.DataFrame([
        {"kind": "line", "x": 0.0, "y": 0.0, "x_start": -0.1, "y_start": 0.0, "x_end": 0.1,
         "y_end": 0.0, "length": 0.2, "width": 0.0, "azimuth_deg": 0.0},
        {"kind": "area", "x": 1.0, "y": 2.0, "x_start": np.nan, "y_start": np.nan,
         "x_end": np.nan, "y_end": np.nan, "length": 0.4, "width": 0.2, "azimuth_deg": 90.0}])
    line, area = geojson(df, {}, "scene", LOCAL)["features"]
    assert line["geometry"]["type"] == "LineString"
    ring = np.array(area["properties"]["outline_xy"])
    assert area["geometry"]["type"] == "Polygon" and np.allclose(ring[0], ring[-1])
    assert np.ptp(ring[:, 0]) == pytest.approx(0.2) and np.ptp(ring[:, 1]) == pytest.approx(0.4)
    assert area["properties"]["x_start"] is None    # NaN is null: valid JSON
    lonlat = np.array(area["geometry"]["coordinates"][0])
    assert lonlat.shape == ring.shape and np.allclose(lonlat[0], lonlat[-1])


def test_a_table_of_several_kinds_is_one_geometry_type_per_file(tmp_path):
    # A Shapefile layer holds one geometry type: OUT holds every object as its point,
    # OUT_lines and OUT_points each kind's own geometry; each is written by pyogrio to
    # a Shapefile without complaint.
    gpd = pytest.importorskip("geopandas")
    from holoradar.io.detections import write

    df = pd.DataFrame([
        {"kind": "line", "x": 0.0, "y": 0.0, "x_start": -0.1, "y_start": 0.0, "x_end": 0.1,
         "y_end": 0.0, "length": 0.2, "azimuth_deg": 0.0},
        {"kind": "point", "x": 0.3, "y": 0.1, "x_start": np.nan, "y_start": np.nan,
         "x_end": np.nan, "y_end": np.nan, "length": 0.0, "azimuth_deg": np.nan}])
    out = tmp_path / "o.geojson"
    written = write(out, df, {}, "scene", LOCAL)
    assert [p.name for p in written] == ["o.geojson", "o_points.geojson", "o_lines.geojson"]
    for p, types in zip(written, (["Point"], ["Point"], ["LineString"]), strict=True):
        g = gpd.read_file(p)
        assert list(g.geometry.geom_type.unique()) == types
        g.to_file(tmp_path / f"{p.stem}.shp")


def test_survey_with_a_crs_lands_where_its_object_is(tmp_path):
    # Two frames placed in UTM 33N (easting, northing in metres) over one point 12 cm
    # deep in sand; the store keeps the CRS (holoradar batch --crs): its GeoJSON,
    # reprojected by geopandas, within 1 cm of the point (a quarter resolution cell is
    # 8 mm here; the fit's standard deviation about 1 mm at 40 dB).
    gpd = pytest.importorskip("geopandas")
    e0, n0 = 500123.0, 4649776.0
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((e0 + 0.04, n0 + 0.11, 0.42))])
    paths = []
    for i, x0 in enumerate((0.0, 0.1)):
        ap = hr.Aperture.grid(16, 0.0125, pose=hr.Pose((e0 + x0, n0 + 0.1, 0.0)))
        h = hr.simulate(scene, ap, 9.9e9, include_surface=False, snr_db=40, seed=i)
        paths.append(hr.save(h, tmp_path / f"frame{i}.nc"))
    run("batch", *paths, "-o", tmp_path / "s.zarr", "--z", "0.42", "--eps", "2.5+0.0125j",
        "--z-surface", "0.3", "--upsample", "4", "--workers", "1", "--crs", UTM33, "-q")
    out = tmp_path / "o.geojson"
    run("detect", tmp_path / "s.zarr", "-o", out, "-q")
    g = gpd.read_file(out).to_crs(UTM33)
    assert len(g) == 1
    assert abs(g.geometry.x[0] - (e0 + 0.04)) < 0.01 and abs(g.geometry.y[0] - (n0 + 0.11)) < 0.01
    # A different CRS for the store is refused by name; nothing written.
    one_line_error(run("detect", tmp_path / "s.zarr", "--crs", "EPSG:32632", "-o",
                       tmp_path / "p.geojson", ok=False), "--crs", "32633")
    assert not (tmp_path / "p.geojson").exists()


def test_geojson_area_is_detects_outline(tmp_path):
    # A metal plate 10 x 6 cm 10 cm deep in sand: one area, whose GeoJSON Polygon is the
    # outline hr.detect found (the hull of its components), not a rectangle.
    plate = hr.PlanarTarget.from_shape("rectangle", 0.40, center=(0.02, -0.01),
                                       reflection=-1, width=0.10, height=0.06)
    h = hr.simulate(hr.Scene(SAND, hr.PlaneWave(), [plate]), hr.Aperture.grid(24, 0.0125),
                    9.9e9, include_surface=False, snr_db=30, seed=1)
    img = hr.save(hr.migrate(h, 0.40, medium=SAND, upsample=4), tmp_path / "plate.nc")
    out = tmp_path / "plate.geojson"
    run("detect", img, *GROUND, "-o", out, "-q", "--crs", LOCAL)
    ref = hr.detect(hr.load(img), medium=SAND)
    assert list(ref.kind) == ["area"]
    (feat,) = json.loads(out.read_text())["features"]
    assert feat["geometry"]["type"] == "Polygon"
    ring = np.array(feat["properties"]["outline_xy"])
    outline = np.array(ref.attrs["outlines"][0])
    assert ring.shape == outline.shape and np.allclose(ring[0], ring[-1])
    assert ring == pytest.approx(outline, abs=1e-12)
    assert np.array(feat["geometry"]["coordinates"][0]).shape == ring.shape


def test_geojson_closes_an_open_outline():
    df = pd.DataFrame([{"kind": "area", "x": 0.5, "y": 0.5, "length": 1.0, "width": 1.0,
                        "azimuth_deg": 0.0}])
    df.attrs["outlines"] = {0: [[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]]}
    (area,) = geojson(df, {}, "scene", LOCAL)["features"]
    assert area["properties"]["outline_xy"] == [[0.0, 0.0], [1.0, 0.0], [0.5, 1.0],
                                                [0.0, 0.0]]
    ring = area["geometry"]["coordinates"][0]
    assert len(ring) == 4 and ring[0] == ring[-1]


def test_hologram_file_imaged_on_z_then_fitted(files):
    res = run("detect", files["holo"], "--z", "0.42", *GROUND, "--eps-interval", "2.2,2.8",
              "--json")
    doc = json.loads(res.stdout)
    img = hr.migrate(files["h"], 0.42, medium=SAND, upsample=4)
    ref = hr.detect(img, hologram=files["h"], medium=SAND, eps_interval=(2.2, 2.8))
    _same(_from_records(doc["objects"])[ref.columns], ref)
    assert doc["n_objects"] == 2 and doc["metadata"]["eps_interval"] == [2.2, 2.8]
    assert (ref.depth_high - ref.depth_low > 0.01).all()   # the eps interval widens it


def test_raised_hologram_fitted_from_its_height(tmp_path):
    # A level array 5 cm up (pose z): imaged on ranges from the array through the ground
    # the flags give in world z, as holoradar image does; a hologram FILE and an image with
    # its --hologram both give the point's true depth below the surface.
    ap = hr.Aperture.grid(16, 0.0125, pose=hr.Pose((0.0, 0.0, 0.05)))
    h = hr.simulate(hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((0.02, 0.01, 0.42))]), ap,
                    9.9e9, include_surface=False, snr_db=40, seed=1)
    holo = hr.save(h, tmp_path / "raised.nc")
    img = hr.save(hr.migrate(h, 0.37, medium=SAND, upsample=4), tmp_path / "raised_img.nc")
    for args in (["--z", "0.37"], ["--hologram", holo]):
        src = holo if args[0] == "--z" else img
        p = json.loads(run("detect", src, *args, *GROUND, "--json").stdout)["objects"]
        assert len(p) == 1, p
        assert p[0]["depth"] == pytest.approx(0.12, abs=2e-3)
        assert p[0]["range"] == pytest.approx(0.37, abs=2e-3)
        assert [p[0]["x"], p[0]["y"]] == pytest.approx([0.02, 0.01], abs=2e-3)


def test_quiet_keeps_the_table(files):
    res = run("detect", files["img"], "--z", "0.42", "-q")
    assert "point" in res.output and "object(s)" not in res.output


def test_existing_output_refused_without_force(files):
    out = files["dir"] / "keep.csv"
    out.write_text("precious")
    res = run("detect", files["img"], "-o", out, ok=False)
    one_line_error(res, "--out", "--force")
    assert out.read_text() == "precious"
    run("detect", files["img"], "-o", out, "--force")
    assert pd.read_csv(out).kind.tolist() == ["point", "point"]


@pytest.mark.parametrize(("args", "needles"), [
    (["--eps-interval", "2.5"], ["--eps-interval", "LO,HI"]),
    (["--eps-interval", "2.8,2.2"], ["--eps-interval", "LO <= HI"]),
    (["--eps-interval", "0.5,2"], ["--eps-interval", ">= 1"]),
    (["--false-alarm", "0.5"], ["--false-alarm", "(0, 0.1]"]),
    (["--false-alarm", "often"], ["--false-alarm"]),
    (["--kinds", "point,blob"], ["--kinds", "point, line, area"]),
    (["--eps", "2.5"], ["--eps/--z-surface"]),
    (["--z", "0.3:0.5:0.01"], ["--z", "one range"]),
    (["--z", "0.9"], ["--z"]),
    (["--z", "0.42", "--hologram", "HOLO"], ["--z", "not both"]),
])
def test_bad_options_named_nothing_written(files, args, needles):
    out = files["dir"] / "never.json"
    args = [str(files["holo"]) if a == "HOLO" else a for a in args]
    one_line_error(run("detect", files["img"], *args, "-o", out, ok=False), *needles)
    assert not out.exists()


def test_bad_inputs_named(files, tmp_path):
    # A hologram needs its planes; an output that is not a table's suffix; a volume needs
    # its hologram or one plane; an eps interval needs a ground.
    one_line_error(run("detect", files["holo"], ok=False), "--z")
    one_line_error(run("detect", files["img"], "-o", tmp_path / "o.txt", ok=False), "--out",
                   ".csv")
    vol = hr.migrate(files["h"], np.array([0.41, 0.42, 0.43]), medium=SAND, upsample=4)
    hr.save(vol, tmp_path / "vol.nc")
    one_line_error(run("detect", tmp_path / "vol.nc", ok=False), "FILE", "--hologram", "--z")
    one_line_error(run("detect", files["holo"], "--z", "0.42", "--eps-interval", "2,3",
                       ok=False), "--eps-interval", "ground")
    # The wrong hologram for an image: refused by the option's name.
    other = hr.save(hr.Hologram(files["h"].data[::-1], files["h"].x, files["h"].y, 9.9e9),
                    tmp_path / "other.nc")
    one_line_error(run("detect", files["img"], "--hologram", other, ok=False), "--hologram")
    assert not list(tmp_path.glob("*.csv")) and not list(tmp_path.glob("*.json"))


@pytest.fixture(scope="module", params=[0.0, 0.05], ids=["level0", "raised"])
def survey(tmp_path_factory, request):
    """Two overlapping frames (16 x 16 at 1.25 cm, 10 cm apart along x, at y = 0.1 m, their
    arrays at world height ``z0``) over one point 12 cm deep in sand at world (0.04, 0.11):
    the store's plane is its range from the arrays, 0.42 - z0."""
    z0 = request.param
    d = tmp_path_factory.mktemp("survey")
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((0.04, 0.11, 0.42))])
    paths = []
    for i, x0 in enumerate((0.0, 0.1)):
        ap = hr.Aperture.grid(16, 0.0125, pose=hr.Pose((x0, 0.1, z0)))
        h = hr.simulate(scene, ap, 9.9e9, include_surface=False, snr_db=40, seed=i)
        paths.append(hr.save(h, d / f"frame{i}.nc"))
    plane = round(0.42 - z0, 6)
    hr.survey.run_batch(paths, d / "s.zarr", z=[plane], medium=SAND, upsample=4,
                        scheduler="synchronous")
    return {"dir": d, "z0": z0, "plane": plane}


@pytest.mark.parametrize("mode", ["hologram", "plane"])
def test_survey_objects_in_survey_coordinates_once(survey, mode):
    # Both the hologram's fit and one stored plane: the object's world position and its
    # depth below the surface, whatever the arrays' height (the planes are ranges from
    # the arrays, the ground seen from their height).
    d, z0 = survey["dir"], survey["z0"]
    plane = [] if mode == "hologram" else ["--z", f"{survey['plane']:g}"]
    out = d / f"objects_{mode}.geojson"
    run("detect", d / "s.zarr", *plane, "-o", out, "--force", "--crs", LOCAL)
    doc = json.loads(out.read_text())
    feats = doc["features"]
    assert len(feats) == 1, [f["properties"] for f in feats]   # seen by both frames: once
    p = feats[0]["properties"]
    seen = hr.Medium.half_space(0.30 - z0, SAND.eps[1])
    cell = hr.theory.lateral_resolution(hr.C0 / 9.9e9, seen.apparent_distance(0.42 - z0), 0.2)
    assert abs(p["x"] - 0.04) < cell / 4 and abs(p["y"] - 0.11) < cell / 4
    from holoradar.io.crs import as_crs, to_lonlat

    assert feats[0]["geometry"]["coordinates"] == pytest.approx(
        list(to_lonlat(p["x"], p["y"], as_crs(LOCAL))), abs=1e-12)
    assert p["frame"] == "frame0.nc"       # the frame it lies nearest the centre of
    per_frame = doc["metadata"]["per_frame"]
    # One frequency: no finite range cell (null); the lateral cell bounds the depth.
    range_cell = per_frame[0]["resolution_cell"][2] or cell
    assert abs(p["depth"] - 0.12) < min(range_cell, cell) / 4, (p["depth"], cell)
    assert abs(p["range"] - (0.42 - z0)) < min(range_cell, cell) / 4
    assert p["depth"] == pytest.approx(0.12, abs=0.01)
    assert "survey" in doc["crs_of_properties"]["frame"]
    assert [f["frame"] for f in per_frame] == ["frame0.nc", "frame1.nc"]
    assert [f["array_z_m"] for f in per_frame] == pytest.approx([z0, z0])


def test_survey_geojson_area_is_the_frames_outline(tmp_path):
    # A plate under a raised frame away from the origin: the store's GeoJSON Polygon is
    # the outline hr.detect finds on the frame's stored plane (world pixels, the ground
    # seen from the array), kept through the survey's gathering of the frames.
    plate = hr.PlanarTarget.from_shape("rectangle", 0.40, center=(0.52, 0.19),
                                       reflection=-1, width=0.10, height=0.06)
    ap = hr.Aperture.grid(24, 0.0125, pose=hr.Pose((0.5, 0.2, 0.05)))
    h = hr.simulate(hr.Scene(SAND, hr.PlaneWave(), [plate]), ap, 9.9e9,
                    include_surface=False, snr_db=30, seed=1)
    frame = hr.save(h, tmp_path / "plate.nc")
    store = tmp_path / "s.zarr"
    hr.survey.run_batch([frame], store, z=[0.35], medium=SAND, upsample=4,
                        scheduler="synchronous")
    out = tmp_path / "plate.geojson"
    run("detect", store, "--z", "0.35", "-o", out, "-q", "--crs", LOCAL)
    seen = hr.Medium.half_space(0.25, SAND.eps[1])
    ref = hr.detect(hr.survey.frame_image(store, 0).plane(0.35), medium=seen)
    assert list(ref.kind) == ["area"] and ref.depth[0] == pytest.approx(0.10, abs=0.01)
    (feat,) = json.loads(out.read_text())["features"]
    assert feat["geometry"]["type"] == "Polygon"
    assert feat["properties"]["depth"] == pytest.approx(ref.depth[0], abs=1e-12)
    ring = np.array(feat["properties"]["outline_xy"])
    assert ring == pytest.approx(np.array(ref.attrs["outlines"][0]), abs=1e-12)
    assert abs(ring[:, 0].mean() - 0.52) < 0.03 and abs(ring[:, 1].mean() - 0.19) < 0.03


def test_survey_stale_hologram_refused_in_cli_terms(tmp_path):
    # A frame's file changed since the batch: one line naming the frame and the CLI's
    # ways out (batch again, --z), no Python keyword.
    scene = hr.Scene(SAND, hr.PlaneWave(), [hr.PointTarget((0.0, 0.0, 0.42))])
    ap = hr.Aperture.grid(16, 0.0125, pose=hr.Pose((0.0, 0.0, 0.05)))
    h = hr.simulate(scene, ap, 9.9e9, include_surface=False, snr_db=40, seed=1)
    frame = hr.save(h, tmp_path / "frame.nc")
    hr.survey.run_batch([frame], tmp_path / "s.zarr", z=[0.37], medium=SAND, upsample=4,
                        scheduler="synchronous")
    hr.save(hr.Hologram(h.data[::-1], h.x, h.y, h.frequency, pose=h.pose), frame,
            overwrite=True)
    res = run("detect", tmp_path / "s.zarr", ok=False)
    one_line_error(res, "frame.nc", "holoradar batch", "--z")
    assert "migrate_options" not in res.output and "={" not in res.output


def test_survey_refuses_ground_flags_and_hologram(survey, files):
    store = survey["dir"] / "s.zarr"
    one_line_error(run("detect", store, *GROUND, ok=False), "--eps/--z-surface")
    one_line_error(run("detect", store, "--hologram", files["holo"], ok=False),
                   "--hologram")


def test_local_positions_are_refused_in_a_crs_and_placed_by_origin(files, tmp_path):
    # An image's axes are local metres: written as eastings and northings of UTM 33N
    # they would land at 10.5 E on the equator. Refused, naming --origin; with --origin
    # (and --azimuth) each object lands where the local grid puts it, to the metre.
    import json

    import pyproj

    from cli_helpers import one_line_error, run

    img, ref = files["img"], files["ref"]
    out = tmp_path / "o.geojson"
    one_line_error(run("detect", img, *GROUND, "--crs", "EPSG:32633", "-o", out, ok=False),
                   "outside the area of use", "--origin")
    assert not out.exists()
    run("detect", img, *GROUND, "--crs", "EPSG:32633", "--origin", "500000,4649776",
        "--azimuth", "90", "-o", out, "-q")
    features = json.loads(out.read_text())["features"]
    to_lonlat = pyproj.Transformer.from_crs("EPSG:32633", "EPSG:4326", always_xy=True)
    for feature, (x, y) in zip(features, zip(ref.x, ref.y, strict=True), strict=True):
        # +y at 90 degrees (east): local (x, y) is E0 + y, N0 - x.
        lon, lat = to_lonlat.transform(500000.0 + y, 4649776.0 - x)
        got = feature["geometry"]["coordinates"]
        assert abs(got[0] - lon) < 2 / 111e3 and abs(got[1] - lat) < 2 / 111e3
