"""``holoradar view`` without a browser: its settings, its imaging, its exports and
``holoradar render``. (The page itself is tested in Chromium by test_viewer_browser.)"""

from __future__ import annotations

import json
import os
import socket
import warnings
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import holoradar as hr
from holoradar.analysis.metrics import peak_position
from holoradar.app.cli import main
from holoradar.app.view.export import export_netcdf, export_png, export_settings
from holoradar.app.view.server import is_loopback, make_server, url_of
from holoradar.app.view.session import ViewSession
from holoradar.app.view.settings import ViewSettings, read_settings, settings_toml

SAND = {"surface": 0.30, "eps": "2.5+0.01j"}
# The paper's 2.5 cm pitch aliases waves beyond 37 degrees off axis: known, and said
# once by every imaging call; these tests are about the viewer's plumbing.
pytestmark = pytest.mark.filterwarnings("ignore::holoradar.AliasingWarning")


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """Two views of a point 12 cm deep in sand, from a horn at two places (simulated by
    holoradar: these tests check the viewer's plumbing, the physics is tested elsewhere)."""
    d = tmp_path_factory.mktemp("scene")
    sand = hr.Medium.half_space(0.30, 2.5 + 0.01j)
    target = [hr.PointTarget((0.02, -0.01, 0.42), 0.05)]
    paths, views = [], []
    for i, sx in enumerate((-0.15, 0.15)):
        h = hr.simulate(hr.Scene(sand, hr.PointSource((sx, 0.0, -0.05)), target),
                        hr.Aperture.grid(16, 0.025), 9.9e9)
        views.append(h)
        paths.append(hr.save(h, d / f"v{i}.nc"))
    return paths, views, sand


def test_settings_round_trip_through_toml(tmp_path):
    s = ViewSettings(files=(str(tmp_path / "a.nc"), str(tmp_path / "b.nc")), depth=0.07,
                     sweep=(0.0, 0.2), planes=21, views=(1,), mode="amplitude",
                     frequency=3, glare="cut", direct=False, scale="linear", db_range=40.0,
                     plane="mirror", section=(0.01, -0.02), ground=SAND)
    p = tmp_path / "look.toml"
    p.write_text(settings_toml(s, relative_to=tmp_path), encoding="utf-8")
    assert '"a.nc"' in p.read_text()  # relative to the TOML's folder
    assert read_settings(p) == s


def test_settings_take_lists_and_keep_every_digit_of_a_permittivity(scene, tmp_path):
    # As TOML and JSON give them: lists become the fields' tuples.
    s = ViewSettings(files=["a.nc"], views=[0, 1], sweep=[0.0, 0.2], section=[0.0, 0.01])
    assert (s.files, s.views, s.sweep, s.section) == (("a.nc",), (0, 1), (0.0, 0.2),
                                                      (0.0, 0.01))
    # A complex permittivity written to a saved look comes back to the last bit, so that
    # the look's image is reproduced bit for bit.
    eps = 2.123456789123 + 0.0123456789123j
    paths, _, _ = scene
    S = ViewSession(paths[:1])
    s = S.default_settings(ground={"surface": 0.3, "eps": eps})
    back = read_settings(export_settings(s, tmp_path))
    assert complex(S.medium(back).eps[1]) == eps


@pytest.mark.parametrize(("text", "message"), [
    ("[image]\ndepth = 'deep'\n", r"image.depth must be a depth in metres, got 'deep'"),
    ("[glare]\nmethod = 'magic'\n", r"glare.method must be 'off' or 'gaussian'"),
    ("[views]\nuse = []\n", r"views.use must be a non-empty list"),
    ("[views]\nuse = [0, 0]\n", r"views.use must be view indices each named once"),
    ("[image]\nzoom = 2\n", r"unknown keys \['zoom'\] in \[image\]; expected depth"),
    ("[camera]\n", r"unknown entries \['camera'\]"),
    ("files = 'a.nc'\n", r"files must be a list of file names"),
    ("depth = = 1\n", r"is not valid TOML"),
    ("[image]\nsweep = 0.3\n", r"image.sweep must be \[first, last\] depths in metres"),
    ("[display]\nsection = 1\n", r"display.section must be \[x, y\] in metres"),
])
def test_bad_settings_name_the_key_and_the_expected_form(tmp_path, text, message):
    p = tmp_path / "look.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError, match=message):
        read_settings(p)


def test_session_images_with_holoradars_functions(scene):
    # The session is a view onto the library: the same call gives the same array.
    paths, views, sand = scene
    S = ViewSession(paths)
    s = S.default_settings(ground=SAND).replace(depth=0.12)
    both = S.image(s)
    np.testing.assert_array_equal(
        both.data, hr.synthesize(views, 0.42, medium=sand, upsample=4, fov="full").data)
    one = S.image(s.replace(views=(1,)))
    np.testing.assert_array_equal(
        one.data, hr.migrate(views[1], 0.42, medium=sand, upsample=4, fov="full").data)
    clean, notes = S.cleaned(s.replace(glare="gaussian"))
    ref, rep = hr.suppress_surface(views[0], sand, method="gaussian")
    np.testing.assert_array_equal(clean[0].data, ref.data)
    assert notes[0].removed_db == rep.glare_removed_db
    assert notes[0].direct_db == rep.direct_removed_db


def test_render_reproduces_an_exported_look(scene, tmp_path):
    paths, _, _ = scene
    S = ViewSession(paths)
    s = S.default_settings(ground=SAND).replace(depth=0.12, glare="gaussian", views=(0,))
    look = export_settings(s, tmp_path)
    shown = export_netcdf(S, s, tmp_path)
    png = export_png(S, s, tmp_path)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = tmp_path / "again.nc"
    r = CliRunner().invoke(main, ["render", str(look), "-o", str(out), "--json"])
    assert r.exit_code == 0, r.output
    np.testing.assert_array_equal(hr.load(out).data, hr.load(shown).data)
    # the reported brightest point is the rendered image's
    ax, ay, _ = peak_position(hr.load(shown))
    assert json.loads(r.output)["peak_m"][:2] == pytest.approx([ax, ay], abs=1e-12)
    assert out.with_suffix(".png").exists()
    # never over an existing file unless asked; never over an input
    again = CliRunner().invoke(main, ["render", str(look), "-o", str(out)])
    assert again.exit_code != 0 and "--force" in again.output
    onto = CliRunner().invoke(main, ["render", str(look), "-o", str(paths[0]), "--force"])
    assert onto.exit_code != 0 and paths[0].exists()
    assert hr.load(paths[0]).data.shape == (16, 16)


def test_exports_never_replace_a_file(scene, tmp_path):
    paths, _, _ = scene
    S = ViewSession(paths[:1])
    s = S.default_settings(ground=SAND)
    first, second = export_png(S, s, tmp_path), export_png(S, s, tmp_path)
    assert first != second and first.exists() and second.exists()
    a, b = export_settings(s, tmp_path), export_settings(s, tmp_path)
    assert a != b and read_settings(a) == read_settings(b)
    n = export_netcdf(S, s, tmp_path)
    assert n.name == f"v0_{s.depth * 100:.1f}cm.nc"
    assert not list(tmp_path.glob(".*"))  # no temporary file left
    umask = os.umask(0)
    os.umask(umask)
    assert all(p.stat().st_mode & 0o777 == 0o666 & ~umask for p in (first, a, n))


def test_view_refuses_a_file_it_cannot_read_with_the_clis_message(tmp_path):
    bad = tmp_path / "notes.txt"
    bad.write_text("not a hologram")
    r = CliRunner().invoke(main, ["view", str(bad), "--no-browser"])
    info = CliRunner().invoke(main, ["info", str(bad)])
    assert r.exit_code != 0 and "unknown format '.txt'" in r.output
    assert r.output.strip().splitlines()[-1] == info.output.strip().splitlines()[-1]
    missing = CliRunner().invoke(main, ["view", str(tmp_path / "gone.nc"), "--no-browser"])
    assert missing.exit_code != 0 and "does not exist" in missing.output


def test_server_binds_the_loopback_and_warns_otherwise(scene):
    paths, _, _ = scene
    S = ViewSession(paths[:1])
    s = S.default_settings(ground=SAND)
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("::1")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.5")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        server = make_server(S, s, export_dir=Path("."))
    try:
        bound = {sock.getsockname()[0] for sock in server._http._sockets.values()}
        assert bound == {"127.0.0.1"}
        assert url_of(server, "127.0.0.1") == f"http://127.0.0.1:{server.port}/"
    finally:
        server.stop()
    with pytest.warns(UserWarning, match="not the loopback"):
        server = make_server(S, s, host="0.0.0.0", export_dir=Path("."))
    try:
        # reachable under the machine's name, and its websocket accepts that origin
        name = socket.gethostname()
        assert url_of(server, "0.0.0.0") == f"http://{name}:{server.port}/"
        assert f"{name}:{server.port}" in server._tornado.websocket_origins
    finally:
        server.stop()


def test_an_image_file_and_a_survey_store_open_too(scene, tmp_path):
    # An image or volume shows its own planes; a survey store its mosaic at the depth.
    _, views, sand = scene
    zs = np.linspace(0.38, 0.46, 9)
    vol = hr.migrate(views[0], zs, medium=sand, upsample=2)
    S = ViewSession([hr.save(vol, tmp_path / "vol.nc")])
    assert S.kind == "image"
    s = S.default_settings()
    np.testing.assert_array_equal(S.image(s.replace(depth=0.42)).data, vol.plane(0.42).data)
    from holoradar.survey import mosaic, run_batch

    frames = []
    for i, x0 in enumerate((-0.1, 0.1)):
        h = hr.Hologram(views[0].data, views[0].x + x0, views[0].y, views[0].frequency)
        frames.append(hr.save(h, tmp_path / f"frame{i}.nc"))
    store = tmp_path / "s.zarr"
    run_batch(frames, store, z=[0.40, 0.42], medium=sand, scheduler="synchronous")
    S = ViewSession([store])
    assert S.kind == "survey"
    np.testing.assert_array_equal(S.image(S.default_settings().replace(depth=0.42)).data,
                                  mosaic(store, 0.42).data)


def test_exports_without_hard_links_copy_without_replacing(scene, tmp_path, monkeypatch):
    # A file system without hard links (FAT, some shares): the same rules by exclusive copy.
    def no_links(*_a, **_k):
        raise OSError("hard links not supported")

    monkeypatch.setattr(os, "link", no_links)
    paths, _, _ = scene
    s = ViewSession(paths[:1]).default_settings(ground=SAND)
    a, b = export_settings(s, tmp_path), export_settings(s, tmp_path)
    assert a != b and read_settings(a) == read_settings(b)
    assert not list(tmp_path.glob(".*"))


DATA = Path(__file__).parent / "data"


def test_several_frequencies_and_a_tilted_array(tmp_path):
    # Plumbing for the other kinds of holograms: gprMax's 21 frequencies summed coherently
    # by migrate (the dipole's phase per frequency), and SMUTHI's tilted array imaged on
    # level planes (frame="ground"); the session must ask for exactly that.
    with np.load(DATA / "run_C_rod.npz") as c:
        h = hr.Hologram(c["Ey"].astype(complex), c["x_m"], c["y_m"], c["freqs_hz"],
                        source=hr.PointSource((-0.2, 0.0, 0.2), axis=(0.0, 1.0, 0.0),
                                              dipole=True))
    S = ViewSession([hr.save(h, tmp_path / "rod21.nc")])
    s = S.default_settings(ground={"surface": 0.3, "eps": "2.5"}).replace(depth=0.1)
    sand = hr.Medium.half_space(0.3, 2.5)
    np.testing.assert_array_equal(
        S.image(s).data,
        hr.migrate(h, 0.4, medium=sand, combine="coherent", upsample=4, fov="full").data)
    one = S.image(s.replace(frequency=9))
    np.testing.assert_array_equal(
        one.data, hr.migrate(h.at_frequency(9), 0.4, medium=sand, upsample=4, fov="full").data)
    d = np.load(DATA / "S7_tilted_array_sphere.npz")
    c = d["centre_m"]
    pose = hr.Pose((c[0], c[1], 0.4 - c[2]), tilt=np.radians(40), azimuth=np.radians(90))
    t = hr.Hologram(d["E_scat"][0], d["x_local_m"], d["y_local_m"], 9.9e9, pose=pose)
    S = ViewSession([hr.save(t, tmp_path / "tilted.nc")])
    s = S.default_settings(ground={"surface": 0.4, "eps": "2.5+0.0125j"})
    assert S.tilted and s.frame == "ground"
    np.testing.assert_array_equal(
        S.image(s.replace(depth=0.11)).data,
        hr.migrate(t, 0.51, medium=hr.Medium.half_space(0.4, 2.5 + 0.0125j), frame="ground",
                   upsample=4).data)


def test_the_mirror_plane_is_the_same_whichever_planes_are_chosen(scene):
    # The glare's mirror-source plane is imaged in the array's own frame (an array facing
    # the ground): the choice of level planes for the image must not change it, nor may
    # a picture cached for one choice be shown for the other.
    paths, views, _ = scene
    S = ViewSession(paths[:1])
    s = S.default_settings(ground=SAND).replace(plane="mirror")
    zm = 2 * 0.30 - (-0.05)
    want = hr.migrate(views[0], zm, upsample=4, fov="full").data
    np.testing.assert_array_equal(S.image(s.replace(frame="ground")).data, want)
    np.testing.assert_array_equal(S.image(s).data, want)
    np.testing.assert_array_equal(S.image(s.replace(frame="ground", fov="aperture")).data,
                                  hr.migrate(views[0], zm, upsample=4, fov="aperture").data)


def test_notes_belong_to_the_settings_shown(tmp_path):
    # Frequencies summed without a source assume a plane wave (the imaging warns); one
    # frequency assumes nothing: its look must not carry the other's note.
    x = np.arange(16) * 0.01
    h = hr.Hologram(np.ones((3, 16, 16), complex), x, x, [9e9, 9.9e9, 10.8e9])
    S = ViewSession([hr.save(h, tmp_path / "band.nc")])
    s = S.default_settings(ground=SAND)
    assert any("plane wave" in n for n in S.notes(s))
    assert S.notes(s.replace(frequency=1)) == ()
    assert any("plane wave" in n for n in S.notes(s))  # and again from the cache


def test_exports_without_hard_links_leave_nothing_when_the_rename_fails(scene, tmp_path,
                                                                         monkeypatch):
    # The name is claimed empty, then the finished file renamed onto it: a failed rename
    # must take the claim back (nothing half-written stays under the export's name).
    def no_links(*_a, **_k):
        raise OSError("hard links not supported")

    real_replace = os.replace

    def broken_replace(src, dst, *a, **k):
        if not Path(dst).name.startswith("."):  # the temporary file is still written
            raise OSError("disk gone")
        return real_replace(src, dst, *a, **k)

    monkeypatch.setattr(os, "link", no_links)
    monkeypatch.setattr(os, "replace", broken_replace)
    paths, _, _ = scene
    s = ViewSession(paths[:1]).default_settings(ground=SAND)
    with pytest.raises(OSError, match="disk gone"):
        export_settings(s, tmp_path)
    assert not list(tmp_path.iterdir())


def test_page_keeps_a_layered_ground_and_reports_bad_widget_values(scene, tmp_path):
    # Without a browser: the page's Python side on a bare Bokeh document.
    from bokeh.document import Document

    from holoradar.app.view.page import ViewerPage

    paths, _, _ = scene
    S = ViewSession(paths[:1])
    layers = {"layer": [{"top": 0.30, "eps": 2.5 + 0.01j}, {"top": 0.45, "eps": 4.0}]}
    page = ViewerPage(Document(), S, S.default_settings(ground=layers), tmp_path)
    # a look saved with layers offers them, and touching a ground knob keeps them
    assert page.ground_kind.value == "layers from file"
    page.eps_re.value = 3.0
    assert page.s.ground == layers
    assert S.surface(page.s) == pytest.approx(0.30)
    # an emptied spinner is said on the page, not raised in the server's callback
    page.db_range.value = None
    assert "dB range" in page.status.text and page.s.db_range == 30.0
    # a failed export is said on the page too, and file names are escaped
    page.export_dir = tmp_path / "gone"
    page._export("settings")
    assert "export settings:" in page.status.text
    assert "<b>v0.nc</b>" in page.info.text


def test_view_names_the_flag_that_is_wrong(scene, tmp_path):
    paths, views, sand = scene
    args = ["view", str(paths[0]), "--no-browser", "--eps", "2.5", "--z-surface", "0.3"]
    r = CliRunner().invoke(main, [*args, "--host", "::1"])
    assert r.exit_code == 2 and "--host" in r.output and "IPv6" in r.output
    r = CliRunner().invoke(main, [*args, "--depth", "nan"])
    assert r.exit_code == 2 and "--depth" in r.output
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        r = CliRunner().invoke(main, [*args, "--port", str(busy.getsockname()[1])])
    assert r.exit_code == 2 and "--port" in r.output and "in use" in r.output
    vol = hr.save(hr.migrate(views[0], [0.40, 0.42], medium=sand), tmp_path / "vol.nc")
    r = CliRunner().invoke(main, ["view", str(vol), "--no-browser", "--eps", "2.5",
                                  "--z-surface", "0.3"])
    assert r.exit_code == 2 and "apply to holograms" in r.output


def test_served_page_says_it_is_loading_before_the_document_arrives(scene):
    # The page is drawn by BokehJS from the document sent over the websocket: the HTML
    # itself must say something, or a plain screenshot (and a slow start) is blank.
    from tornado.httpclient import AsyncHTTPClient

    paths, _, _ = scene
    S = ViewSession(paths[:1])
    server = make_server(S, S.default_settings(ground=SAND), export_dir=Path("."))
    try:
        url = url_of(server, "127.0.0.1")
        resp = server.io_loop.run_sync(lambda: AsyncHTTPClient().fetch(url), timeout=120)
    finally:
        server.stop()
    html = resp.body.decode()
    assert resp.code == 200
    loading = html.find("loading the holoradar viewer...")
    # before the page's root, which BokehJS fills once the document has arrived
    assert 0 <= loading < html.index("data-root-id")


def test_page_layout_stretches_and_fits_a_1000_px_window(scene, tmp_path):
    # Fixed controls beside a plan view that takes what the window leaves (between its
    # minimum and maximum) and fixed-width sections: at their smallest they fit 1000 px,
    # less a scrollbar. (The browser test looks at the page at 1000 x 800.)
    from bokeh.document import Document

    from holoradar.app.view.page import ViewerPage

    paths, _, _ = scene
    S = ViewSession(paths)
    doc = Document()
    page = ViewerPage(doc, S, S.default_settings(ground=SAND), tmp_path)
    root = doc.roots[0]
    assert root.sizing_mode == "stretch_width"
    controls, main = root.children
    assert controls.sizing_mode in (None, "fixed") and main.sizing_mode == "stretch_width"
    assert page.fig.sizing_mode == "stretch_width"
    assert page.fig.min_width < page.fig.max_width
    sections = main.children[0].children[1]
    assert page.xz in sections.children and page.yz in sections.children
    def side_margins(model) -> int:  # left + right, as Bokeh takes its margin property
        m = model.margin or 0
        return 2 * m if isinstance(m, int) else m[1] + m[3]

    scrollbar = 20
    narrowest = sum(w + side_margins(m) for w, m in ((controls.width, controls),
                                                     (page.fig.min_width, page.fig),
                                                     (sections.width, sections)))
    assert narrowest <= 1000 - scrollbar
    assert all(w.width <= controls.width for w in controls.children if w.width)
    # every figure below the plan stretches too
    assert all(f.sizing_mode == "stretch_width" for f in page.hfigs)


# ----------------------------------------------------------------------------- objects
def _objects_table():
    """Three objects as holoradar.detect tabulates them (its columns): a point, a line
    along x through the origin, and an area with its outline (metres)."""
    import pandas as pd

    from holoradar.analysis.detect.table import COLUMNS

    nan = float("nan")
    rows = [
        {"kind": "point", "x": 0.02, "y": -0.01, "range": 0.42, "depth": 0.12,
         "depth_low": 0.11, "depth_high": 0.135, "length": 0.0, "width": 0.0,
         "snr_db": 21.3},
        {"kind": "line", "x": 0.0, "y": 0.0, "range": 0.40, "depth": 0.10, "length": 0.10,
         "width": 0.01, "azimuth_deg": 0.0, "x_start": -0.05, "y_start": 0.0,
         "x_end": 0.05, "y_end": 0.0, "snr_db": 15.0},
        {"kind": "area", "x": -0.05, "y": 0.05, "range": 0.45, "depth": 0.15,
         "length": 0.06, "width": 0.04, "azimuth_deg": 0.0, "snr_db": 12.04, "area": 0.0024},
    ]
    df = pd.DataFrame([{c: r.get(c, nan) for c in COLUMNS} for r in rows], columns=COLUMNS)
    df.attrs["outlines"] = {2: [[-0.08, 0.03], [-0.02, 0.03], [-0.02, 0.07], [-0.08, 0.07]]}
    return df


def test_page_overlays_and_lists_the_objects(scene, tmp_path):
    # The glyph sources carry the table's rows (cm), numbered from 1 in its order; the
    # list shows them; choosing a row moves the slider to its depth and the sections
    # through it.
    from bokeh.document import Document

    from holoradar.app.view.page import ViewerPage

    paths, _, _ = scene
    S = ViewSession(paths[:1])
    df = _objects_table()
    page = ViewerPage(Document(), S, S.default_settings(ground=SAND).replace(depth=0.1, planes=5),
                      tmp_path, objects=df)
    src = {k: dict(v.data) for k, v in page.obj_src.items()}
    assert src["points"] == {"x": [2.0], "y": [-1.0], "n": [1]}
    assert src["lines"] == {"x0": [-5.0], "y0": [0.0], "x1": [5.0], "y1": [0.0], "n": [2]}
    np.testing.assert_allclose(src["areas"]["xs"][0], [-8.0, -2.0, -2.0, -8.0], atol=1e-12)
    np.testing.assert_allclose(src["areas"]["ys"][0], [3.0, 3.0, 7.0, 7.0], atol=1e-12)
    assert src["areas"]["n"] == [3] and src["labels"]["text"] == ["1", "2", "3"]
    table = dict(page.obj_table_src.data)
    assert page.obj_table.visible
    assert table["n"] == [1, 2, 3] and table["kind"] == ["point", "line", "area"]
    # an interval where the table has one
    assert table["depth"] == ["12.0 [11.0, 13.5]", "10.0", "15.0"]
    assert table["size"] == ["-", "10.0 long", "6.0 x 4.0"]
    assert table["snr"] == ["21.3", "15.0", "12.0"]
    # the page's depth axis: range less the surface (0.30 m)
    np.testing.assert_allclose(table["at"], [12.0, 10.0, 15.0], atol=1e-9)
    page.obj_table_src.selected.indices = [2]
    assert page.depth.value == pytest.approx(15.0)
    assert page.s.section == (-0.05, 0.05)
    # On the sections: the objects within half a resolution cell of their planes (from a
    # file without one: two pixels, 2 x 2.5 cm / 4, or 1 cm). Through (0, 0): the point
    # 1 cm off y = 0 and the line along x on the x-z section; on the y-z section the
    # line where it crosses x = 0, its middle.
    assert page._near() == pytest.approx(0.0125)
    page.section_at = (0.0, 0.0)
    page._draw_objects()
    xz, yz = (dict(s.data) for s in page.obj_sections)
    assert xz["text"] == ["1", "2"] and xz["x"] == pytest.approx([2.0, 0.0])
    assert xz["z"] == pytest.approx([12.0, 10.0])
    assert yz["text"] == ["2"] and yz["x"] == [0.0] and yz["z"] == pytest.approx([10.0])


def test_objects_files_of_holoradar_detect_are_read_back(tmp_path):
    # What `holoradar detect -o` writes (.csv, .json, .geojson) is what the page shows.
    from holoradar.app.view.objects import overlay, read_objects
    from holoradar.io.detections import write as _write

    df = _objects_table()
    for suffix in (".csv", ".json", ".geojson"):
        p = tmp_path / f"objects{suffix}"
        _write(p, df, {"input": "test"}, "scene", "EPSG:3857")
        back = read_objects(p)
        assert list(back["kind"]) == ["point", "line", "area"], suffix
        for c in ("x", "y", "range", "depth", "x_start", "snr_db"):
            np.testing.assert_allclose(back[c], df[c], rtol=0, atol=0, err_msg=c)
        ring = overlay(back)["areas"]
        if suffix == ".geojson":  # the outline travels (closed); elsewhere the rectangle
            np.testing.assert_allclose(ring["xs"][0], [-8.0, -2.0, -2.0, -8.0, -8.0])
        else:
            np.testing.assert_allclose(ring["xs"][0], [-8.0, -2.0, -2.0, -8.0, -8.0])
            np.testing.assert_allclose(ring["ys"][0], [3.0, 3.0, 7.0, 7.0, 3.0])


@pytest.mark.parametrize(("name", "text", "message"), [
    ("o.txt", "x", r"o.txt: expected an objects table from holoradar detect -o \(.csv"),
    ("o.json", '{"features": []}', r"o.json: not an objects table"),
    ("o.csv", "a,b\n1,2\n", r"o.csv: not an objects table .*no column kind, x, y, range"),
    ("o.geojson", "[1, 2", r"o.geojson: not an objects table"),
])
def test_bad_objects_files_are_refused_by_name(tmp_path, scene, name, text, message):
    from holoradar.app.view.objects import read_objects

    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError, match=message):
        read_objects(p)
    paths, _, _ = scene
    r = CliRunner().invoke(main, ["view", str(paths[0]), "--no-browser", "--objects", str(p)])
    assert r.exit_code == 2 and "--objects" in r.output and name in r.output


def test_find_objects_runs_detect_on_the_plane_shown(scene, tmp_path, monkeypatch):
    # The page's "Find objects" is holoradar.detect on the plane at the slider with the
    # look's ground (detect itself is tested in test_detect*.py): plumbing only.
    from bokeh.document import Document

    import holoradar.analysis.detect as det
    from holoradar.app.view.page import ViewerPage

    seen = []

    def fake(image, *, medium=None):
        seen.append((image, medium))
        return _objects_table()

    monkeypatch.setattr(det, "detect", fake)
    paths, views, sand = scene
    S = ViewSession(paths[:1])
    page = ViewerPage(Document(), S, S.default_settings(ground=SAND).replace(depth=0.1, planes=5),
                      tmp_path)
    assert page.obj_table_src.data["n"] == [] and not page.obj_table.visible  # no room taken
    page.depth.value = 12.0
    page._find()
    (image, medium), = seen
    np.testing.assert_array_equal(
        image.data, hr.migrate(views[0], 0.42, medium=sand, upsample=4, fov="full").data)
    assert medium == S.medium(page.s)
    assert page.obj_table_src.data["n"] == [1, 2, 3]
    assert "3 object(s) in the plane at depth 12.0 cm" in page.objects_note.text
    page._find()  # the same plane: cached, not found again
    assert len(seen) == 1
    page.which.active = 1  # the mirror-source plane is not the scene
    page.s = page.s.replace(plane="mirror")
    page._find()
    assert "find objects: objects are found in the image plane" in page.status.text


def test_reflectivity_display_is_invert_of_the_view(scene, tmp_path):
    # display.plane = "reflectivity": the view's hologram inverted on the look's plane
    # (hr.invert, least squares, the same options), refused for several views at once.
    paths, _views, sand = scene
    S = ViewSession(paths)
    s = S.default_settings(ground=SAND).replace(depth=0.12, views=(1,), plane="reflectivity",
                                                upsample=2)
    got = S.image(s)
    zs = 0.30 + np.linspace(0.0, 0.25, s.planes)     # the default sweep
    ref = hr.invert(S.hologram(s, 1), zs, medium=sand, upsample=2, progress=False).plane(0.42)
    np.testing.assert_allclose(got.data, ref.data, rtol=1e-12, atol=0)
    assert got.method == "invert:lsqr"
    with pytest.raises(ValueError, match="reflectivity inverts one view"):
        S.image(s.replace(views=None))
    toml = tmp_path / "look.toml"
    toml.write_text(settings_toml(s, relative_to=tmp_path))
    assert read_settings(toml).plane == "reflectivity"


def test_ctrl_c_stops_the_viewer_with_one_line_and_exit_130(tmp_path, monkeypatch):
    """Ctrl-C while the viewer serves: one line, exit code 130, as every command."""
    from types import SimpleNamespace

    from cli_helpers import run
    from holoradar.app.cli import view as view_cmd

    class Loop:
        def start(self):
            raise KeyboardInterrupt

    stopped = []
    monkeypatch.setattr(view_cmd, "_serve", lambda *a, **k: SimpleNamespace(
        io_loop=Loop(), stop=lambda: stopped.append(True)))
    monkeypatch.setattr("holoradar.app.view.server.url_of", lambda server, host: "http://x")
    h = hr.save(hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))]),
                            hr.Aperture.grid(16, 0.01), 9.9e9), tmp_path / "h.nc")
    res = run("view", h, "--no-browser", ok=False)
    assert res.exit_code == 130, res.output
    assert res.output.strip().splitlines()[-1].startswith("interrupted: the viewer stopped")
    assert stopped == [True]


def test_glare_table_says_a_rough_eps_without_rounding_residue():
    """The Gaussian fit's eps has no sigma: two digits and "rough", no 3.1e-23j."""
    from holoradar.app.view.page.figures import _fmt_eps

    assert _fmt_eps(2.64 + 3.1e-23j, None) == "about 2.6 (rough: no σ from this method)"
    assert "e-" not in _fmt_eps(2.64 + 3.1e-23j, None)


def test_glare_table_gives_the_exact_fit_eps_with_its_sigma():
    """With a sigma: digits from it and no rounding residue as eps''."""
    from holoradar.app.view.page.figures import _fmt_eps

    text = _fmt_eps(2.641972 + 3.2e-23j, (0.5656, 0.5656))
    assert text.startswith("eps' = 2.64 ± 0.57 (95 %: 1.53 .. 3.75)"), text
    assert "e-" not in text
