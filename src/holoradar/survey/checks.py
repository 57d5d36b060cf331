"""The arguments of :func:`~holoradar.survey.run_batch` checked before anything is read or
written: where the frames are imaged, the frames' paths, the store's path, the layout."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..io.output import check_output
from . import schedule
from .store import is_survey

__all__ = ["check_store", "frame_paths", "layout_text", "where_asked"]


def where_asked(workers: Any, scheduler: str | None) -> tuple[str, int | None]:
    """Where a run images: ``"auto"``, ``"in-process"``, ``"local cluster"`` or the Dask
    scheduler (name or address) asked; and the local workers asked (None: not asked)."""
    n_workers = schedule.check_workers(workers)
    if n_workers is not None and scheduler is not None:
        raise ValueError(f"give workers (a local cluster started for the run) or scheduler, "
                         f"not both: got workers={workers!r}, scheduler={scheduler!r}")
    sched = "auto" if scheduler is None else schedule.check_scheduler(scheduler)
    if n_workers is not None:
        sched = "in-process" if n_workers == 1 else "local cluster"
    return sched, n_workers


def frame_paths(frames: Sequence[str | os.PathLike[str]]) -> list[Path]:
    """The frames asked, as paths (``ValueError``: one path, or none)."""
    if isinstance(frames, str | os.PathLike):
        raise ValueError("frames must be a sequence of paths (a list), not one path")
    given = [Path(f) for f in frames]
    if not given:
        raise ValueError("frames: no frames given")
    return given


def check_store(store: str | os.PathLike[str], given: list[Path]) -> tuple[Path, bool]:
    """The store's path, and whether it exists (a survey store, then), checked against the
    frames: ``ValueError`` for a bad path, one that holds a frame, or another folder."""
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
    return target, exists


def layout_text(layout: Any) -> Any:
    """A layout as something every worker can be sent (checked here, once)."""
    from ..io import as_layout

    return as_layout(layout)
