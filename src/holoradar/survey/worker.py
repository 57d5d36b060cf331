"""The work of one task: read frames, image them, write them to the store a chunk at a time.

This runs in the caller's process (one worker) or on Dask workers (a local
cluster's processes, or a cluster's machines): it needs the frames' files and
the store at the same paths as the caller. A task holds the frames of whole
chunks of the store (:func:`~holoradar.survey.schedule.plan_tasks`), so no two
tasks write the same chunk; each chunk's images are written with one write, by a
thread of the worker's own while it images the next frames.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..data.hologram import Hologram
from ..imaging.migration.image import image_of
from ..io import load
from .frames import FrameGeometry, frame_position
from .schedule import stop_requested
from .settings import Settings
from .store import as_block, chunk_of, write_frames

__all__ = ["Job", "drain_writes", "image_frame", "process_chunk", "read_frame", "warm"]


@dataclass(frozen=True)
class Job:
    """What every task of one run shares (pickled to the workers).

    ``stop_file``: a path whose existence asks the tasks to stop after the frame in
    hand (a run on a cluster, whose workers share no memory with the caller).
    ``drain``: each task waits for its own writes before it returns (True); False
    leaves a task's last chunk writing while the worker's next task images its
    frames, and the caller waits for every worker's writes (:func:`drain_writes`)
    before it counts or reports the store.
    """

    store: str
    token: str
    settings: Settings
    geometry: FrameGeometry
    strict: bool
    layout: Any = None
    stop_file: str | None = None
    drain: bool = True


def read_frame(path: str, geometry: FrameGeometry | None,
               layout: Any = None) -> tuple[Hologram | None, str | None]:
    """``(hologram, None)``, or ``(None, why it cannot be a frame)``. The I/Q sign is
    checked when probing the first frame (``geometry`` None), not for every frame."""
    try:
        holo = load(path, layout=layout, iq_check=geometry is None)
    except ValueError as exc:
        return None, str(exc)
    if not isinstance(holo, Hologram):
        return None, "holds an Image, not a Hologram"
    if geometry is None:
        try:
            FrameGeometry.of(holo)
        except ValueError as exc:
            return None, str(exc)
        return holo, None
    problem = geometry.mismatch(holo)
    return (None, problem) if problem else (holo, None)


def image_frame(path: str, name: str, job: Job) -> tuple[dict[str, Any], Any]:
    """Read and image one frame: ``(record, (image data, position))``, or ``(record,
    None)`` for a frame that cannot be imaged.

    The record is ``{"name", "status", ...}``: ``status`` ``"done"`` or ``"skipped"``
    (with a ``reason``); with ``job.strict`` a frame that cannot be imaged raises
    ``ValueError`` instead. Nothing is written here
    (:func:`process_chunk` writes, and gathers the warnings).
    """
    holo, problem = read_frame(path, job.geometry, job.layout)
    result = None
    if holo is not None:
        s = job.settings
        try:
            img = image_of(holo, s.z, s.medium,
                           s.migration.replace(dtype=np.dtype(job.geometry.dtype)))
        except ValueError as exc:
            problem = f"cannot be imaged: {exc}"
        else:
            want = job.geometry.image_shape(s.z.size, s.upsample)
            if img.data.shape != want:
                problem = f"its image has shape {img.data.shape}, the survey's {want}"
            else:
                result = (img.data, frame_position(holo))
    if problem is not None:
        if job.strict:
            raise ValueError(f"frame {name!r}: {problem} (strict: the run stops; the frames "
                             "finished so far are in the store)")
        return {"name": name, "status": "skipped", "reason": problem}, None
    return {"name": name, "status": "done"}, result


class _Writer:
    """Writes a worker's finished chunks on a thread of its own, one at a time, while the
    worker images the next frames (compressing and writing files release the GIL).

    At most one write waits behind the one running, so at most two chunks of images
    are held in memory. The writes run in the order submitted, never two at once (a
    single-thread executor): a chunk is complete before the next starts, whatever the
    load (two writer threads at once let a later chunk finish first). :meth:`drain`
    waits for all and raises a write's error.
    """

    def __init__(self, store: str, token: str) -> None:
        from concurrent.futures import ThreadPoolExecutor

        self.store, self.token = store, token
        self.pending: list[Future[None]] = []
        self.pool = ThreadPoolExecutor(max_workers=1,
                                       thread_name_prefix="holoradar-survey-writer")

    def submit(self, slots: list[int], images: list[np.ndarray],
               positions: list[tuple[float, float, float]]) -> None:
        if not slots:
            return
        while len(self.pending) > 1:
            self.pending.pop(0).result()
        real = np.float32 if images[0].dtype == np.complex64 else np.float64
        block = as_block(images, real)  # here: the worker's thread is the one with time
        self.pending.append(self.pool.submit(write_frames, self.store, self.token, slots,
                                             block, positions))

    def drain(self) -> None:
        while self.pending:
            self.pending.pop(0).result()

    def close(self) -> None:
        """Drain, then end the writer's thread (it takes no more writes)."""
        try:
            self.drain()
        finally:
            self.pool.shutdown(wait=True)


_WRITERS: dict[tuple[str, str], _Writer] = {}  # this process's writer of a run


def _writer(store: str, token: str) -> _Writer:
    key = (store, token)
    w = _WRITERS.get(key)
    if w is None:
        drain_writes()  # another run's writes (one run at a time per process)
        w = _WRITERS[key] = _Writer(store, token)
    return w


def drain_writes() -> int:
    """Wait for this process's pending chunk writes (of any run); raise a write's error.

    Returns the number of runs whose writers were drained. Called by the caller after a
    run's tasks (in each worker of a cluster: ``client.run(drain_writes)``).
    """
    n = 0
    while _WRITERS:
        _, w = _WRITERS.popitem()
        w.close()
        n += 1
    return n


def process_chunk(chunk: Sequence[tuple[int, str, str]], job: Job) -> list[dict[str, Any]]:
    """Image the frames ``(slot, path, name)`` of a task in turn, and store them.

    The images are gathered per chunk of the store and each chunk written once
    (images, positions and times, then the ``done`` flags) on a writer thread, while
    the next frames are imaged. After Ctrl-C
    (:func:`~holoradar.survey.schedule.stop_requested`), or when a frame stops the
    run (``strict``) or anything raises, no further frame is started: the frames
    imaged so far are written, the writes waited for, and only then the task returns
    or raises. Records are :func:`image_frame`'s, with
    ``seconds`` (the frame's share of the task's time) and ``warnings`` (each
    distinct warning the task raised, once, as ``"Category: message"``, on its first
    record; a worker's own output is not the user's console).
    """
    out: list[dict[str, Any]] = []
    if not chunk:
        return out
    per = chunk_of(job.store, job.token)
    writer = _writer(job.store, job.token)
    group = -1
    slots: list[int] = []
    images: list[np.ndarray] = []
    positions: list[tuple[float, float, float]] = []
    ok = False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            t = time.perf_counter()
            for slot, path, name in chunk:
                if stop_requested(job.stop_file):  # the run was interrupted: leave the rest
                    break
                if slot // per != group:  # a new chunk of the store: the last is complete
                    writer.submit(slots, images, positions)
                    slots, images, positions = [], [], []
                    group = slot // per
                rec, result = image_frame(path, name, job)
                now = time.perf_counter()
                rec["seconds"], t = now - t, now
                out.append(rec)
                if result is not None:
                    slots.append(slot)
                    images.append(result[0])
                    positions.append(result[1])
            ok = True
        finally:
            # Whatever ended the task (its last frame, Ctrl-C, a strict stop): what was
            # imaged is handed to the writer; waited for here unless the caller drains.
            try:
                writer.submit(slots, images, positions)
            finally:
                if job.drain or not ok or stop_requested(job.stop_file):
                    writer.drain()
    for j, rec in enumerate(out):
        rec["warnings"] = [] if j else sorted({f"{w.category.__name__}: {w.message}"
                                               for w in caught})
    return out


def warm() -> None:
    """Import what a task needs (a worker's first frame then costs what the others do):
    holoradar's imaging and readers, SciPy's FFT (0.3 s or more of imports on the first
    migrate), h5py and Zarr. Run once per worker process as it starts."""
    import h5py  # noqa: F401
    import scipy.fft  # noqa: F401
    import zarr  # noqa: F401

    from ..physics import propagation  # noqa: F401
