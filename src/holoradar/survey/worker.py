"""The work of one task: read frames, image them, write them to the store.

This runs on Dask workers (threads, processes or a cluster's machines): it
needs the frames' files and the store at the same paths as the caller.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..data.hologram import Hologram
from ..imaging.migrate import migrate
from ..io import load
from .frames import FrameGeometry, frame_position
from .schedule import stop_requested
from .settings import Settings
from .store import write_frame

__all__ = ["Job", "process_chunk", "process_frame"]


@dataclass(frozen=True)
class Job:
    """What every task of one run shares (pickled to the workers)."""

    store: str
    token: str
    settings: Settings
    geometry: FrameGeometry
    strict: bool
    layout: Any = None


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


def process_frame(slot: int, path: str, name: str, job: Job) -> dict[str, Any]:
    """Image one frame into its slot; a record ``{"name", "status", "warnings", ...}``.

    ``status`` is ``"done"`` or ``"skipped"`` (with a ``reason``); with
    ``job.strict`` a frame that cannot be imaged raises ``ValueError`` instead.
    Warnings are returned in the record (a worker's own output is not the
    user's console): each once, as ``"Category: message"``.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec = _process_frame(slot, path, name, job)
    rec["warnings"] = sorted({f"{w.category.__name__}: {w.message}" for w in caught})
    return rec


def _process_frame(slot: int, path: str, name: str, job: Job) -> dict[str, Any]:
    t0 = time.perf_counter()
    holo, problem = read_frame(path, job.geometry, job.layout)
    if holo is not None:
        s = job.settings
        try:
            img = migrate(holo, s.z, medium=s.medium, method=s.method,  # type: ignore[arg-type]
                          upsample=s.upsample, dtype=np.dtype(job.geometry.dtype))
        except ValueError as exc:
            problem = f"cannot be imaged: {exc}"
        else:
            want = job.geometry.image_shape(s.z.size, s.upsample)
            if img.data.shape != want:
                problem = f"its image has shape {img.data.shape}, the survey's {want}"
            else:
                write_frame(job.store, job.token, slot, img.data, frame_position(holo))
    if problem is not None:
        if job.strict:
            raise ValueError(f"frame {name!r}: {problem} (strict: the run stops; the frames "
                             "finished so far are in the store)")
        return {"name": name, "status": "skipped", "reason": problem}
    return {"name": name, "status": "done", "seconds": time.perf_counter() - t0}


def process_chunk(chunk: Sequence[tuple[int, str, str]], job: Job) -> list[dict[str, Any]]:
    """:func:`process_frame` on each ``(slot, path, name)`` of a task, in turn; after
    Ctrl-C (:func:`~holoradar.survey.schedule.stop_requested`) no further frame."""
    out = []
    for slot, path, name in chunk:
        if stop_requested():  # the run was interrupted: leave the rest to a rerun
            break
        out.append(process_frame(slot, path, name, job))
    return out
