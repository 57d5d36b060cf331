"""``run_batch``: image every frame of a survey with the same settings, on one or more
worker processes (a local cluster started for the run, or Dask's schedulers)."""

from __future__ import annotations

import os
import time
import uuid
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..io.output import check_output
from ..physics.medium import Medium
from . import schedule
from .frames import FrameGeometry
from .settings import Settings
from .space import bytes_text as bytes_text  # re-exported: the command line's sizes
from .space import folder_bytes, plan_space
from .store import (
    create_store,
    file_stamp,
    frame_bytes,
    frames_per_chunk,
    is_survey,
    note_skipped,
    read_index,
    register_frames,
    remembered_bad,
    stored_settings,
)
from .worker import Job, drain_writes, process_chunk, read_frame

__all__ = ["BatchInterrupted", "SettingsMismatchError", "run_batch"]


class BatchInterrupted(KeyboardInterrupt):
    """:func:`run_batch` stopped by Ctrl-C (SIGINT): how much of the survey is stored.

    A ``KeyboardInterrupt``, so code that stops on one still stops; raised once the
    local workers have stopped (:func:`~holoradar.survey.schedule.run_tasks`). The
    store is consistent: a rerun with the same arguments images the rest.

    Attributes
    ----------
    store : str
        The store's path.
    stored : int
        Frames of this run's list stored complete (done), before or during it.
    frames : int
        Distinct frames the run was given.
    """

    def __init__(self, store: str, stored: int, frames: int) -> None:
        self.store, self.stored, self.frames = store, stored, frames
        of = f"{frames} frame is" if frames == 1 else f"{frames} frames are"
        super().__init__(f"interrupted: {stored} of {of} stored in {store!r}; run_batch "
                         "with the same arguments resumes")


class SettingsMismatchError(ValueError):
    """An existing store was made with other settings than a run asks for.

    Attributes
    ----------
    store : str
        The store's path.
    differences : list of str
        One line per setting that differs (``"z: the store has ..., this run asks ..."``).
    """

    def __init__(self, store: str, differences: list[str]) -> None:
        self.store, self.differences = store, list(differences)
        super().__init__(f"store {store!r} was made with other settings ("
                         + "; ".join(differences) + "): pass overwrite=True to start it "
                         "again (its frames are removed), or choose another store")


def run_batch(frames: Sequence[str | os.PathLike[str]], store: str | os.PathLike[str], *,
              z: float | Sequence[float], medium: Medium | None = None,
              method: str = "angular", upsample: int = 1, workers: int | None = None,
              scheduler: str | None = None, strict: bool = False, overwrite: bool = False,
              retry_bad: bool = False, progress: bool = False, layout: Any = None,
              on_start: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """Image every frame of a survey with the same settings into one Zarr store.

    Each frame (a hologram file written by :func:`holoradar.save`) is read with
    :func:`holoradar.load`, migrated with :func:`holoradar.migrate` and written
    into its own slot of the store together with its position along the survey
    (the world position of the centre of its element grid: ``pose.center`` for
    the usual centred grids, the centre of the coordinates for the identity
    pose; :func:`~holoradar.survey.frames.frame_position`). A task images the
    frames of whole chunks of the store (several frames a chunk) and writes each
    chunk once; the layout of the store is in :mod:`holoradar.survey.store`.

    Parameters
    ----------
    frames : sequence of path
        Hologram files (``.nc``). Duplicates are imaged once.
    store : path
        The Zarr store to write, ending in ``.zarr``; its folder must exist and
        it must not be one of the frames.
    z : float or sequence of float
        Ranges of the image planes from the aperture, metres (>= 0).
    medium : Medium, optional
        Layered ground (None: free space).
    method : {"angular", "fresnel"}
        Migration method (:func:`holoradar.migrate`).
    upsample : int
        Output pixels per element pitch.
    workers : int, optional
        Worker processes on this machine: 1 images the frames in this process
        (no Dask); N >= 2 starts a ``dask.distributed.LocalCluster`` of N
        processes of one thread each for the run (closed at its end). None (the
        default, with no ``scheduler``): this process images a first chunk of
        frames, and a cluster of one worker per usable core is started for the
        rest only if they would take more than :data:`AUTO_CLUSTER_S` seconds
        here (starting workers costs seconds; a short survey is faster without).
    scheduler : str, optional
        Instead of ``workers``: ``"synchronous"`` (this process, as
        ``workers=1``), ``"threads"`` or ``"processes"`` (Dask's local
        schedulers), or the address of a running ``dask.distributed`` scheduler
        (``"tcp://host:8786"``), whose workers must see the frames and the store
        at the same paths.
    strict : bool
        Stop at the first frame that cannot be imaged (raise ``ValueError``
        naming it); the frames finished before stay in the store. Default
        False: such frames are reported in the summary and skipped.
    overwrite : bool
        Start a new store even if one exists (the old one is removed once the
        new layout is in place). Default False: an existing store of the same
        settings is resumed: frames marked done are not imaged again.
    retry_bad : bool
        Read again the frames an earlier run of this store found bad (damaged,
        of another geometry...). Default False: such a frame whose file has not
        changed since (same size and modification time) is skipped with the
        reason found then, without reading it.
    progress : bool
        Show a progress bar.
    layout : Layout, dict or str, optional
        For frames in a user's format: where the hologram is in each file
        (:func:`holoradar.load`); the same for every frame.
    on_start : callable, optional
        Called once before the first frame is imaged (not when none is left to
        image) with the plan: ``frames`` (to image), ``bytes`` (the most the store
        grows by: their images before compression), ``bytes_per_frame``,
        ``image_shape`` (nz, ny', nx'), ``dtype`` (of the stored I and Q values),
        ``free`` (bytes free on the store's disk) and ``store``.

    Returns
    -------
    dict
        ``done`` (frames imaged by this run), ``resumed`` (frames found done in
        the store and not imaged again), ``skipped`` (list of ``{"name",
        "reason"}``), ``seconds`` (wall time of the run), ``frames`` (distinct
        frames asked), ``store`` (its path), ``scheduler`` (``"in-process"``,
        ``"local cluster"``, or the scheduler asked), ``workers``, ``remembered``
        (skipped frames found bad by an earlier run, not read again; their
        entries in ``skipped`` carry ``"remembered": True``) and
        ``warnings`` (each distinct warning the workers raised, once, as
        ``"Category: message"``), ``bytes_estimated`` (the store's growth at most,
        as given to ``on_start``; 0 when nothing was left to image).

    Raises
    ------
    ValueError
        No frames; a bad store path (suffix, folder, equal to a frame, an
        existing folder that is not a survey store); an existing store made
        with other settings (unless ``overwrite``; :class:`SettingsMismatchError`); a
        bad scheduler or ``workers``, or both given; no frame can be imaged; with
        ``strict``, the first frame
        that cannot be imaged; the images would not fit on the store's disk
        (checked before any is imaged, against their size before compression).
    BatchInterrupted
        Ctrl-C (a ``KeyboardInterrupt``): the workers are stopped, and the
        exception says how many of the frames are stored.

    Notes
    -----
    The store's images are compressed (Blosc LZ4 after a bit shuffle), which
    saves only about a tenth: float images are noise in their low bits. Each
    frame takes ``nz * ny' * nx' * 2 * 8`` bytes before compression (4 for
    complex64 frames), ``ny' = upsample * (ny - 1) + 1``: 240 frames of 16 x 16
    elements with 61 planes at ``upsample=8`` take up to 3.4 GB. Those not
    imaged yet must fit in the free space of the store's disk, or the run is
    refused before it starts.

    All frames must share the grid, pitch, frequencies, kind (array or
    transceiver) and aperture height of the first readable frame (of the store,
    when resuming); a frame that differs is skipped with the reason. Frames
    must be level (no tilt). Each frame's result is bit for bit that of
    ``migrate(load(frame), z, medium=..., method=..., upsample=...)``.

    Examples
    --------
    >>> import pathlib, tempfile, numpy as np
    >>> import holoradar as hr
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> x = (np.arange(8) - 3.5) * 0.01
    >>> paths = [hr.save(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9,
    ...                               pose=hr.Pose((0.05 * i, 0.0, 0.0))), d / f"f{i}.nc")
    ...          for i in range(3)]
    >>> s = run_batch(paths, d / "survey.zarr", z=[0.2, 0.3], scheduler="synchronous")
    >>> s["done"], s["resumed"], s["skipped"]
    (3, 0, [])
    >>> run_batch(paths, d / "survey.zarr", z=[0.2, 0.3], scheduler="synchronous")["resumed"]
    3
    """
    t0 = time.perf_counter()
    settings = Settings.make(z, medium, method, upsample)
    n_workers = schedule.check_workers(workers)
    if n_workers is not None and scheduler is not None:
        raise ValueError(f"give workers (a local cluster started for the run) or scheduler, "
                         f"not both: got workers={workers!r}, scheduler={scheduler!r}")
    sched = "auto" if scheduler is None else schedule.check_scheduler(scheduler)
    if n_workers is not None:
        sched = "in-process" if n_workers == 1 else "local cluster"
    if isinstance(frames, str | os.PathLike):
        raise ValueError("frames must be a sequence of paths (a list), not one path")
    given = [Path(f) for f in frames]
    if not given:
        raise ValueError("frames: no frames given")
    target = check_output(store, suffixes=[".zarr"], inputs=given, overwrite=True, name="store",
                          folder=True)
    # A frame inside the store's folder: only where that folder exists already.
    root = target.resolve() if target.exists() else None
    inside = [p for p in given if root is not None and root in p.resolve().parents]
    if inside:
        raise ValueError(f"store {str(target)!r} holds the frame {str(inside[0])!r}: refusing "
                         "to write into (or replace) the folder of the data")
    exists = target.exists()
    if exists and not is_survey(target):
        raise ValueError(f"store {str(target)!r} exists and is not a holoradar survey store: "
                         "refusing to touch it (choose another path or remove it)")

    # A cluster is reached before anything is written (an unreachable address is an error).
    client = schedule.connect(sched) if sched not in (*schedule.LOCAL, *_OWN) else None
    try:
        summary = _run(given, target, settings, sched, client, strict=bool(strict),
                       overwrite=overwrite, exists=exists, progress=progress,
                       layout=_layout_text(layout), on_start=on_start,
                       workers=n_workers, retry_bad=bool(retry_bad))
    except KeyboardInterrupt:
        # The workers have stopped (run_tasks): what the store holds now is what a
        # rerun finds. "from None": the interrupted frame's traceback says nothing.
        raise _interrupted(target, given) from None
    finally:
        if client is not None:
            client.close()
    summary["seconds"] = time.perf_counter() - t0
    return summary


def _interrupted(target: Path, given: list[Path]) -> BatchInterrupted:
    """How many of the frames asked are stored complete, once a run is interrupted."""
    asked = {str(p.resolve()) for p in given}
    stored = 0
    try:
        if is_survey(target):
            idx = read_index(target)
            stored = sum(1 for p, d in zip(idx["frame_path"], idx["done"], strict=True)
                         if d and p in asked)
    except ValueError:  # a store damaged before this run: nothing of it counts
        pass
    return BatchInterrupted(str(target), stored, len(asked))


def _layout_text(layout: Any) -> Any:
    """A layout as something every worker can be sent (checked here, once)."""
    from ..io import _as_layout

    return _as_layout(layout)


_OWN = ("auto", "in-process", "local cluster")  # run here, or on a cluster started here

AUTO_CLUSTER_S = 10.0
"""With ``workers=None``: the least time (s) the frames left after the first chunk would
take in this process for a local cluster to be started for them. Starting one costs
2 to 5 s (its processes start and import the imaging code; measured on 2 cores,
benchmarks/results_batch.json), so below this the run stays in this process."""


def _run(given: list[Path], target: Path, settings: Settings, sched: str, client: Any, *,
         strict: bool, overwrite: bool, exists: bool, progress: bool,
         layout: Any = None,
         on_start: Callable[[dict[str, Any]], None] | None = None,
         workers: int | None = None, retry_bad: bool = False) -> dict[str, Any]:
    """The run itself, once the arguments are checked (see :func:`run_batch`)."""
    # Distinct frames, and the checks that need no reading, before anything is written.
    frames_in: list[tuple[Path, str]] = []  # (absolute path, name as given)
    seen: set[Path] = set()
    skipped: list[dict[str, Any]] = []
    for p in given:
        key = p.resolve()
        if key in seen:
            continue
        seen.add(key)
        problem = (None if p.is_file() else "is not a file") or \
            ("is empty" if p.stat().st_size == 0 else None)
        if problem:
            _skip(skipped, str(p), problem, strict)
        else:
            frames_in.append((key, str(p)))
    n_frames = len(seen)
    # The files' stamps before any is read: a frame found bad is remembered with these, so
    # a file changed while the run read it is read again by the next run.
    stamps = {str(k): file_stamp(k) for k, _ in frames_in}
    read_bad: dict[str, str] = {}  # absolute path -> reason: found bad when read or imaged

    fresh = overwrite or not exists  # a new store is laid out
    if not fresh:
        old, geometry = stored_settings(target)
        diff = old.differences(settings)
        if diff:
            raise SettingsMismatchError(str(target), diff)
        known_bad = {} if retry_bad else remembered_bad(target)
        keep = []
        for key, name in frames_in:
            reason = known_bad.get(str(key))
            if reason is None:
                keep.append((key, name))
                continue
            if strict:
                raise ValueError(f"frame {name!r}: {reason} (found by an earlier run; strict: "
                                 "nothing was written; retry_bad reads it again)")
            skipped.append({"name": name, "reason": reason, "remembered": True})
            read_bad[str(key)] = reason
        frames_in = keep
    else:
        found, refused = _reference(frames_in, strict, layout)
        for name, reason in refused:
            skipped.append({"name": name, "reason": reason})
        refused_names = {name for name, _ in refused}
        read_bad.update({str(k): r for k, n in frames_in for name, r in refused if n == name})
        frames_in = [f for f in frames_in if f[1] not in refused_names]
        if found is None:
            raise ValueError(f"none of the {n_frames} frames can be imaged: "
                             + "; ".join(f"{s['name']}: {s['reason']}" for s in skipped[:3]))
        geometry = found
        # Before the store is laid out: a refused run writes nothing.
        plan = plan_space(target, settings, geometry, len(frames_in),
                          reclaimed=folder_bytes(target) if exists else 0)
        create_store(target, settings, geometry, replace=exists,
                     chunk=frames_per_chunk(frame_bytes(settings, geometry), len(frames_in)))

    slots = register_frames(target, [p for p, _ in frames_in])
    index = read_index(target)
    done, chunk = index["done"], int(index["group"]["image"].chunks[0])
    todo = [(slot, str(p), name) for slot, (p, name) in zip(slots, frames_in, strict=True)
            if not done[slot]]
    if todo and not fresh:  # (a new store was checked before it was laid out)
        plan = plan_space(target, settings, geometry, len(todo))
    if todo and on_start is not None:
        on_start(plan)
    token = uuid.uuid4().hex
    stop_file = target.with_name(f".{target.name}.{token}.stop")
    # Dask's local pools wait for each task's writes; elsewhere a worker's last chunk is
    # written while it images its next task, and the writes are waited for at the end.
    job = Job(str(target), token, settings, geometry, strict, layout,
              stop_file=str(stop_file) if sched not in schedule.LOCAL else None,
              drain=sched in ("threads", "processes"))
    records: list[dict[str, Any]] = []
    used = {"scheduler": sched, "workers": 1}

    def remember() -> None:
        # Why frames are missing, kept in the store for `holoradar info` and the next run
        # (by absolute path), also when the run stops early.
        by_name = {name: str(k) for k, name in frames_in}
        for r in records:
            if r["status"] == "skipped" and r["name"] in by_name:
                read_bad[by_name[r["name"]]] = r["reason"]
        reasons = {str(Path(k["name"]).resolve()): k["reason"] for k in skipped}
        reasons.update(read_bad)
        note_skipped(target, reasons, [str(p) for p in seen],
                     {k: v for k, v in stamps.items() if k in read_bad and v is not None})

    try:
        if todo:
            _execute(todo, chunk, job, sched, client, workers, progress, records, used)
    except BaseException:
        try:
            remember()
        except Exception:  # the run's own exception is the one to see
            pass
        raise
    else:
        remember()
    finally:
        stop_file.unlink(missing_ok=True)
    skipped += [{"name": r["name"], "reason": r["reason"]} for r in records
                if r["status"] == "skipped"]
    return {"store": str(target), "frames": n_frames,
            "done": sum(r["status"] == "done" for r in records),
            "resumed": len(frames_in) - len(todo), "skipped": skipped, "seconds": 0.0,
            "scheduler": used["scheduler"], "workers": used["workers"],
            "remembered": sum(bool(k.get("remembered")) for k in skipped),
            "warnings": sorted({w for r in records for w in r.get("warnings", [])}),
            "bytes_estimated": plan["bytes"] if todo else 0}


def _execute(todo: list[tuple[int, str, str]], chunk: int, job: Job, sched: str, client: Any,
             workers: int | None, progress: bool, records: list[dict[str, Any]],
             used: dict[str, Any]) -> None:
    """Run the tasks where ``sched`` says; records appended to ``records`` as tasks end.
    Returns once every write of the run is done (or failed: its error is raised)."""
    try:
        _dispatch(todo, chunk, job, sched, client, workers, progress, records, used)
    finally:
        drain_writes()  # the writes of this process's tasks


def _on_cluster(tasks: list[list[tuple[int, str, str]]], job: Job, client: Any,
                progress: bool, records: list[dict[str, Any]]) -> None:
    """The tasks on a ``dask.distributed`` cluster, then every worker's writes waited for."""
    try:
        schedule.run_tasks(process_chunk, tasks, job, "cluster", progress=progress,
                           client=client, into=records)
    except BaseException:
        try:
            client.run(drain_writes)
        except Exception:  # the run's own error says more
            pass
        raise
    client.run(drain_writes)  # a write's error is raised here


def _dispatch(todo: list[tuple[int, str, str]], chunk: int, job: Job, sched: str, client: Any,
              workers: int | None, progress: bool, records: list[dict[str, Any]],
              used: dict[str, Any]) -> None:
    if sched not in _OWN:  # Dask's local schedulers, or a cluster's address
        n = schedule.cluster_workers(client) if client is not None \
            else schedule.local_workers(sched)
        used["workers"] = n
        if client is not None:
            _on_cluster(schedule.plan_tasks(todo, chunk), job, client, progress, records)
        else:
            schedule.run_tasks(process_chunk, schedule.plan_tasks(todo, chunk), job, sched,
                               progress=progress, into=records)
        return
    tasks = schedule.plan_tasks(todo, chunk)
    if sched == "in-process":
        used["scheduler"] = "in-process"
        schedule.run_here(process_chunk, tasks, job, progress=progress, into=records)
        return
    n = workers if sched == "local cluster" else schedule.usable_cores()
    if sched == "auto":
        # The first chunk here, timed; a cluster only for work that outlasts its start.
        used["scheduler"] = "in-process"
        if n < 2 or len(tasks) < 2:
            schedule.run_here(process_chunk, tasks, job, progress=progress, into=records)
            return
        schedule.run_here(process_chunk, tasks[:1], job, into=records)
        # A frame's time here: the median (the first one pays this process's imports).
        times = [r["seconds"] for r in records if "seconds" in r]
        per_frame = float(np.median(times)) if times else 0.0
        tasks = tasks[1:]
        left = sum(len(t) for t in tasks) * per_frame
        if left < AUTO_CLUSTER_S:
            schedule.run_here(process_chunk, tasks, job, progress=progress, into=records)
            return
        n = min(n, len(tasks))
    assert n is not None
    used["scheduler"], used["workers"] = "local cluster", n
    cluster, own = schedule.local_cluster(n)
    try:
        _on_cluster(tasks, job, own, progress, records)
    finally:
        own.close()
        cluster.close()


def _skip(skipped: list[dict[str, str]], name: str, reason: str, strict: bool) -> None:
    if strict:
        raise ValueError(f"frame {name!r}: {reason} (strict: nothing was written)")
    skipped.append({"name": name, "reason": reason})


def _reference(frames: list[tuple[Path, str]], strict: bool,
               layout: Any = None) -> tuple[FrameGeometry | None, list[tuple[str, str]]]:
    """The geometry of the first frame that can be read, and the frames refused before it."""
    refused: list[tuple[str, str]] = []
    for path, name in frames:
        holo, problem = read_frame(str(path), None, layout)
        if holo is not None:
            return FrameGeometry.of(holo), refused
        assert problem is not None
        if strict:
            raise ValueError(f"frame {name!r}: {problem} (strict: nothing was written)")
        refused.append((name, problem))
    return None, refused
