"""The survey commands as a user meets them: Ctrl-C, reruns, refusals, `info` of a store,
the mosaic's file and picture. Each failure a user reported has a test showing its fix."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

import holoradar as hr
from holoradar.app.cli import main
from holoradar.survey import store as survey_store

F0 = 9.9e9
PITCH = 0.01


def run(*args: object, ok: bool = True):
    res = CliRunner().invoke(main, [str(a) for a in args])
    if ok:
        assert res.exit_code == 0, res.output
    return res


def _frames(folder: Path, n: int, size: int = 8) -> list[Path]:
    rng = np.random.default_rng(1)
    x = (np.arange(size) - (size - 1) / 2) * PITCH
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for i in range(n):
        data = rng.standard_normal((size, size)) + 1j * rng.standard_normal((size, size))
        h = hr.Hologram(data, x, x, F0, pose=hr.Pose((0.04 * i, 0.0, 0.0)))
        out.append(hr.save(h, folder / f"f{i:03d}.nc"))
    return out


@pytest.fixture(scope="module")
def survey(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Five frames, a truncated one and a text file posing as NetCDF."""
    d = tmp_path_factory.mktemp("frames")
    paths = _frames(d, 5)
    blob = paths[0].read_bytes()
    (d / "g_truncated.nc").write_bytes(blob[: len(blob) // 2])
    (d / "h_text.nc").write_text("not a NetCDF file, only words " * 4)
    return sorted(d.glob("*.nc"))


@pytest.mark.parametrize("workers", ["1", pytest.param("2", marks=pytest.mark.slow)])
def test_ctrl_c_during_batch_is_one_line_and_exit_130(tmp_path: Path, workers: str) -> None:
    """SIGINT to the process group, as a terminal's Ctrl-C sends it (the workers of a
    local cluster included): one line saying how many frames are stored (the store's
    own count) and that a rerun resumes; exit code 130; no traceback."""
    # 200 copies of one frame, a tenth of a second or more each: many seconds of work,
    # interrupted once two are stored (where the frames lie does not matter here).
    one = _frames(tmp_path / "one", 1, size=16)[0]
    (tmp_path / "s").mkdir()
    frames = [shutil.copyfile(one, tmp_path / "s" / f"f{i:03d}.nc") for i in range(200)]
    store = tmp_path / "s.zarr"
    args = ["batch", str(tmp_path / "s" / "*.nc"), "-o", str(store), "--z", "0.05:0.35:0.01",
            "--upsample", "8", "--workers", workers]
    # A process started from a shell without job control ignores SIGINT, and its
    # children inherit that: give the command line Python's usual handler back.
    code = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
            "from holoradar.app.cli import main; main(sys.argv[1:], prog_name='holoradar')")
    proc = subprocess.Popen([sys.executable, "-c", code, *args], start_new_session=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None:
            if survey_store.is_survey(store) and \
                    survey_store.read_index(store)["done"].sum() >= 2:
                break
            time.sleep(0.01)
        os.killpg(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    stored = int(survey_store.read_index(store)["done"].sum())
    assert 2 <= stored < len(frames)
    assert lines[0] == (f"interrupted: {stored} of {len(frames)} frames are stored in {store}; "
                        "run the same command again to resume")
    assert out.startswith(f"imaging {len(frames)} frames into {store}: up to ")
    # Consistent: the frames marked done hold their images, the others none (a rerun
    # images those: tested with the library in test_survey.py).
    # Read where a write could have gone astray: the chunks holding a done frame, and
    # the first chunk after them (the whole store's images would be 1.4 GB of NaN).
    done = survey_store.read_index(store)["done"]
    image = hr.survey.open_survey(store)["image"]
    per = image.data.chunksize[0]
    chunks = np.unique(np.flatnonzero(done) // per)
    look = np.flatnonzero(np.isin(np.arange(done.size) // per,
                                  np.append(chunks, chunks.max() + 1)))
    images = image[look].values
    assert not np.isnan(images[done[look]]).any() and np.isnan(images[~done[look]]).all()


def test_ctrl_c_in_any_command_is_one_line_and_exit_130(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    import holoradar.imaging.autofocus as af
    import holoradar.model.simulate as sim

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    scene = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "sand_box.toml"
    holo = hr.save(hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))]),
                               hr.Aperture.grid(16, PITCH), F0), tmp_path / "h.nc")
    monkeypatch.setattr(sim, "simulate", interrupted)
    monkeypatch.setattr(af, "autofocus", interrupted)
    for args in (["simulate", scene, "-o", tmp_path / "x.nc"],
                 ["autofocus", holo, "--z-surface", "0.1"]):
        res = run(*args, ok=False)
        assert res.exit_code == 130, res.output
        assert res.output.strip().splitlines() == [
            "interrupted: stopped before the end (outputs are written whole or not at all)"]
    res = run("simulate", scene, "-o", tmp_path / "x.nc", "--json", ok=False)
    assert res.exit_code == 130
    assert json.loads(res.stdout)["exit_code"] == 130
    assert not (tmp_path / "x.nc").exists()


def test_batch_messages_a_user_reported(survey: list[Path], tmp_path: Path,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """The size said before starting; a no-op rerun says so (no 'wrote'); a settings
    mismatch names --force, not the library's overwrite=True, without float noise; a
    skipped frame's reason is cut at a word; no progress bar into a file."""
    import holoradar.survey as survey_pkg

    calls = []
    real = survey_pkg.run_batch

    def spy(*args: object, **kwargs: object) -> dict:
        calls.append(kwargs)
        return real(*args, **kwargs)

    monkeypatch.setattr(survey_pkg, "run_batch", spy)
    store = tmp_path / "s.zarr"
    pattern = str(survey[0].parent / "*.nc")
    args = ["batch", pattern, "-o", store, "--z", "0.1:0.18:0.01", "--scheduler",
            "synchronous"]
    res = run(*args)
    assert calls[-1]["progress"] is False  # CliRunner's stderr is no terminal
    per = 9 * 8 * 8 * 2 * 8  # 9 planes of 8 x 8 pixels, I and Q as float64
    assert f"imaging 7 frames into {store}: up to {7 * per / 1e3:.0f} kB ({per / 1e3:.3g} kB " \
        "a frame before compression)" in res.stdout
    text = next(ln for ln in res.output.splitlines() if "h_text.nc" in ln)
    # a text file posing as NetCDF: said in words, not xarray's list of engines
    assert "is not a NetCDF file (it is text)" in text and "engine" not in text

    res = run(*args)  # the two bad frames are tried again, and skipped again
    assert res.output.strip().splitlines()[-1] == \
        f"nothing imaged: 5 frames already stored in {store}, 2 skipped"
    assert "wrote" not in res.output
    res = run("batch", *survey[:5], *args[2:])
    assert res.output.strip() == f"nothing to do: 5 frames already stored in {store}"

    res = run("batch", pattern, "-o", store, "--z", "0.1:0.14:0.02", "--scheduler",
              "synchronous", ok=False)
    assert res.exit_code == 2
    assert res.output.strip() == (
        f"error: {store} was made with other settings (z: the store has 9 planes "
        "0.1..0.18 (step 0.01) m, this run asks [0.1, 0.12, 0.14] m): pass --force to "
        "start it again (its frames are removed), or choose another store")
    # The library keeps its own word, and its numbers read plainly too.
    with pytest.raises(hr.survey.SettingsMismatchError, match=r"overwrite=True") as err:
        hr.survey.run_batch(survey[:5], store, z=np.arange(0.1, 0.1501, 0.01),
                            scheduler="synchronous")
    assert err.value.differences == ["z: the store has 9 planes 0.1..0.18 (step 0.01) m, "
                                     "this run asks [0.1, 0.11, 0.12, 0.13, 0.14, 0.15] m"]


def test_info_describes_a_survey_store(survey: list[Path], tmp_path: Path) -> None:
    store = tmp_path / "s.zarr"
    hr.survey.run_batch([*survey, tmp_path / "gone.nc"], store, z=[0.3, 0.4], upsample=2,
                        scheduler="synchronous")
    res = run("info", store)
    lines = res.output.splitlines()
    assert lines[0].startswith("s.zarr: a holoradar survey store (")
    rows = {ln[2:18].strip(): ln[19:] for ln in lines[1:] if ln.startswith("  ") and
            not ln.startswith("  not stored") and not ln.startswith("  damaged")}
    assert rows["frames"] == "5 stored of 8"
    assert rows["planes z (m)"] == "0.3 .. 0.4 (2, step 0.1)"
    assert rows["frame grid"] == "8 x 8 elements, pitch 10 x 10 mm, receiver array"
    assert rows["image"].startswith("15 x 15 pixels a plane, step 5 x 5 mm (upsample 2)")
    assert rows["ground"] == "free space" and rows["method"] == "angular"
    missing = [ln for ln in lines if ln.startswith("  not stored: ")]
    assert [ln.split(":")[1].strip() for ln in missing] == ["g_truncated.nc", "h_text.nc",
                                                            "gone.nc"]
    assert missing[2].endswith("is not a file")
    # A done frame whose image chunk went missing is named as damaged.
    idx = survey_store.read_index(store)
    slot = int(np.nonzero(idx["done"])[0][1])
    (store / "image" / "c" / str(slot) / "0" / "0" / "0" / "0").unlink()
    res = run("info", store, "--json", ok=False)
    assert res.exit_code == 2 and idx["frame_name"][slot] in res.stderr
    d = json.loads(res.stdout)
    assert d["frames_stored"] == 5 and d["frames_expected"] == 8
    assert d["damaged"] == [{"name": idx["frame_name"][slot], "path": idx["frame_path"][slot],
                             "reason": "marked done but its image chunk is missing"}]
    # A folder that is not a store: one line, exit code 2.
    res = run("info", survey[0].parent, ok=False)
    assert res.exit_code == 2 and res.output.count("\n") == 1
    assert "is a folder that is not a holoradar survey store" in res.output


def test_mosaic_file_is_an_amplitude_and_one_panel_says_so(survey: list[Path],
                                                           tmp_path: Path) -> None:
    from holoradar.app import plotting

    store = tmp_path / "s.zarr"
    hr.survey.run_batch(survey[:3], store, z=[0.3], scheduler="synchronous")
    run("mosaic", store, "--range", "0.3", "-o", tmp_path / "map.nc")
    with h5py.File(tmp_path / "map.nc") as f:
        assert f["image"].dtype == np.float64 and "iq" not in f
    m = hr.load(tmp_path / "map.nc")
    assert m.data.dtype == np.float64
    np.testing.assert_array_equal(m.data, hr.survey.mosaic(store, 0.3).data)
    fig = plotting.plot_planes(m, [0.3])
    assert [a.get_ylabel() for a in fig.axes[1:]] == ["|E| / max"]
    fig = plotting.plot_planes(hr.migrate(hr.load(survey[0]), [0.3, 0.4]), [0.3, 0.4])
    assert [a.get_ylabel() for a in fig.axes[2:]] == ["|E| / max (all panels)"]


@pytest.mark.parametrize("damage", ["truncate", "remove", "flip"])
def test_every_command_names_a_damaged_frame_with_exit_2(survey: list[Path], tmp_path: Path,
                                                         damage: str) -> None:
    """A frame's image chunk truncated, missing or with a flipped bit: mosaic, detect (on
    the frames' holograms, or one plane of the images), report and info answer with the
    frame's name and exit code 2 (no crash in the decompressor, no blank hole)."""
    store = tmp_path / "s.zarr"
    hr.survey.run_batch(survey[:3], store, z=[0.3], scheduler="synchronous")
    idx = survey_store.read_index(store)
    slot = int(np.nonzero(idx["done"])[0][1])
    name = str(idx["frame_name"][slot])
    chunk = store / "image" / "c" / str(slot) / "0" / "0" / "0" / "0"
    blob = bytearray(chunk.read_bytes())
    if damage == "remove":
        chunk.unlink()
    elif damage == "truncate":
        chunk.write_bytes(bytes(blob[: len(blob) // 2]))
    else:
        blob[len(blob) // 2] ^= 0x10
        chunk.write_bytes(bytes(blob))
    for args in (("mosaic", store, "--range", "0.3", "-o", tmp_path / "map.nc"),
                 ("detect", store), ("detect", store, "--z", "0.3"),
                 ("report", store, "-o", tmp_path / "r.html"), ("info", store)):
        res = run(*args, ok=False)
        assert res.exit_code == 2, (args[0], res.output)
        assert name in res.output and "Traceback" not in res.output, (args[0], res.output)
    assert not (tmp_path / "map.nc").exists() and not (tmp_path / "r.html").exists()
    # A rerun of the batch images the damaged frame again: every command reads it.
    hr.survey.run_batch(survey[:3], store, z=[0.3], scheduler="synchronous")
    run("mosaic", store, "--range", "0.3", "-o", tmp_path / "map.nc")
    run("info", store)
