"""Surveys written a chunk of frames at a time: exactness, crash consistency, bad frames
remembered between runs, and the number of workers.

Exactness: the stored images must be bit for bit ``migrate(frame)``: the parts are
copied into the chunk (no arithmetic), so the tolerance is 0 wherever the frames
lie in their chunks (whole chunks, partial ones, a skipped frame between two).
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from click.testing import CliRunner

import holoradar as hr
from conftest import migrate64
from holoradar.app.cli import main
from holoradar.io import readers
from holoradar.survey import batch as survey_batch
from holoradar.survey import store as survey_store
from holoradar.survey import worker as survey_worker

F0 = 9.9e9
PITCH = 0.01
Z = [0.05, 0.1]


def _frames(folder: Path, n: int, size: int = 8) -> tuple[list[Path], list]:
    rng = np.random.default_rng(3)
    x = (np.arange(size) - (size - 1) / 2) * PITCH
    folder.mkdir(parents=True, exist_ok=True)
    paths, holos = [], []
    for i in range(n):
        data = rng.standard_normal((size, size)) + 1j * rng.standard_normal((size, size))
        h = hr.Hologram(data, x, x, F0, pose=hr.Pose((0.04 * i, 0.0, 0.0)))
        paths.append(hr.save(h, folder / f"f{i:02d}.nc"))
        holos.append(h)
    return paths, holos


@pytest.fixture(scope="module")
def survey(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[Path], list]:
    return _frames(tmp_path_factory.mktemp("frames"), 12)


def _consistent(store: Path, paths: list[Path], holos: list) -> np.ndarray:
    """Every frame marked done holds exactly its migrate (tolerance 0, see the module);
    returns the done mask."""
    idx = survey_store.read_index(store)
    images = survey_store.read_images(idx, range(idx["n"]))
    by_path = {str(p.resolve()): h for p, h in zip(paths, holos, strict=True)}
    for i in np.nonzero(idx["done"])[0]:
        h = by_path[idx["frame_path"][i]]
        assert np.array_equal(images[i], migrate64(h, Z).data), idx["frame_name"][i]
        assert idx["frame_x"][i] == h.pose.center[0]
    return idx["done"]


def _refuse(reader, path: Path):
    """Stands in for the isolated parser process (which takes a second to start): the
    verdict it gives a file that is not NetCDF."""
    raise ValueError(f"{path.name} is not a readable .nc file (simulated parser)")


def test_chunks_of_frames_are_exact_whole_partial_and_around_a_skip(
        survey, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    paths, holos = survey
    monkeypatch.setattr(survey_batch, "frames_per_chunk", lambda per, n: 4)
    monkeypatch.setattr(readers, "_isolated", _refuse)  # no parser process for a text file
    store = tmp_path / "s.zarr"
    s = hr.survey.run_batch(paths[:6], store, z=Z, workers=1)  # chunk 1 half full
    assert s["done"] == 6
    first = survey_store.read_index(store)["finished"].copy()
    image = survey_store.read_index(store)["group"]["image"]
    assert image.chunks[0] == 4
    assert len(list((store / "image" / "c").iterdir())) == 2  # two chunks, not six files
    # More frames, one of them unreadable: slots 6, 7 complete chunk 1 (a partial chunk
    # written again around the stored frames), slot 9 is skipped between 8 and 10.
    bad = tmp_path / "bad.nc"
    bad.write_text("not a NetCDF file")
    frames = [*paths[:9], bad, *paths[9:]]
    s = hr.survey.run_batch(frames, store, z=Z, workers=1)
    assert (s["done"], s["resumed"], [k["name"] for k in s["skipped"]]) == (6, 6, [str(bad)])
    idx = survey_store.read_index(store)
    assert np.array_equal(idx["finished"][:6], first)  # stored frames untouched
    done = _consistent(store, paths, holos)
    assert done.sum() == 12 and not done[9]
    assert np.isnan(survey_store.read_images(idx, [9])).all()


def test_an_error_between_chunks_leaves_done_marks_matching_the_data(
        survey, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An exception while imaging the 7th frame (not a bad frame: a failure of the run):
    the frames imaged before it are written, marked done and exact; no other frame is
    marked done; a rerun images the rest."""
    paths, holos = survey
    monkeypatch.setattr(survey_batch, "frames_per_chunk", lambda per, n: 4)
    real = survey_worker.image_of
    calls = [0]

    def fails_on_the_seventh(*a, **kw):
        calls[0] += 1
        if calls[0] == 7:
            raise RuntimeError("out of memory (simulated)")
        return real(*a, **kw)

    monkeypatch.setattr(survey_worker, "image_of", fails_on_the_seventh)
    store = tmp_path / "s.zarr"
    with pytest.raises(RuntimeError, match="simulated"):
        hr.survey.run_batch(paths, store, z=Z, workers=1)
    done = _consistent(store, paths, holos)
    assert done.tolist() == [True] * 6 + [False] * 6
    idx = survey_store.read_index(store)
    assert np.isnan(survey_store.read_images(idx, range(6, 12))).all()
    monkeypatch.setattr(survey_worker, "image_of", real)
    s = hr.survey.run_batch(paths, store, z=Z, workers=1)
    assert (s["resumed"], s["done"]) == (6, 6) and _consistent(store, paths, holos).all()


def test_a_failure_inside_a_chunk_write_leaves_no_frame_marked_done_without_its_data(
        survey, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The real write order: a failure after a chunk's images and positions are written
    but before its done flags (here: the clock read for ``finished`` fails on the second
    chunk) leaves that chunk's frames not done; a rerun images them."""
    paths, holos = survey
    monkeypatch.setattr(survey_batch, "frames_per_chunk", lambda per, n: 4)
    calls = [0]

    def clock() -> float:
        calls[0] += 1
        if calls[0] == 2:
            raise OSError("disk gone (simulated)")
        return 1.7e9

    monkeypatch.setattr(survey_store, "time", SimpleNamespace(
        time=clock, strftime=time.strftime, gmtime=time.gmtime))
    store = tmp_path / "s.zarr"
    with pytest.raises(OSError, match="simulated"):
        hr.survey.run_batch(paths, store, z=Z, workers=1)
    done = _consistent(store, paths, holos)
    assert not done[4:8].any() and done[:4].all()
    idx = survey_store.read_index(store)
    assert not np.isnan(survey_store.read_images(idx, range(4, 8))).any()  # images written
    monkeypatch.undo()
    s = hr.survey.run_batch(paths, store, z=Z, workers=1)
    assert s["resumed"] + s["done"] == 12 and _consistent(store, paths, holos).all()


def test_a_damaged_frame_is_remembered_and_not_parsed_again(
        survey, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A frame found bad is kept in the store with its reason and its file's stamp (size,
    modification time): a rerun skips it without reading it; --retry-bad, or a changed
    file, reads it again. The parser is counted (standing in for the isolated parser
    process, which a damaged NetCDF file reaches)."""
    paths, _ = survey
    parses, reads = [], []

    def parser(reader, path):
        parses.append(path.name)
        raise ValueError(f"{path.name} is not a readable .nc file (damaged, simulated)")

    real_read = survey_worker.read_frame

    def counting_read(path, geometry, layout=None):
        reads.append(Path(path).name)
        return real_read(path, geometry, layout)

    monkeypatch.setattr(readers, "_isolated", parser)
    monkeypatch.setattr(survey_worker, "read_frame", counting_read)
    damaged = tmp_path / "damaged.nc"
    damaged.write_bytes(paths[0].read_bytes()[:300])  # a truncated file
    frames = [*paths[:3], damaged, paths[3]]
    store = tmp_path / "s.zarr"
    s = hr.survey.run_batch(frames, store, z=Z, workers=1)
    assert s["done"] == 4 and parses == ["damaged.nc"] and s["remembered"] == 0
    reason = s["skipped"][0]["reason"]
    assert "damaged, simulated" in reason
    info = hr.survey.describe_store(store)["not_stored"]
    assert [(m["name"], m["reason"]) for m in info] == [("damaged.nc", reason)]

    parses.clear()
    reads.clear()
    s = hr.survey.run_batch(frames, store, z=Z, workers=1)
    assert parses == [] and reads == []  # nothing read: four done, one remembered
    assert s["skipped"] == [{"name": str(damaged), "reason": reason, "remembered": True}]
    assert (s["remembered"], s["resumed"], s["done"]) == (1, 4, 0)
    with pytest.raises(ValueError, match=r"damaged\.nc.*found by an earlier run"):
        hr.survey.run_batch(frames, store, z=Z, workers=1, strict=True)

    s = hr.survey.run_batch(frames, store, z=Z, workers=1, retry_bad=True)
    assert parses == ["damaged.nc"] and s["remembered"] == 0 and len(s["skipped"]) == 1

    # The file replaced by a good frame: its stamp changed, so it is read and imaged.
    parses.clear()
    damaged.write_bytes(paths[4].read_bytes())
    os.utime(damaged, ns=(1, 1))
    s = hr.survey.run_batch(frames, store, z=Z, workers=1)
    assert (s["done"], s["skipped"], parses) == (1, [], [])
    assert hr.survey.describe_store(store)["not_stored"] == []


def test_workers_must_be_a_positive_integer(survey, tmp_path: Path) -> None:
    paths, _ = survey
    for bad in (0, -2, 1.5, "2", True):
        with pytest.raises(ValueError, match=r"workers must be a positive integer \(the "
                                             r"number of worker processes\), got"):
            hr.survey.run_batch(paths[:2], tmp_path / "s.zarr", z=Z, workers=bad)
    with pytest.raises(ValueError, match=r"workers.*or scheduler, not both"):
        hr.survey.run_batch(paths[:2], tmp_path / "s.zarr", z=Z, workers=2,
                            scheduler="threads")
    assert not (tmp_path / "s.zarr").exists()
    for bad in ("0", "-1", "two", "1.5"):
        res = CliRunner().invoke(main, ["batch", str(paths[0]), "-o", str(tmp_path / "c.zarr"),
                                        "--z", "0.1", "--workers", bad])
        assert res.exit_code == 2, res.output
        assert (f"Invalid value for '--workers': must be a positive integer (the number of "
                f"worker processes), got '{bad}'") in res.output
    res = CliRunner().invoke(main, ["batch", str(paths[0]), "-o", str(tmp_path / "c.zarr"),
                                    "--z", "0.1", "--workers", "2", "--scheduler", "threads"])
    assert res.exit_code == 2 and "give one of them" in res.output
    assert not (tmp_path / "c.zarr").exists()
    res = CliRunner().invoke(main, ["batch", *map(str, paths[:3]), "-o",
                                    str(tmp_path / "c.zarr"), "--z", "0.1", "--workers", "1"])
    assert res.exit_code == 0 and "(in-process, 1 worker)" in res.output


@pytest.mark.slow  # a two-process local cluster: its start alone takes seconds
def test_two_workers_local_cluster_is_exact(survey, tmp_path: Path) -> None:
    paths, holos = survey
    store = tmp_path / "s.zarr"
    s = hr.survey.run_batch(paths, store, z=Z, workers=2)
    assert (s["scheduler"], s["workers"], s["done"]) == ("local cluster", 2, 12)
    assert _consistent(store, paths, holos).all()


def _worker_environ() -> dict[str, str | None]:
    import os

    return {k: os.environ.get(k) for k in ("HOLORADAR_THREADS", "MALLOC_TRIM_THRESHOLD_")}


@pytest.mark.slow  # a two-process local cluster
def test_local_cluster_workers_run_one_thread_and_keep_freed_memory() -> None:
    # One FFT thread per worker; and no MALLOC_TRIM_THRESHOLD_ (Dask's default for its
    # workers), which made every freed array come back as fresh pages: a frame's
    # load + migrate cost 31-33 ms of CPU against 20-23 ms. The caller's Dask
    # configuration is left as it was.
    import dask
    import distributed  # noqa: F401  (its configuration)

    from holoradar.survey.schedule import local_cluster

    before = dask.config.get("distributed.nanny.pre-spawn-environ")
    cluster, client = local_cluster(2)
    try:
        seen = client.run(_worker_environ)
    finally:
        client.close()
        cluster.close()
    assert len(seen) == 2
    assert all(e == {"HOLORADAR_THREADS": "1", "MALLOC_TRIM_THRESHOLD_": None}
               for e in seen.values()), seen
    assert dask.config.get("distributed.nanny.pre-spawn-environ") == before


def test_chunk_writes_run_one_at_a_time_in_order(survey, tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """A worker's chunk writes never overlap and finish in the order submitted (two at
    once let a later chunk finish first under load: the test above then failed now and
    then). A slow write stands in for a loaded disk."""
    import threading

    paths, _ = survey
    monkeypatch.setattr(survey_batch, "frames_per_chunk", lambda per, n: 4)
    real = survey_worker.write_frames
    running, order, overlaps = [0], [], []
    lock = threading.Lock()

    def slow(store, token, slots, block, positions):
        with lock:
            running[0] += 1
            overlaps.append(running[0])
        time.sleep(0.05)
        real(store, token, slots, block, positions)
        with lock:
            running[0] -= 1
            order.append(int(slots[0]))

    monkeypatch.setattr(survey_worker, "write_frames", slow)
    hr.survey.run_batch(paths, tmp_path / "s.zarr", z=Z, workers=1)
    assert max(overlaps) == 1 and order == sorted(order) and len(order) == 3
