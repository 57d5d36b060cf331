"""Surveys on Dask: many frames imaged with the same settings into one Zarr store.

Exactness: a frame's stored image must be bit for bit ``migrate(frame, ...)`` in
one process. The same float operations run in the same order on the same data
wherever the task runs (FFT threads split a batch of transforms, never one
transform), and I/Q are split and joined without arithmetic (the real and
imaginary parts are copied), so the tolerance is 0, not a rounding bound.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import holoradar as hr
from conftest import FUZZED, migrate64
from holoradar.survey import store as survey_store
from holoradar.survey import worker as survey_worker

F0 = 9.9e9
PITCH = 0.01          # < lambda/2 = 1.51 cm at 9.9 GHz: no aliasing warning
Z = [0.05, 0.1]       # two planes
N_CLUSTER = 20        # frames of the module's survey (the most a test uses)


def _frames(folder: Path, n: int, size: int = 8, seed: int = 0) -> tuple[list[Path], list]:
    """``n`` random frames of size x size, placed along x every half aperture."""
    rng = np.random.default_rng(seed)
    x = (np.arange(size) - (size - 1) / 2) * PITCH
    folder.mkdir(parents=True, exist_ok=True)
    paths, holos = [], []
    for i in range(n):
        data = rng.standard_normal((size, size)) + 1j * rng.standard_normal((size, size))
        h = hr.Hologram(data, x, x, F0, pose=hr.Pose((0.04 * i, 0.01 * (i % 3), 0.0)))
        paths.append(hr.save(h, folder / f"frame{i:03d}.nc"))
        holos.append(h)
    return paths, holos


@pytest.fixture(scope="module")
def survey_frames(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[Path], list]:
    return _frames(tmp_path_factory.mktemp("frames"), N_CLUSTER)


def _stored(store: Path) -> dict:
    idx = survey_store.read_index(store)
    return {"idx": idx, "images": survey_store.read_images(idx, range(idx["n"]))}


def _assert_exact(store: Path, paths: list[Path], holos: list, **kw) -> np.ndarray:
    """Every frame marked done equals the single-process migrate bit for bit; the done mask."""
    s = _stored(store)
    idx = s["idx"]
    by_path = {str(p.resolve()): h for p, h in zip(paths, holos, strict=True)}
    for i in np.nonzero(idx["done"])[0]:
        h = by_path[idx["frame_path"][i]]
        ref = migrate64(h, Z, **kw).data
        assert np.array_equal(s["images"][i], ref), f"frame {idx['frame_name'][i]} differs"
        assert idx["frame_x"][i] == h.pose.center[0] and idx["frame_y"][i] == h.pose.center[1]
    return idx["done"]


# (a) a dask.distributed cluster of 2 worker processes gives the single-process results
@pytest.mark.slow  # a real two-process cluster takes 15 s to start and run; the default
# process scheduler's test below covers the same equality across processes
def test_cluster_of_two_workers_equals_single_process(survey_frames, tmp_path: Path) -> None:
    from distributed import LocalCluster

    paths, holos = survey_frames
    # The files hold the holograms bit for bit (so migrating the ones in memory is the
    # single-process result of each file); checked on a few.
    for i in (0, N_CLUSTER // 2, N_CLUSTER - 1):
        assert np.array_equal(hr.load(paths[i]).data, holos[i].data)
    store = tmp_path / "survey.zarr"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster:
        summary = hr.survey.run_batch(paths, store, z=Z, scheduler=cluster.scheduler_address)
    assert summary["done"] == N_CLUSTER and summary["skipped"] == [] and summary["resumed"] == 0
    assert summary["workers"] == 2
    done = _assert_exact(store, paths, holos)
    assert done.all() and done.size == N_CLUSTER
    ds = hr.survey.open_survey(store)
    assert dict(ds["image"].sizes) == {"frame": N_CLUSTER, "z": 2, "y": 8, "x": 8, "iq": 2}
    assert list(ds["frame_name"].values[:2]) == ["frame000.nc", "frame001.nc"]


# (b) corrupt, truncated, empty and foreign frames: reported by name and skipped; strict stops
def test_bad_frames_are_reported_and_skipped(survey_frames, tmp_path: Path) -> None:
    paths, holos = survey_frames
    good = paths[:4]
    truncated = tmp_path / "truncated.nc"
    truncated.write_bytes(paths[4].read_bytes()[: paths[4].stat().st_size // 2])
    empty = tmp_path / "empty.nc"
    empty.write_bytes(b"")
    other = _frames(tmp_path / "big", 1, size=10)[0][0]  # another grid
    image = hr.save(migrate64(holos[5], Z), tmp_path / "image.nc")
    frames = [good[0], truncated, good[1], empty, good[2], other, image, good[3]]
    s = hr.survey.run_batch(frames, tmp_path / "s.zarr", z=Z, scheduler="synchronous")
    reasons = {Path(k["name"]).name: k["reason"] for k in s["skipped"]}
    assert s["done"] == 4 and set(reasons) == {"truncated.nc", "empty.nc", "frame000.nc",
                                               "image.nc"}
    assert "is empty" in reasons["empty.nc"]
    assert "not a readable NetCDF-4" in reasons["truncated.nc"] \
        or "truncated" in reasons["truncated.nc"]
    assert "10 x 10" in reasons["frame000.nc"] and "Image" in reasons["image.nc"]
    assert _assert_exact(tmp_path / "s.zarr", paths, holos).sum() == 4

    # strict: an empty file is seen before anything is written ...
    with pytest.raises(ValueError, match=r"empty\.nc"):
        hr.survey.run_batch([good[0], empty], tmp_path / "s1.zarr", z=Z, strict=True,
                            scheduler="synchronous")
    assert not (tmp_path / "s1.zarr").exists()
    # ... a truncated one when it is read: the run stops there; what the store holds is
    # complete (Dask may have run other frames first, in any order).
    with pytest.raises(ValueError, match=r"truncated\.nc"):
        hr.survey.run_batch([good[0], good[1], truncated, good[2]], tmp_path / "s2.zarr",
                            z=Z, strict=True, scheduler="synchronous")
    done = _assert_exact(tmp_path / "s2.zarr", paths, holos)
    assert done.sum() <= 3 and not done[2]
    # not strict, the same store finishes the rest
    s = hr.survey.run_batch([good[0], good[1], truncated, good[2]], tmp_path / "s2.zarr",
                            z=Z, scheduler="synchronous")
    assert s["resumed"] + s["done"] == 3 and [k["name"] for k in s["skipped"]] == [
        str(truncated)]


# (c) a rerun resumes: frames already done are not imaged again
def test_rerun_resumes_without_redoing(survey_frames, tmp_path: Path,
                                       monkeypatch: pytest.MonkeyPatch) -> None:
    paths, holos = survey_frames
    calls = []
    real = survey_worker.image_of

    def counting(*a, **kw):
        calls.append(1)
        return real(*a, **kw)

    monkeypatch.setattr(survey_worker, "image_of", counting)
    store = tmp_path / "s.zarr"
    s1 = hr.survey.run_batch(paths[:10], store, z=Z, scheduler="synchronous")
    first = survey_store.read_index(store)["finished"].copy()
    assert s1["done"] == 10 and len(calls) == 10
    s2 = hr.survey.run_batch(paths[:20], store, z=Z, scheduler="synchronous")
    assert (s2["done"], s2["resumed"], len(calls)) == (10, 10, 20)
    idx = survey_store.read_index(store)
    assert np.array_equal(idx["finished"][:10], first)     # untouched
    assert np.all(idx["finished"][10:] >= first.max())
    assert _assert_exact(store, paths, holos).sum() == 20
    s3 = hr.survey.run_batch(paths[:20], store, z=Z, scheduler="synchronous")
    assert (s3["done"], s3["resumed"], len(calls)) == (0, 20, 20)


# (d) a run cut short leaves a readable store; the rerun completes it
def test_interrupted_run_leaves_readable_store(survey_frames, tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    from holoradar.survey import batch as survey_batch

    paths, holos = survey_frames
    frames = paths[:12]
    # Chunks of 4 frames: the second chunk's images are written, then the run "dies"
    # before their positions and done flags (a KeyboardInterrupt in the writer).
    monkeypatch.setattr(survey_batch, "frames_per_chunk", lambda per, n: 4)
    real = survey_worker.write_frames
    n = [0]
    crashed = []

    def crash_after_image(store, token, slots, block, positions):
        n[0] += 1
        if n[0] != 2:
            return real(store, token, slots, block, positions)
        h = survey_store._handles(store, token)
        h["image"][slots[0]:slots[-1] + 1] = block
        crashed.extend(slots)
        raise KeyboardInterrupt

    monkeypatch.setattr(survey_worker, "write_frames", crash_after_image)
    store = tmp_path / "s.zarr"
    with pytest.raises(KeyboardInterrupt) as stop:
        hr.survey.run_batch(frames, store, z=Z, workers=1)
    assert crashed == [4, 5, 6, 7]
    # Ctrl-C says what the store holds (the command line prints it as its one line): the
    # first chunk, and the third if its write had started before the second failed.
    assert isinstance(stop.value, hr.survey.BatchInterrupted)
    stored = int(survey_store.read_index(store)["done"].sum())
    assert stored in (4, 8) and (stop.value.stored, stop.value.frames) == (stored, 12)
    assert str(stop.value) == (f"interrupted: {stored} of 12 frames are stored in "
                               f"{str(store)!r}; run_batch with the same arguments resumes")
    ds = hr.survey.open_survey(store)
    assert int(ds["done"].sum()) == stored and not ds["done"][crashed].any()
    assert _assert_exact(store, paths, holos).sum() == stored
    monkeypatch.setattr(survey_worker, "write_frames", real)
    s = hr.survey.run_batch(frames, store, z=Z, workers=1)
    assert (s["resumed"], s["done"]) == (stored, 12 - stored)
    assert _assert_exact(store, paths, holos).all()


def test_after_ctrl_c_workers_start_no_further_frame(survey_frames, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """After Ctrl-C the caller asks the workers to stop (schedule.stop_requested): a task
    finishes the frame in hand and starts no other; the next run starts afresh."""
    from holoradar.survey import schedule

    paths, holos = survey_frames
    real = survey_worker.image_frame
    calls = []

    def ctrl_c_during_the_first(*args, **kwargs):
        calls.append(1)
        schedule._LOCAL_STOP.set()  # what run_tasks does on KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(survey_worker, "image_frame", ctrl_c_during_the_first)
    store = tmp_path / "s.zarr"
    job = survey_worker.Job(str(store), "run", hr.survey.Settings.make(Z, None, "angular", 1),
                            hr.survey.FrameGeometry.of(holos[0]), False)
    survey_store.create_store(store, job.settings, job.geometry)
    slots = survey_store.register_frames(store, [p.resolve() for p in paths[:4]])
    chunk = [(slot, str(p), p.name) for slot, p in zip(slots, paths[:4], strict=True)]
    assert [r["status"] for r in survey_worker.process_chunk(chunk, job)] == ["done"]
    assert len(calls) == 1
    assert survey_store.read_index(store)["done"].sum() == 1  # the frame in hand is stored
    monkeypatch.setattr(survey_worker, "image_frame", real)
    s = hr.survey.run_batch(paths[:4], store, z=Z, scheduler="synchronous")
    assert (s["resumed"], s["done"]) == (1, 3)  # the stop does not outlive its run


def test_killed_process_leaves_readable_store(survey_frames, tmp_path: Path) -> None:
    paths, holos = survey_frames
    # 120 frames (enough work to be killed midway), copies of the survey's 20: copying
    # is fast, writing 120 holograms took seconds.
    (tmp_path / "f").mkdir()
    frames = [Path(shutil.copyfile(paths[i % len(paths)], tmp_path / "f" / f"f{i:03d}.nc"))
              for i in range(120)]
    holos = [holos[i % len(paths)] for i in range(120)]
    paths = frames
    store = tmp_path / "s.zarr"
    listing = tmp_path / "frames.txt"
    listing.write_text("\n".join(map(str, frames)))
    code = textwrap.dedent(f"""
        import holoradar as hr
        frames = open({str(listing)!r}).read().split()
        hr.survey.run_batch(frames, {str(store)!r}, z={Z!r}, scheduler="synchronous")
    """)
    proc = subprocess.Popen([sys.executable, "-c", code])
    try:
        deadline = time.monotonic() + 60
        k = 0
        while time.monotonic() < deadline and proc.poll() is None:
            if survey_store.is_survey(store):
                k = int(survey_store.read_index(store)["done"].sum())
                if k >= 5:
                    break
            time.sleep(0.01)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    ds = hr.survey.open_survey(store)                    # readable
    done_before = int(ds["done"].sum())
    assert 5 <= done_before < len(frames)
    assert _assert_exact(store, paths, holos).sum() == done_before
    s = hr.survey.run_batch(frames, store, z=Z, scheduler="synchronous")
    assert (s["resumed"], s["done"]) == (done_before, len(frames) - done_before)
    assert _assert_exact(store, paths, holos).all()


def test_images_are_compressed_and_plain_stores_still_work(survey_frames, tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch
                                                            ) -> None:
    """New stores compress the images (Blosc LZ4, bit-shuffled); a store written before
    (plain chunks) is read and resumed as it is, exactly."""
    import zarr

    paths, holos = survey_frames
    new = tmp_path / "new.zarr"
    hr.survey.run_batch(paths[:3], new, z=Z, scheduler="synchronous")
    codecs = zarr.open_array(str(new / "image"), mode="r").compressors
    assert [(type(c).__name__, c.cname.value, c.shuffle.value) for c in codecs[:1]] == \
        [("BloscCodec", "lz4", "bitshuffle")]
    assert type(codecs[-1]).__name__ == "Crc32cCodec"   # each chunk checked before Blosc
    assert hr.survey.describe_store(new)["compressors"] == ["blosc", "crc32c"]
    assert _assert_exact(new, paths, holos).all()

    old = tmp_path / "old.zarr"
    monkeypatch.setattr(survey_store, "_image_codecs", lambda: None)  # as stores were made
    hr.survey.run_batch(paths[:3], old, z=Z, scheduler="synchronous")
    monkeypatch.undo()
    assert zarr.open_array(str(old / "image"), mode="r").compressors == ()
    s = hr.survey.run_batch(paths[:6], old, z=Z, scheduler="synchronous")
    assert (s["resumed"], s["done"]) == (3, 3)
    assert _assert_exact(old, paths, holos).all()
    assert hr.survey.describe_store(old)["compressors"] == []
    np.testing.assert_array_equal(hr.survey.frame_image(old, 4).data,
                                  migrate64(holos[4], Z).data)

    # A store of the version that shuffled bytes keeps its codec when resumed.
    from zarr.codecs import BloscCodec

    byte = tmp_path / "byte.zarr"
    monkeypatch.setattr(survey_store, "_image_codecs",
                        lambda: [BloscCodec(cname="lz4", clevel=5, shuffle="shuffle")])
    hr.survey.run_batch(paths[:3], byte, z=Z, scheduler="synchronous")
    monkeypatch.undo()
    s = hr.survey.run_batch(paths[:6], byte, z=Z, scheduler="synchronous")
    assert (s["resumed"], s["done"]) == (3, 3)
    assert [c.shuffle.value for c in zarr.open_array(str(byte / "image"), mode="r").compressors
            ] == ["shuffle"]
    assert _assert_exact(byte, paths, holos).all()


def test_size_is_said_before_and_a_full_disk_refused(survey_frames, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    import shutil as sh

    from holoradar.survey import space as survey_space

    paths, _ = survey_frames
    per = 2 * 8 * 8 * 2 * 8  # 2 planes of 8 x 8 pixels, I and Q as float64
    plans = []
    store = tmp_path / "s.zarr"
    s = hr.survey.run_batch(paths[:4], store, z=Z, scheduler="synchronous", on_start=plans.append)
    assert len(plans) == 1 and plans[0]["frames"] == 4
    assert (plans[0]["bytes"], plans[0]["bytes_per_frame"], s["bytes_estimated"]) == \
        (4 * per, per, 4 * per)
    assert plans[0]["image_shape"] == [2, 8, 8] and plans[0]["dtype"] == "float64"
    s = hr.survey.run_batch(paths[:6], store, z=Z, scheduler="synchronous",
                            on_start=plans.append)  # a rerun counts what is left
    assert plans[1]["frames"] == 2 and s["bytes_estimated"] == 2 * per
    hr.survey.run_batch(paths[:6], store, z=Z, scheduler="synchronous", on_start=plans.append)
    assert len(plans) == 2  # nothing left to image: no plan

    real = sh.disk_usage

    def tiny(path):
        return real(path)._replace(free=3 * per)

    monkeypatch.setattr(survey_space.shutil, "disk_usage", tiny)
    with pytest.raises(ValueError, match=r"would need up to 10 kB for 5 frames \(2.05 kB "
                       r"each: 2 planes of 8 x 8 pixels, I and Q as float64\) but its disk "
                       r"has 6.14 kB free: free some space"):
        hr.survey.run_batch(paths[:5], tmp_path / "t.zarr", z=Z, scheduler="synchronous")
    assert not (tmp_path / "t.zarr").exists()  # refused before anything was written
    with pytest.raises(ValueError, match=r"would need up to 14 kB for 7 frames"):
        hr.survey.run_batch(paths[:13], store, z=Z, scheduler="synchronous")
    assert survey_store.read_index(store)["done"].sum() == 6  # the store kept as it was
    # A store replaced (overwrite=True) frees its own space: 6 frames' worth, so 9 fit.
    s = hr.survey.run_batch(paths[:9], store, z=[0.05, 0.2], scheduler="synchronous",
                            overwrite=True)
    assert s["done"] == 9


# (e) the mosaic puts a point target at its world position
def test_mosaic_places_a_point_target(tmp_path: Path) -> None:
    target = (0.031, -0.018, 0.30)
    scene = hr.Scene(targets=[hr.PointTarget(target)], source=hr.PlaneWave())
    paths = []
    for j, cy in enumerate((-0.1, 0.0, 0.1)):
        for i, cx in enumerate((-0.1, 0.0, 0.1)):   # 16 x 16 frames, 16 cm wide: 6 cm overlap
            ap = hr.Aperture.grid(16, PITCH, pose=hr.Pose((cx, cy, 0.0)))
            paths.append(hr.save(hr.simulate(scene, ap, F0), tmp_path / f"t{j}{i}.nc"))
    store = tmp_path / "scene.zarr"
    s = hr.survey.run_batch(paths, store, z=[0.25, 0.30, 0.35], upsample=4,
                            scheduler="synchronous")
    assert s["done"] == 9
    m = hr.survey.mosaic(store, 0.31)
    px = PITCH / 4
    assert float(m.z[0]) == 0.30 and m.data.shape == (141, 141)
    assert np.isclose(m.x[0], -0.175) and np.isclose(m.x[-1], 0.175)
    assert np.allclose(np.diff(m.x), px) and np.allclose(np.diff(m.y), px)
    # The image of a point peaks on it: for the frame above it exactly (symmetric PSF,
    # lambda*z/A ~ 6 cm wide); the frames beside it see it through a truncated aperture,
    # which pulls their maximum by a fraction of that width, but the taper weights them
    # down (measured 1 mm). Sampled every 2.5 mm (upsample=4, exact band-limited
    # interpolation), the brightest pixel is within half a pixel of the peak: one pixel
    # bounds both.
    x, y, _ = m.peak()
    assert abs(x - target[0]) <= px and abs(y - target[1]) <= px
    # A finer map resamples bilinearly, whose maxima lie on the frames' samples: the
    # same bound, one 2.5 mm sample.
    fine = hr.survey.mosaic(store, 0.30, pitch=0.001)
    assert fine.data.shape == (351, 351)
    xf, yf, _ = fine.peak()
    assert abs(xf - target[0]) <= px and abs(yf - target[1]) <= px
    # One frame alone: the map is that frame's |image| exactly (weights cancel; the grid
    # goes through its pixels, so no interpolation); relative rounding ~1e-16.
    one = tmp_path / "one.zarr"
    hr.survey.run_batch(paths[4:5], one, z=[0.30], scheduler="synchronous")
    ref = np.abs(migrate64(hr.load(paths[4]), [0.30]).data[0])
    np.testing.assert_allclose(hr.survey.mosaic(one, 0.3).data, ref, rtol=1e-14, atol=0)
    img = hr.survey.frame_image(one, "t11.nc")
    assert np.allclose(img.x, (np.arange(16) - 7.5) * PITCH)


# (f) refusals, before any work
def test_refusals(survey_frames, tmp_path: Path) -> None:
    paths, _ = survey_frames
    frame_as_zarr = tmp_path / "frame.zarr"
    shutil.copy(paths[0], frame_as_zarr)
    with pytest.raises(ValueError, match="one of the inputs"):
        hr.survey.run_batch([frame_as_zarr], frame_as_zarr, z=Z, scheduler="synchronous")
    (tmp_path / "in.zarr").mkdir()
    inside = shutil.copy(paths[0], tmp_path / "in.zarr" / "f.nc")
    with pytest.raises(ValueError, match="holds the frame"):
        hr.survey.run_batch([inside], tmp_path / "in.zarr", z=Z, overwrite=True)
    with pytest.raises(ValueError, match=r"must end in \.zarr"):
        hr.survey.run_batch(paths[:2], tmp_path / "s.nc", z=Z, scheduler="synchronous")
    with pytest.raises(ValueError, match="does not exist"):
        hr.survey.run_batch(paths[:2], tmp_path / "no" / "s.zarr", z=Z)
    with pytest.raises(ValueError, match="scheduler"):
        hr.survey.run_batch(paths[:2], tmp_path / "s.zarr", z=Z, scheduler="fast")
    with pytest.raises(ValueError, match="no frames"):
        hr.survey.run_batch([], tmp_path / "s.zarr", z=Z)
    (tmp_path / "foreign.zarr").mkdir()
    with pytest.raises(ValueError, match="not a holoradar survey store"):
        hr.survey.run_batch(paths[:2], tmp_path / "foreign.zarr", z=Z, overwrite=True)
    store = tmp_path / "s.zarr"
    hr.survey.run_batch(paths[:2], store, z=Z, scheduler="synchronous")
    with pytest.raises(ValueError, match=r"z: the store has \[0.05, 0.1\] m.*overwrite=True"):
        hr.survey.run_batch(paths[:2], store, z=[0.05, 0.2], scheduler="synchronous")
    sand = hr.Medium.half_space(0.08, 2.5 + 0.01j)
    with pytest.raises(ValueError, match="medium: the store has free space"):
        hr.survey.run_batch(paths[:2], store, z=Z, medium=sand, scheduler="synchronous")
    with pytest.raises(ValueError, match="upsample"):
        hr.survey.run_batch(paths[:2], store, z=Z, upsample=2, scheduler="synchronous")
    s = hr.survey.run_batch(paths[:2], store, z=Z, medium=sand, overwrite=True,
                            scheduler="synchronous")
    assert (s["done"], s["resumed"]) == (2, 0)
    assert hr.survey.open_survey(store).attrs["settings"]["medium"]["eps"][1] == [2.5, 0.01]
    with pytest.raises(ValueError, match="not a holoradar survey store"):
        hr.survey.open_survey(tmp_path / "foreign.zarr")
    with pytest.raises(ValueError, match=r"none of the 1 frames can be imaged.*is not a file"):
        hr.survey.run_batch([tmp_path / "x.nc"], tmp_path / "t.zarr", z=Z)
    assert not (tmp_path / "t.zarr").exists()


def test_default_and_dask_local_schedulers(survey_frames, tmp_path: Path) -> None:
    """By default a short survey stays in the caller's process (a cluster would take
    longer to start than the frames to image); Dask's local schedulers still work."""
    paths, holos = survey_frames
    s = hr.survey.run_batch(paths[:16], tmp_path / "d.zarr", z=Z)
    assert (s["scheduler"], s["workers"], s["done"]) == ("in-process", 1, 16)
    assert _assert_exact(tmp_path / "d.zarr", paths, holos).all()
    s = hr.survey.run_batch(paths[:16], tmp_path / "s.zarr", z=Z, scheduler="processes")
    assert s["scheduler"] == "processes" and s["done"] == 16
    assert _assert_exact(tmp_path / "s.zarr", paths, holos).all()
    s = hr.survey.run_batch(paths[:16], tmp_path / "t.zarr", z=Z, scheduler="threads")
    assert s["done"] == 16 and _assert_exact(tmp_path / "t.zarr", paths, holos).all()


_DAMAGED = {"n": 0}


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_damaged_stores_give_a_clear_error(survey_frames, tmp_path: Path, data) -> None:
    """A store whose files were truncated, flipped or removed: reading it (open_survey,
    mosaic, frame_image) is a ValueError or a valid answer, never another exception."""
    paths, _ = survey_frames
    base = tmp_path / "base.zarr"
    if not base.exists():
        hr.survey.run_batch(paths[:3], base, z=0.3, scheduler="synchronous")
    store = tmp_path / f"s{_DAMAGED['n']}.zarr"
    _DAMAGED["n"] += 1
    FUZZED["survey stores: a file truncated, flipped or removed"] += 1
    shutil.copytree(base, store)
    files = sorted(p for p in store.rglob("*") if p.is_file())
    victim = data.draw(st.sampled_from(files))
    op = data.draw(st.sampled_from(["truncate", "flip", "remove"]))
    blob = bytearray(victim.read_bytes())
    if op == "remove":
        victim.unlink()
    elif op == "truncate":
        victim.write_bytes(bytes(blob[: data.draw(st.integers(0, max(0, len(blob) - 1)))]))
    elif blob:
        at = data.draw(st.integers(0, len(blob) - 1))
        blob[at] ^= 1 << data.draw(st.integers(0, 7))
        victim.write_bytes(bytes(blob))
    for read in (lambda: hr.survey.open_survey(store).load(),
                 lambda: hr.survey.mosaic(store, 0.3),
                 lambda: hr.survey.frame_image(store, 0),
                 lambda: hr.survey.describe_store(store)):
        try:
            read()
        except ValueError as exc:
            assert str(exc)
