"""The command line a new user meets: each failure a user reported has a test showing its fix;
every command has --help and --json; user mistakes are one line and exit code 2."""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import numpy as np
import pytest
import scipy.io

import holoradar as hr
from cli_helpers import one_line_error, run
from holoradar.app.cli import main

REPO = Path(__file__).resolve().parents[1]
F = 9.9e9
SCENE = REPO / "examples" / "scenes" / "sand_box.toml"






@pytest.fixture(scope="module")
def holo_nc(tmp_path_factory):
    d = tmp_path_factory.mktemp("scene")
    out = d / "holo.nc"
    run("simulate", SCENE, "-o", out, "--quiet")
    return out


def _point_hologram() -> hr.Hologram:
    scene = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))])
    return hr.simulate(scene, hr.Aperture.grid(32, 0.01), F)


def _leaves(group, path=()):
    for name, cmd in group.commands.items():
        if hasattr(cmd, "commands"):
            assert run(*path, name, "--help").exit_code == 0
            yield from _leaves(cmd, (*path, name))
        else:
            yield (*path, name)


def test_every_command_has_help_and_json(holo_nc, tmp_path):
    leaves = list(_leaves(main))
    assert len(leaves) >= 13
    for path in leaves:
        res = run(*path, "--help")
        assert "--json" in res.output and "--quiet" in res.output, path
    res = run("theory", "--json")
    assert json.loads(res.stdout)["wavelength_m"] == pytest.approx(hr.C0 / F, rel=1e-12)
    res = run("info", holo_nc, "--json")
    assert json.loads(res.stdout)["readable_as"]["kind"] == "Hologram"
    res = run("image", holo_nc, "--z", "0.42", "--eps", "2.5", "--tan-delta", "0.005",
              "--z-surface", "0.3", "-o", tmp_path / "i.nc", "--json")
    assert json.loads(res.stdout)["out"] == str(tmp_path / "i.nc")
    res = run("plot", tmp_path / "i.nc", "-o", tmp_path / "p.png", "--json")
    assert json.loads(res.stdout)["kind"] == "Image"
    # -q hides progress and narrative, never the result (warnings still go to stderr)
    res = run("image", holo_nc, "--z", "0.42", "-o", tmp_path / "q.nc", "--quiet")
    assert res.stdout == f"wrote {tmp_path / 'q.nc'}\nwrote {tmp_path / 'q.png'}\n"
    res = run("simulate", SCENE, "-o", tmp_path / "q2.nc", "-q")
    assert res.stdout == f"wrote {tmp_path / 'q2.nc'}\n"
    res = run("theory", "-q")  # every line of theory is its answer
    assert res.stdout.count("\n") == 5 and "lateral resolution" in res.stdout


def test_scene_file_simulates_and_images_through_layers_and_loss(holo_nc, tmp_path):
    """simulate SCENE.toml -> image through the sand from flags, from --layers (the same
    sand split in two) and from a TOML medium file: the same focus."""
    h = hr.load(holo_nc)
    assert h.data.shape == (16, 16) and isinstance(h.source, hr.PointSource)
    steps = [s["step"] for s in hr.io.read_history(holo_nc)]
    assert steps == ["simulate", "save"]
    (tmp_path / "sand.toml").write_text("[ground]\nsurface = 0.30\neps = 2.5\n"
                                        "tan_delta = 0.005\n")
    peaks = []
    for k, ground in enumerate([["--eps", "2.5", "--tan-delta", "0.005", "--z-surface", "0.3"],
                                ["--layers", "0.30:2.5+0.0125j,0.40:2.5+0.0125j"],
                                ["--medium", tmp_path / "sand.toml"]]):
        res = run("image", holo_nc, "--z", "0.40:0.46:0.005", *ground, "-o",
                  tmp_path / f"img{k}.nc", "--json", "--no-png")
        peaks.append(json.loads(res.stdout)["peak_m"])
    # The same ground three ways: the same image. A ground split in two identical layers
    # differs from the half-space only by rounding (an interface between equal media
    # transmits 1 exactly in theory), so the interpolated peaks agree to 1e-9 m.
    assert peaks[1] == pytest.approx(peaks[0], abs=1e-9) and peaks[2] == peaks[0]
    # The scene's stronger target (-5, 0) cm 12 cm deep: within a pixel laterally.
    assert abs(peaks[0][0] + 0.05) <= 0.025 / 4 and abs(peaks[0][1]) <= 0.025 / 4
    # --sigma adds i*sigma/(omega eps0): 0.0069 S/m at 9.9 GHz is Im(eps) 0.0125, the
    # same ground as tan_delta 0.005 with eps' 2.5, so again the same peak.
    res = run("image", holo_nc, "--z", "0.40:0.46:0.005", "--eps", "2.5", "--sigma",
              str(0.0125 * 2 * np.pi * F * 8.8541878128e-12), "--z-surface", "0.3", "-o",
              tmp_path / "s.nc", "--json", "--no-png")
    assert json.loads(res.stdout)["peak_m"] == pytest.approx(peaks[0], abs=1e-9)


def test_scene_file_errors_name_the_key(tmp_path):
    bad = tmp_path / "bad.toml"
    for text, needle in [
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = -1\n", "aperture.pitch must be > 0"),
        ("frequency = 9.9\n[aperture]\nn = 16\npitch = 0.02\n", "below 100 MHz: given in GHz"),
        ("frequency = 9.9e9\n[aperture]\nn = 'x'\npitch = 0.02\n", "aperture.n must be an "
                                                                  "integer"),
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 0.02\n[ground]\nsurface = 0.3\n"
         "eps = -4\n", "negative real part"),
        # judged as given: with a loss tangent it said "Im(eps) >= 0 ... (-2.5-0.0125j)"
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 0.02\n[ground]\nsurface = 0.3\n"
         "eps = -2.5\ntan_delta = 0.005\n", "bad.ground.eps = -2.5 has a negative real part"),
        # ranges in centimetres: 42 m and 30 m in front of a 40 cm array focus nothing
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 0.025\n[[target]]\n"
         "position = [0, 0, 42]\n", "bad.target[0].position at range 42 m in front of a 0.4 m"),
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 0.025\n[ground]\nsurface = 30\n"
         "eps = 2.5\n", "bad.ground.surface at range 30 m"),
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 0.02\ncolour = 1\n",
         "unknown key(s) ['colour']"),
        ("frequency = 9.9e9\n[[target]]\nposition = [0, 0]\n", "missing table [aperture]"),
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 0.02\n[[target]]\nposition = [0, 0]\n",
         "target[0].position must be a list of 3 numbers"),
        ("frequency = [", "not valid TOML"),
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 25\n", "millimetres or centimetres"),
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 0.02\n[source]\ntype = 'gaussian'\n"
         "waist = 1e-300\n", "quarter wavelength"),
        ("frequency = 9.9e9\n[aperture]\nn = 16\npitch = 0.02\n[[target]]\ntype = 'shape'\n"
         "shape = 'disk'\nz = 0.4\nradius = 0.02\n", "takes the sizes ['diameter']"),
    ]:
        bad.write_text(text)
        res = run("simulate", bad, "-o", tmp_path / "h.nc", ok=False)
        one_line_error(res, needle)
        assert not (tmp_path / "h.nc").exists()


def test_reported_failures_are_fixed(tmp_path):
    """Each failure of the first report, as a new user met it, and what happens now."""
    h = _point_hologram()
    # A .npy crashed with a TypeError: now it reads, given its coordinates.
    np.save(tmp_path / "a.npy", h.data)
    one_line_error(run("image", tmp_path / "a.npy", "--z", "0.3", "-o", tmp_path / "a.nc",
                       ok=False), "no frequency found")
    run("image", tmp_path / "a.npy", "--z", "0.3", "-o", tmp_path / "a.nc", "--layout",
        "pitch=0.01,frequency=9.9e9", "-q")
    # .csv, .mat, .h5 got numpy's advice to load 'unsafely': now they are read.
    scipy.io.savemat(tmp_path / "b.mat", {"data": h.data, "x": h.x, "y": h.y, "frequency": F})
    res = run("image", tmp_path / "b.mat", "--z", "0.3", "-o", tmp_path / "b.nc", "--json")
    assert abs(json.loads(res.stdout)["peak_m"][2] - 0.3) < 0.01
    # Empty and truncated files gave tracebacks or 'Aborted!': now one line, exit 2.
    (tmp_path / "e.npz").write_bytes(b"")
    one_line_error(run("image", tmp_path / "e.npz", "--z", "0.3", "-o", tmp_path / "e.nc",
                       ok=False), "is empty")
    np.savez(tmp_path / "t.npz", data=h.data, x=h.x, y=h.y, frequency=F)
    blob = (tmp_path / "t.npz").read_bytes()
    (tmp_path / "t.npz").write_bytes(blob[: len(blob) // 2])
    one_line_error(run("image", tmp_path / "t.npz", "--z", "0.3", "-o", tmp_path / "t.nc",
                       ok=False), "t.npz")
    # Millimetres and GHz produced a confident wrong image with exit code 0.
    np.savez(tmp_path / "mm.npz", data=h.data, x=h.x * 1e3, y=h.y * 1e3, frequency=F)
    one_line_error(run("image", tmp_path / "mm.npz", "--z", "0.3", "-o", tmp_path / "m.nc",
                       ok=False), "millimetres", "length_unit=mm")
    np.savez(tmp_path / "ghz.npz", data=h.data, x=h.x, y=h.y, frequency=9.9)
    one_line_error(run("image", tmp_path / "ghz.npz", "--z", "0.3", "-o", tmp_path / "g.nc",
                       ok=False), "GHz")
    # --out img.png overwrote the image it had just written: the image must be .nc/.npz.
    one_line_error(run("image", tmp_path / "b.mat", "--z", "0.3", "-o", tmp_path / "i.png",
                       ok=False), "must end in")
    # --out equal to the input replaced the hologram with the image.
    before = (tmp_path / "b.nc").read_bytes()
    one_line_error(run("image", tmp_path / "b.nc", "--z", "0.3", "-o", tmp_path / "b.nc",
                       ok=False), "one of the inputs")
    assert (tmp_path / "b.nc").read_bytes() == before
    # A missing output folder failed only after the computation: now before it.
    one_line_error(run("image", tmp_path / "b.mat", "--z", "0.3", "-o",
                       tmp_path / "nowhere" / "i.nc", ok=False), "does not exist")
    # --z 0.3:0.6:0 raised ZeroDivisionError; theory --frequency 0 a traceback.
    one_line_error(run("image", tmp_path / "b.mat", "--z", "0.3:0.6:0", "-o",
                       tmp_path / "z.nc", ok=False), "step > 0")
    one_line_error(run("theory", "--frequency", "0", ok=False), "--frequency")
    # Nothing was written by any failure above.
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "a.nc", "a.npy", "a.png", "b.mat", "b.nc", "b.png", "e.npz", "ghz.npz", "mm.npz",
        "t.npz"]


def test_json_errors_are_json_too(tmp_path):
    """A program calling holoradar --json gets an error as JSON on stdout as well."""
    res = run("image", tmp_path / "none.nc", "--z", "0.3", "-o", tmp_path / "i.nc", "--json",
              ok=False)
    assert res.exit_code == 2
    doc = json.loads(res.stdout)
    assert doc["exit_code"] == 2 and "does not exist" in doc["error"]


def test_outputs_get_the_users_umask(tmp_path):
    """Every output file was created 0600: now 0666 less the umask, like any file."""
    h = _point_hologram()
    src = hr.save(h, tmp_path / "h.nc")
    old = os.umask(0o022)
    try:
        run("image", src, "--z", "0.3", "-o", tmp_path / "i.nc", "-q")
        run("plot", tmp_path / "i.nc", "-o", tmp_path / "p.png", "-q")
    finally:
        os.umask(old)
    for name in ("i.nc", "i.png", "p.png"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o644, name


def test_suppress_and_synthesize_from_the_command_line(tmp_path):
    """The glare of a horn over sand removed by the CLI; three plane-wave views
    synthesised by the CLI focus where the library's synthesis does."""
    sand = hr.Medium.half_space(0.3, 2.5)
    horn = hr.PointSource((0.0, 0.0, -0.05))
    scene = hr.Scene(sand, horn, [hr.PointTarget((0.05, 0.0, 0.42), 0.01)])
    h = hr.simulate(scene, hr.Aperture.grid(32, 0.0125), F)
    src = hr.save(h, tmp_path / "glare.nc")
    res = run("suppress", src, "--eps", "2.5", "--z-surface", "0.3", "-o", tmp_path / "c.nc",
              "--json")
    s = json.loads(res.stdout)
    clean, rep = hr.suppress_surface(h, sand)
    # The CLI runs the same library call: the same numbers, exactly.
    assert s["glare_suppression_db"] == rep.glare_suppression_db
    assert np.array_equal(hr.load(tmp_path / "c.nc").data, clean.data)
    one_line_error(run("suppress", src, "-o", tmp_path / "d.nc", ok=False), "needs a ground")
    ap = hr.Aperture.grid(25, 0.015)
    files, views = [], []
    for a in (-20, 0, 20):
        v = hr.simulate(hr.Scene(source=hr.PlaneWave(np.radians(a), 0.0),
                                 targets=[hr.PointTarget((0.0, 0.0, 0.5))]), ap, F)
        views.append(v)
        # written without their source, as a user's file would be
        np.savez(tmp_path / f"v{a}.npz", data=v.data, x=v.x, y=v.y, frequency=F)
        files.append(tmp_path / f"v{a}.npz")
    one_line_error(run("synthesize", *files, "--z", "0.5", "-o", tmp_path / "s.nc",
                       ok=False), "no source")
    res = run("synthesize", *files, "--z", "0.5", "--plane-wave", "-20,0", "--plane-wave",
              "0,0", "--plane-wave", "20,0", "-o", tmp_path / "s.nc", "--json")
    # --upsample auto: the cell lambda L / A = 3.03 cm x 0.5 / 0.36 = 4.2 cm, a quarter
    # of it 1.05 cm, finer than the 1.5 cm pitch: 2 pixels per pitch
    ref = hr.synthesize(views, 0.5, upsample=2)
    assert np.array_equal(hr.load(tmp_path / "s.nc").data, ref.data)
    assert json.loads(res.stdout)["views"] == 3


def test_info_lists_what_a_users_file_holds(tmp_path):
    np.savez(tmp_path / "u.npz", E_scat=np.ones((3, 4, 4), complex), x_pos=np.arange(4.0))
    res = run("info", tmp_path / "u.npz")
    assert "E_scat" in res.output and "(3, 4, 4)" in res.output
    assert "not readable as a hologram yet" in res.output and "data=E_scat[1]" in res.output


def test_calibrate_fit_and_apply_from_files_equal_the_library(tmp_path):
    """A faulty device's raw references and survey as users' files: the CLI's calibration
    and calibrated hologram equal the library's exactly; another device is refused."""
    from holoradar import calibrate as cb

    x = (np.arange(8) - 3.5) * 0.025
    f = np.array([9.5e9, 9.9e9])
    horn = hr.PointSource((0.0, -0.25, -0.05), pattern_exponent=2, axis=(0.0, 0.5, 1.0))
    rng = np.random.default_rng(3)
    dev = cb.DeviceFaults(dc_i=0.1, dc_q=-0.05, iq_gain=1.1, iq_phase=np.radians(6),
                          element_gain=np.exp(2j * np.pi * rng.random((8, 8))),
                          response=np.array([1.0, 0.8j]), conjugate=True, noise=1e-3)

    def write(raw, name):
        np.savez(tmp_path / name, I=raw.i, Q=raw.q, x=x, y=x, frequency=f)
        return tmp_path / name

    refs, files = [], []
    for j, z in enumerate((0.300, 0.304)):
        field = hr.Hologram(cb.reference_field("plate", x, x, f, horn, plate_range=z), x, x, f,
                            source=horn)
        raw = dev.record(field, "HSR-7", repeats=4, seed=j)
        refs.append(cb.Reference(raw, "plate", plate_range=z))
        files.append(write(raw, f"plate{j}.npz"))
    dark = dev.record(hr.Hologram(np.zeros((2, 8, 8)), x, x, f), "HSR-7", repeats=16,
                      transmitter=False, seed=9)
    write(dark, "dark.npz")
    scene = hr.Scene(source=horn, targets=[hr.PointTarget((0.02, 0.0, 0.4), 0.05)])
    survey = dev.record(hr.simulate(scene, hr.Aperture.grid(8, 0.025), f), "HSR-7", seed=5)
    write(survey, "survey.npz")
    # The repeats' axis is a frame axis: declared with the letter t.
    res = run("calibrate", "fit", "--device", "HSR-7", "--plate", files[0], "0.300", "--plate",
              files[1], "0.304", "--dark", tmp_path / "dark.npz", "--horn", "0,-0.25,-0.05",
              "--horn-axis", "0,0.5,1", "--pattern", "2", "--layout", "axes=tfyx", "-o",
              tmp_path / "HSR-7.nc", "--json")
    assert json.loads(res.stdout)["iq_sign"] == "I-iQ"
    ref_cal = cb.fit_calibration(refs, dark=dark, notes="x")
    cal = cb.Calibration.load(tmp_path / "HSR-7.nc")
    assert np.array_equal(cal.total_gain, ref_cal.total_gain)
    run("calibrate", "apply", tmp_path / "survey.npz", "--calibration", tmp_path / "HSR-7.nc",
        "--device", "HSR-7", "-o", tmp_path / "holo.nc", "-q")
    assert np.array_equal(hr.load(tmp_path / "holo.nc").data, ref_cal.apply(survey).data)
    one_line_error(run("calibrate", "apply", tmp_path / "survey.npz", "--calibration",
                       tmp_path / "HSR-7.nc", "--device", "HSR-8", "-o",
                       tmp_path / "other.nc", ok=False), "HSR-8")
    assert not (tmp_path / "other.nc").exists()


def test_batch_and_mosaic_from_the_command_line(tmp_path):
    """Frames placed by their pose imaged into a store; a truncated frame is reported by
    name and skipped (or fails the run with --strict); a rerun resumes; the mosaic puts
    the stone where it is."""
    scene = hr.Scene(targets=[hr.PointTarget((0.12, 0.0, 0.3), 0.05)])
    (tmp_path / "s").mkdir()
    for k, x0 in enumerate((0.0, 0.1, 0.2)):
        ap = hr.Aperture.grid(12, 0.01, pose=hr.Pose((x0, 0.0, 0.0)))
        hr.save(hr.simulate(scene, ap, F), tmp_path / "s" / f"f{k}.nc")
    blob = (tmp_path / "s" / "f0.nc").read_bytes()
    (tmp_path / "s" / "f3.nc").write_bytes(blob[: len(blob) // 2])
    pattern = str(tmp_path / "s" / "*.nc")
    store = tmp_path / "survey.zarr"
    res = run("batch", pattern, "-o", store, "--z", "0.3", "--upsample", "2", "--strict",
              "--scheduler", "synchronous", ok=False)
    one_line_error(res, "f3.nc")
    res = run("batch", pattern, "-o", store, "--z", "0.3", "--upsample", "2", "--scheduler",
              "synchronous", "--json")
    s = json.loads(res.stdout)
    # the strict run kept the frames it had finished: this run resumes after them
    assert s["done"] + s["resumed"] == 3
    assert [Path(k["name"]).name for k in s["skipped"]] == ["f3.nc"]  # named as given
    assert "warning: skipped " in res.output and "f3.nc" in res.output
    res = run("batch", pattern, "-o", store, "--z", "0.3", "--upsample", "2", "--scheduler",
              "synchronous", "--json")
    assert json.loads(res.stdout)["resumed"] == 3
    one_line_error(run("batch", pattern, "-o", store, "--z", "0.35", "--scheduler",
                       "synchronous", ok=False), "other settings")
    res = run("mosaic", store, "--range", "0.3", "-o", tmp_path / "map.nc", "--json")
    peak = json.loads(res.stdout)["peak_m"]
    # The stone at x = 0.12 m: within one map pixel (pitch / upsample = 5 mm).
    assert abs(peak[0] - 0.12) <= 0.005 and abs(peak[1]) <= 0.005
    run("mosaic", store, "--range", "0.3", "-o", tmp_path / "map.png", "-q")
    # A range outside the stored planes took the nearest plane without a word.
    one_line_error(run("mosaic", store, "--range", "30", "-o", tmp_path / "m30.png", ok=False),
                   "--range", "30 m is outside the stored planes 0.3 m", "centimetres",
                   "--range 0.3")
    # A depth is below the surface: with --z-surface it names the same plane; alone it
    # is refused with the way out (the option was a range under a depth's name).
    run("mosaic", store, "--depth", "0.1", "--z-surface", "0.2", "-o", tmp_path / "md.nc")
    one_line_error(run("mosaic", store, "--depth", "0.3", "-o", tmp_path / "mx.png", ok=False),
                   "--depth", "--z-surface", "--range")
    one_line_error(run("mosaic", store, "--range", "0.80", "-o", tmp_path / "m80.png",
                       ok=False), "0.8 m is outside the stored planes 0.3 m")
    res = run("mosaic", store, "--range", "0.3", "--z-surface", "0.4", "-o",
              tmp_path / "m40.png", "-q")
    assert "warning: --z-surface 0.4 m lies beyond the mapped plane" in res.output
    # Ranges against the frames' array (12 x 1 cm at 9.9 GHz: nothing focuses beyond 0.48 m),
    # before any frame is imaged.
    one_line_error(run("batch", pattern, "-o", tmp_path / "cm.zarr", "--z", "30",
                       "--scheduler", "synchronous", ok=False), "--z", "centimetres",
                   "--z 0.3")
    assert not (tmp_path / "cm.zarr").exists()
    assert not list(tmp_path.glob("m[38]0.png"))


def test_calibrate_apply_reads_the_device_the_file_records(tmp_path):
    """A raw file that records its device: another --device is refused, none needed."""
    from holoradar import calibrate as cb

    x = (np.arange(4) - 1.5) * 0.025
    cal = cb.Calibration("HSR-7", x, x, F, iq_sign="I+iQ", response=[1.0],
                         gains=np.ones((4, 4)))
    cal.save(tmp_path / "cal.nc")
    np.savez(tmp_path / "raw.npz", I=np.ones((4, 4)), Q=np.zeros((4, 4)), x=x, y=x,
             frequency=F, device=np.array("HSR-7"))
    run("calibrate", "apply", tmp_path / "raw.npz", "--calibration", tmp_path / "cal.nc",
        "-o", tmp_path / "h.nc", "-q")
    one_line_error(run("calibrate", "apply", tmp_path / "raw.npz", "--calibration",
                       tmp_path / "cal.nc", "--device", "HSR-8", "-o", tmp_path / "g.nc",
                       ok=False), "recorded by device 'HSR-7', not 'HSR-8'")
    np.savez(tmp_path / "anon.npz", I=np.ones((4, 4)), Q=np.zeros((4, 4)), x=x, y=x,
             frequency=F)
    one_line_error(run("calibrate", "apply", tmp_path / "anon.npz", "--calibration",
                       tmp_path / "cal.nc", "-o", tmp_path / "g.nc", ok=False), "--device")
    assert not (tmp_path / "g.nc").exists()


def test_autofocus_from_the_command_line_equals_the_library(tmp_path):
    truth = hr.Medium.half_space(0.30, 4.0 * (1 + 0.005j))
    scene = hr.Scene(truth, hr.PlaneWave(), [hr.PointTarget((0.01, -0.02, 0.38))])
    h = hr.simulate(scene, hr.Aperture.paper(), F, include_surface=False, snr_db=40, seed=0)
    hr.save(h, tmp_path / "h.nc")
    res = run("autofocus", tmp_path / "h.nc", "--z-surface", "0.30", "--tan-delta", "0.005",
              "--plot", tmp_path / "f.png", "--json")
    got = json.loads(res.stdout)
    lib = hr.autofocus(h, medium_model=hr.Medium.half_space(0.30, 3.0 * (1 + 0.005j)))
    assert got["eps"] == pytest.approx(lib.eps, rel=1e-9)
    assert got["eps_interval"] == pytest.approx(list(lib.eps_interval), rel=1e-9)
    assert (tmp_path / "f.png").stat().st_size > 0
    one_line_error(run("autofocus", tmp_path / "h.nc", "--z-surface", "0.30", "--plot",
                       tmp_path / "f.png", ok=False), "--plot")  # exists: needs --force
    one_line_error(run("autofocus", tmp_path / "h.nc", ok=False), "--z-surface")
    one_line_error(run("autofocus", tmp_path / "h.nc", "--z-surface", "0.3", "--eps-range",
                       "3", ok=False), "--eps-range")
    one_line_error(run("autofocus", tmp_path / "h.nc", "--layers", "0.3:3,0.4:5", ok=False),
                   "half-space")
    # Depths in centimetres: refused before the search, with the metres meant.
    one_line_error(run("autofocus", tmp_path / "h.nc", "--z-surface", "0.30", "--depth-range",
                       "2,20", ok=False), "--depth-range", "centimetres",
                   "--depth-range 0.02,0.2")
    # Noise only: "not determinable" is an answer (exit 0), with the reason.
    noise = np.random.default_rng(0).standard_normal((*h.shape, 2)) @ [1, 1j]
    hr.save(hr.Hologram(noise, h.x, h.y, F), tmp_path / "n.nc")
    res = run("autofocus", tmp_path / "n.nc", "--z-surface", "0.30", "--plot",
              tmp_path / "n.png")
    assert "not determinable" in res.stdout and "noise" in res.stdout
    assert "no plot" in res.stdout and not (tmp_path / "n.png").exists()
    # -q printed nothing, not even the answer: now the answer alone.
    res = run("autofocus", tmp_path / "n.nc", "--z-surface", "0.30", "-q")
    assert res.stdout.splitlines() == [res.stdout.splitlines()[0]]
    assert res.stdout.startswith("eps' not determinable")


def test_unit_slips_in_options_are_refused_before_any_work(holo_nc, tmp_path, monkeypatch):
    """Centimetres typed for metres ran a minute and imaged 35 m away with exit code 0, or
    imaged in air with the ground ignored: now refused like a file's unit slip, naming the
    option and the metres meant; planes above a plausible ground are imaged with a warning."""
    out = tmp_path / "a.nc"
    one_line_error(run("image", holo_nc, "--z", "35:55:0.5", "--eps", "2.5", "--z-surface", "30",
                       "-o", out, ok=False),
                   "--z", "35..55 m in front of a 0.4 m array", "centimetres",
                   "--z 0.35:0.55:0.005")
    one_line_error(run("image", holo_nc, "--z", "0.42", "--eps", "2.5", "--z-surface", "30",
                       "-o", out, ok=False), "--z-surface", "centimetres", "--z-surface 0.3")
    one_line_error(run("image", holo_nc, "--z", "42", "-o", out, ok=False), "--z 0.42")
    one_line_error(run("image", holo_nc, "--z", "0.42", "--layers", "0.30:2.5,40:3", "-o", out,
                       ok=False), "--layers", "a layer top at 40 m", "centimetres")
    one_line_error(run("synthesize", holo_nc, "--z", "42", "-o", out, ok=False), "--z 0.42")
    one_line_error(run("suppress", holo_nc, "--eps", "2.5", "--z-surface", "30", "-o", out,
                       ok=False), "--z-surface 0.3")
    one_line_error(run("plan-oblique", "--target", "0,5,42", ok=False), "--target 0,0.05,0.42")
    one_line_error(run("plan-oblique", "--z-surface", "30", ok=False), "--z-surface 0.3")
    assert not list(tmp_path.iterdir())  # nothing written by a refusal
    # Every plane in the air above a plausible ground can be meant: imaged, with a warning.
    res = run("image", holo_nc, "--z", "0.10:0.25:0.05", "--eps", "2.5", "--z-surface", "0.3",
              "-o", out)
    assert ("warning: every plane of --z (0.1..0.25 m) lies above the ground surface at "
            "0.3 m") in res.output
    # --no-check takes a range as given (6 m, refused above; 42 m would image on a
    # 2048 x 2048 grid, the padding that samples the transfer function that far: 3 s).
    one_line_error(run("image", holo_nc, "--z", "6", "-o", tmp_path / "far.nc", ok=False),
                   "--z", "6 m in front of a 0.4 m array")
    run("image", holo_nc, "--z", "6", "-o", tmp_path / "far.nc", "--no-png", "--no-check")
    # plot labels depths with --z-surface: 30 for 30 cm is refused, beyond the planes warned
    one_line_error(run("plot", out, "-o", tmp_path / "p.png", "--z-surface", "30", ok=False),
                   "--z-surface 0.3")
    res = run("plot", out, "-o", tmp_path / "p.png", "--z-surface", "0.3")
    assert "warning: --z-surface 0.3 m lies beyond every plane" in res.output
    # view --depth: outside an image's planes, or beyond what the array can focus; refused
    # before the page is served.
    from holoradar.app.cli import view as view_cli

    def serve(*args, **kwargs):
        raise RuntimeError("served")

    monkeypatch.setattr(view_cli, "_serve", serve)
    one_line_error(run("view", out, "--depth", "15", "--no-browser", ok=False),
                   "--depth", "outside the image's planes 0.1..0.25 m", "--depth 0.15")
    one_line_error(run("view", holo_nc, "--eps", "2.5", "--z-surface", "0.3", "--depth", "12",
                       "--no-browser", ok=False),
                   "--depth", "a depth 12 m below the surface at 0.3 m", "--depth 0.12")


def test_a_permittivity_slip_reads_the_same_wherever_it_is_made(holo_nc, tmp_path):
    """eps = -2.5 in a scene file said 'Im(eps) >= 0 ... (-2.5-0.0125j)' (the loss tangent
    applied first), --eps -2.5 'negative real part': one check, one sentence."""
    sentence = "-2.5 has a negative real part: a sign slip?"
    scene = SCENE.read_text().replace("eps = 2.5", "eps = -2.5")
    (tmp_path / "neg.toml").write_text(scene)
    res = run("simulate", tmp_path / "neg.toml", "-o", tmp_path / "h.nc", ok=False)
    one_line_error(res, "neg.ground.eps = " + sentence)
    for ground, name in [(["--eps", "-2.5", "--tan-delta", "0.005", "--z-surface", "0.3"],
                          "--eps"),
                         (["--eps", "-2.5", "--z-surface", "0.3"], "--eps"),
                         (["--layers", "0.3:2.5,0.4:-2.5"], "--layers")]:
        res = run("image", holo_nc, "--z", "0.42", *ground, "-o", tmp_path / "i.nc", ok=False)
        one_line_error(res, f"Invalid value for {name}", sentence)
    with pytest.raises(ValueError, match="eps = " + sentence.replace("?", r"\?")):
        hr.Medium.half_space(0.3, -2.5)
    assert not (tmp_path / "h.nc").exists() and not (tmp_path / "i.nc").exists()


def test_info_shows_each_steps_parameters_and_refusals_name_force(holo_nc, tmp_path):
    """info showed step names only (parameters with --json alone); an existing output was
    refused with the API's 'overwrite=True'."""
    out = tmp_path / "i.nc"
    run("image", holo_nc, "--z", "0.40:0.44:0.02", "--eps", "2.5", "--z-surface", "0.3", "-o",
        out, "-q")
    text = run("info", out).output
    assert "input=sand_box.toml, scene=<" in text  # the scene's text is long: --json has it
    assert "input=holo.nc, z=0.40:0.44:0.02, method=angular, frame=aperture" in text
    assert "(--json shows every parameter whole)" in text
    for res in (run("image", holo_nc, "--z", "0.42", "-o", out, ok=False),):
        one_line_error(res, "--out", "exists: pass --force to replace it")
        assert "overwrite=True" not in res.output
    out.unlink()  # the PNG beside it is left: refused by its own name
    res = run("image", holo_nc, "--z", "0.42", "-o", out, ok=False)
    one_line_error(res, "--out's PNG", "exists: pass --force to replace it")
    assert "overwrite=True" not in res.output
    with pytest.raises(ValueError, match=r"exists: pass overwrite=True to replace it"):
        hr.save(hr.load(holo_nc), holo_nc)  # the API keeps the API's word


def test_image_says_a_large_output_and_refuses_what_the_disk_cannot_hold(holo_nc, tmp_path,
                                                                        monkeypatch):
    """The image's size is known before any work: planes x pixels x 8 bytes (I and Q as
    float32). Over ANNOUNCE_BYTES it is said; over the disk's free room it is refused,
    naming --out, and nothing is written."""
    import shutil
    from collections import namedtuple

    from holoradar.app.cli import image as image_cmd

    h = hr.load(holo_nc)
    ny, nx = h.data.shape[-2:]
    need = 3 * (2 * (ny - 1) + 1) * (2 * (nx - 1) + 1) * 8
    monkeypatch.setattr(image_cmd, "ANNOUNCE_BYTES", need - 1)
    res = run("image", holo_nc, "--z", "0.3:0.5:0.1", "--upsample", "2", "--no-png", "-o",
              tmp_path / "a.nc")
    from holoradar.survey.space import bytes_text

    assert f"the image will take {bytes_text(need)} (3 planes of" in res.output
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda p: usage(10**9, 10**9, need - 1))
    res = run("image", holo_nc, "--z", "0.3:0.5:0.1", "--upsample", "2", "--no-png", "-o",
              tmp_path / "b.nc", ok=False)
    one_line_error(res, "--out", "free")
    assert not (tmp_path / "b.nc").exists()


def test_suppress_says_eps_with_its_uncertainty_or_that_it_is_rough(tmp_path):
    """The exact glare fit's eps with its 1-sigma and 95 % interval (digits from the
    sigma, no rounding residue as eps''), with either method; the Gaussian fit's own
    eps in --json, marked rough."""
    run("demo", "--out", tmp_path / "d", "--upsample", "1", "--quiet")
    h = tmp_path / "d" / "hologram.nc"
    res = run("suppress", h, "--eps", "2.5", "--z-surface", "0.30", "--method", "image_source",
              "--no-direct", "-o", tmp_path / "a.nc")
    line = next(ln for ln in res.output.splitlines() if "permittivity" in ln)
    assert "+-" in line and "(95 %: " in line and "e-" not in line, line
    d = json.loads(run("suppress", h, "--eps", "2.5", "--z-surface", "0.30", "--method",
                       "image_source", "--no-direct", "-o", tmp_path / "b.nc",
                       "--json").stdout)
    lo, hi = d["eps_interval_95"]
    assert lo < d["eps"][0] < hi and d["eps_std"][0] > 0
    assert lo < 2.5 < hi   # the demo's sand
    # The default (Gaussian) method removes the glare; the eps it prints is the exact
    # fit's, with its interval, the Gaussian's own in --json as rough.
    d = json.loads(run("suppress", h, "--eps", "2.5", "--z-surface", "0.30", "--no-direct",
                       "-o", tmp_path / "c.nc", "--json").stdout)
    lo, hi = d["eps_interval_95"]
    assert lo < 2.5 < hi and d["eps_gaussian_rough"][0] > 1 and "exact" in d["eps_from"]
    res = run("suppress", h, "--eps", "2.5", "--z-surface", "0.30", "--no-direct",
              "-o", tmp_path / "e.nc")
    line = next(ln for ln in res.output.splitlines() if "permittivity" in ln)
    assert "exact glare fit" in line and "+-" in line and "e-" not in line, line
