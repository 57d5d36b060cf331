"""``run_batch``: image every frame of a survey with the same settings, on one or more
worker processes (a local cluster started for the run, or Dask's schedulers).

The steps of a run: the arguments checked (:func:`run_batch`); the frames made distinct
and checked (:mod:`holoradar.survey.intake`); the store laid out, or an existing one
resumed; the frames left imaged where the scheduler says
(:mod:`holoradar.survey.execute`); the frames found bad remembered in the store, and
the summary returned.
"""

from __future__ import annotations

import os
import time
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..physics.medium import Medium
from . import schedule
from .checks import check_store, frame_paths, layout_text, where_asked
from .execute import AUTO_CLUSTER_S as AUTO_CLUSTER_S  # re-exported: documented here
from .execute import OWN, Placement, Todo, run_chunks
from .frames import FrameGeometry
from .intake import Intake, check_frames, drop_remembered, drop_unreadable, remember
from .settings import Settings
from .space import bytes_text as bytes_text  # re-exported: the command line's sizes
from .space import folder_bytes, plan_space
from .store import (
    create_store,
    describe_store,
    frame_bytes,
    frames_per_chunk,
    is_survey,
    read_index,
    register_frames,
    remembered_bad,
    stored_settings,
)
from .worker import Job

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
              on_start: Callable[[dict[str, Any]], None] | None = None,
              crs: Any = None) -> dict[str, Any]:
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
    crs : str or pyproj.CRS, optional
        The projected coordinate reference system (metres: easting, northing) of the
        frames' positions, kept with the store: GeoJSON of its objects is then WGS 84
        longitude and latitude (``holoradar detect -o objects.geojson``).
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
    if crs is not None:
        from ..io.crs import as_crs

        crs = as_crs(crs)
    sched, n_workers = where_asked(workers, scheduler)
    given = frame_paths(frames)
    target, exists = check_store(store, given)
    if crs is not None and exists and not overwrite:
        from .store import check_crs

        check_crs(target, crs)
    # A cluster is reached before anything is written (an unreachable address is an error).
    client = schedule.connect(sched) if sched not in (*schedule.LOCAL, *OWN) else None
    try:
        run = _Run(target, settings, sched, client, n_workers, bool(strict),
                   layout_text(layout), progress)
        summary = _run(run, given, exists=exists, overwrite=overwrite,
                       retry_bad=bool(retry_bad), on_start=on_start)
    except KeyboardInterrupt:
        # The workers have stopped (run_tasks): what the store holds now is what a
        # rerun finds. "from None": the interrupted frame's traceback says nothing.
        raise _interrupted(target, given) from None
    finally:
        if client is not None:
            client.close()
    if crs is not None:
        from .store import set_crs

        set_crs(target, crs)
    from .store import consolidate

    consolidate(target)
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


@dataclass(frozen=True)
class _Run:
    """A run's arguments, once checked (see :func:`run_batch`)."""

    target: Path  # the store
    settings: Settings
    sched: str  # as checks.where_asked says
    client: Any  # the connection to a cluster's address (None: no address)
    workers: int | None  # local workers asked
    strict: bool
    layout: Any  # as checks.layout_text says
    progress: bool


@dataclass(frozen=True)
class _Imaged:
    """What the imaging of a run produced: a record per frame tried, and where."""

    records: tuple[dict[str, Any], ...]
    placement: Placement


def _run(run: _Run, given: list[Path], *, exists: bool, overwrite: bool, retry_bad: bool,
         on_start: Callable[[dict[str, Any]], None] | None) -> dict[str, Any]:
    """The run itself, once the arguments are checked: its summary (see :func:`run_batch`)."""
    # Distinct frames, and the checks that need no reading, before anything is written.
    intake = check_frames(given, run.strict)
    if overwrite or not exists:  # a new store is laid out
        intake, geometry, plan = _lay_out(run, intake, replace=exists)
        todo, chunk = _todo(run.target, intake)
    else:
        intake, geometry = _resume(run, intake, retry_bad)
        todo, chunk = _todo(run.target, intake)
        # What is left must fit (a new store was checked before it was laid out).
        plan = plan_space(run.target, run.settings, geometry, len(todo)) if todo else None
    if todo and on_start is not None:
        assert plan is not None  # (a plan whenever frames are left)
        on_start(plan)
    imaged = _image(run, geometry, intake, todo, chunk)
    return _summary(run.target, intake, todo, imaged, plan)


def _lay_out(run: _Run, intake: Intake, *,
             replace: bool) -> tuple[Intake, FrameGeometry, dict[str, Any]]:
    """A new store for the frames that can be imaged: those, the survey's geometry (the
    first readable frame's) and the plan of its growth (``on_start``).

    Everything is checked before the store is laid out: a refused run writes nothing.
    ``replace``: a store exists there (removed once the new layout is in place; the space
    it frees counts).
    """
    intake, geometry = drop_unreadable(intake, run.strict, run.layout)
    plan = plan_space(run.target, run.settings, geometry, len(intake.frames),
                      reclaimed=folder_bytes(run.target) if replace else 0)
    create_store(run.target, run.settings, geometry, replace=replace,
                 chunk=frames_per_chunk(frame_bytes(run.settings, geometry), len(intake.frames)))
    return intake, geometry, plan


def _resume(run: _Run, intake: Intake, retry_bad: bool) -> tuple[Intake, FrameGeometry]:
    """An existing store, checked against the run's settings: the frames left once those
    it remembers as bad are skipped (unless ``retry_bad``), and the survey's geometry."""
    old, geometry = stored_settings(run.target)
    diff = old.differences(run.settings)
    if diff:
        raise SettingsMismatchError(str(run.target), diff)
    known_bad = {} if retry_bad else remembered_bad(run.target)
    return drop_remembered(intake, known_bad, run.strict), geometry


def _todo(target: Path, intake: Intake) -> tuple[Todo, int]:
    """The frames not done yet, once each has its slot in the store: ``(slot, absolute
    path, name)``; and the frames per chunk of the store."""
    slots = register_frames(target, [p for p, _ in intake.frames])
    index = read_index(target)
    done, chunk = np.array(index["done"]), int(index["group"]["image"].chunks[0])
    # A frame marked done whose chunk is damaged (missing, short, failing its checksum)
    # is imaged again: the rerun repairs the store.
    damaged = {d["path"] for d in describe_store(target)["damaged"]}
    for i, p in enumerate(index["frame_path"]):
        if str(p) in damaged:
            done[i] = False
    todo = [(slot, str(p), name) for slot, (p, name) in zip(slots, intake.frames, strict=True)
            if not done[slot]]
    return todo, chunk


def _image(run: _Run, geometry: FrameGeometry, intake: Intake, todo: Todo,
           chunk: int) -> _Imaged:
    """Image the frames of ``todo``; the frames found bad are remembered in the store, also
    when the run stops early (Ctrl-C, an error: raised once they are)."""
    token = uuid.uuid4().hex
    stop_file = run.target.with_name(f".{run.target.name}.{token}.stop")
    # Dask's local pools wait for each task's writes; elsewhere a worker's last chunk is
    # written while it images its next task, and the writes are waited for at the end.
    job = Job(str(run.target), token, run.settings, geometry, run.strict, run.layout,
              stop_file=str(stop_file) if run.sched not in schedule.LOCAL else None,
              drain=run.sched in ("threads", "processes"))
    records: list[dict[str, Any]] = []  # filled as tasks end: kept if the run stops
    try:
        placement = run_chunks(todo, chunk, job, run.sched, run.client, run.workers,
                               run.progress, into=records) if todo else Placement(run.sched, 1)
    except BaseException:
        try:
            remember(run.target, intake, records)
        except Exception:  # the run's own exception is the one to see
            pass
        raise
    else:
        remember(run.target, intake, records)
    finally:
        stop_file.unlink(missing_ok=True)
    return _Imaged(tuple(records), placement)


def _summary(target: Path, intake: Intake, todo: Todo, imaged: _Imaged,
             plan: dict[str, Any] | None) -> dict[str, Any]:
    """What :func:`run_batch` returns (``seconds`` set by it)."""
    records = imaged.records
    skipped = [*intake.skipped, *({"name": r["name"], "reason": r["reason"]} for r in records
                                  if r["status"] == "skipped")]
    return {"store": str(target), "frames": intake.count,
            "done": sum(r["status"] == "done" for r in records),
            "resumed": len(intake.frames) - len(todo), "skipped": skipped, "seconds": 0.0,
            "scheduler": imaged.placement.scheduler, "workers": imaged.placement.workers,
            "remembered": sum(bool(k.get("remembered")) for k in skipped),
            "warnings": sorted({w for r in records for w in r.get("warnings", [])}),
            "bytes_estimated": plan["bytes"] if todo and plan is not None else 0}
