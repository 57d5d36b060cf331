"""Imaging the chunks of frames a run has left: in this process, on a local cluster started
for the run, on one of Dask's local schedulers, or on a ``dask.distributed`` cluster.

:func:`run_chunks` picks the place from the scheduler's name that
:func:`~holoradar.survey.run_batch` settled on, runs the tasks there
(:mod:`holoradar.survey.schedule`) and returns once every write is done. Each task's
records are appended to the caller's list as the task ends, so that the caller has them
also when the run stops early (Ctrl-C, an error): the frames found bad by then are
remembered in the store.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from . import schedule
from .worker import Job, drain_writes, process_chunk

__all__ = ["AUTO_CLUSTER_S", "OWN", "Placement", "run_chunks"]

Todo = list[tuple[int, str, str]]  # (slot in the store, absolute path, name as given)
Records = list[dict[str, Any]]  # one per task and frame (worker.process_chunk)

OWN = ("auto", "in-process", "local cluster")  # run here, or on a cluster started here

AUTO_CLUSTER_S = 10.0
"""With ``workers=None``: the least time (s) the frames left after the first chunk would
take in this process for a local cluster to be started for them. Starting one costs
2 to 5 s (its processes start and import the imaging code; measured on 2 cores,
benchmarks/results_batch.json), so below this the run stays in this process."""


@dataclass(frozen=True)
class Placement:
    """Where a run's frames were imaged, as its summary reports it.

    Attributes
    ----------
    scheduler : str
        ``"in-process"``, ``"local cluster"``, or the Dask scheduler (name or address)
        asked.
    workers : int
        Worker processes (or threads) that imaged frames.
    """

    scheduler: str
    workers: int


def run_chunks(todo: Todo, chunk: int, job: Job, sched: str, client: Any,
               workers: int | None, progress: bool, *, into: Records) -> Placement:
    """Image the frames of ``todo`` where ``sched`` says; where that was.

    Parameters
    ----------
    todo : list of (int, str, str)
        The frames to image: slot in the store, absolute path, name as given.
    chunk : int
        Frames per chunk of the store (a task writes whole chunks).
    job : Job
        What every task shares.
    sched : str
        One of :data:`OWN`, a Dask local scheduler's name, or a cluster's address.
    client : distributed.Client or None
        The connection to the cluster at that address (None otherwise).
    workers : int or None
        The local cluster's processes, for ``sched == "local cluster"``.
    progress : bool
        Show a progress bar.
    into : list of dict
        The records of each task are appended here as it ends (kept if the run stops).

    Returns
    -------
    Placement
        Once every write of the run is done (or failed: its error is raised).
    """
    try:
        return _dispatch(todo, chunk, job, sched, client, workers, progress, into)
    finally:
        drain_writes()  # the writes of this process's tasks


def _dispatch(todo: Todo, chunk: int, job: Job, sched: str, client: Any, workers: int | None,
              progress: bool, into: Records) -> Placement:
    if sched not in OWN:  # Dask's local schedulers, or a cluster's address
        return _on_dask(todo, chunk, job, sched, client, progress, into)
    tasks = schedule.plan_tasks(todo, chunk)
    if sched == "in-process":
        schedule.run_here(process_chunk, tasks, job, progress=progress, into=into)
        return Placement("in-process", 1)
    if sched == "auto":
        return _auto(tasks, job, progress, into)
    assert workers is not None  # "local cluster" is asked with a number of workers
    return _local_cluster(tasks, job, workers, progress, into)


def _on_dask(todo: Todo, chunk: int, job: Job, sched: str, client: Any, progress: bool,
             into: Records) -> Placement:
    """The tasks on one of Dask's local schedulers or on the cluster of ``client``."""
    n = schedule.cluster_workers(client) if client is not None \
        else schedule.local_workers(sched)
    if client is not None:
        _on_cluster(schedule.plan_tasks(todo, chunk), job, client, progress, into)
    else:
        schedule.run_tasks(process_chunk, schedule.plan_tasks(todo, chunk), job, sched,
                           progress=progress, into=into)
    return Placement(sched, n)


def _auto(tasks: list[Todo], job: Job, progress: bool, into: Records) -> Placement:
    """The first chunk here, timed; a local cluster only for work that outlasts its start."""
    n = schedule.usable_cores()
    if n < 2 or len(tasks) < 2:
        schedule.run_here(process_chunk, tasks, job, progress=progress, into=into)
        return Placement("in-process", 1)
    schedule.run_here(process_chunk, tasks[:1], job, into=into)
    # A frame's time here: the median (the first one pays this process's imports).
    times = [r["seconds"] for r in into if "seconds" in r]
    per_frame = float(np.median(times)) if times else 0.0
    tasks = tasks[1:]
    left = sum(len(t) for t in tasks) * per_frame
    if left < AUTO_CLUSTER_S:
        schedule.run_here(process_chunk, tasks, job, progress=progress, into=into)
        return Placement("in-process", 1)
    return _local_cluster(tasks, job, min(n, len(tasks)), progress, into)


def _local_cluster(tasks: list[Todo], job: Job, n: int, progress: bool,
                   into: Records) -> Placement:
    """The tasks on a local cluster of ``n`` processes started for them (closed after)."""
    cluster, own = schedule.local_cluster(n)
    try:
        _on_cluster(tasks, job, own, progress, into)
    finally:
        own.close()
        cluster.close()
    return Placement("local cluster", n)


def _on_cluster(tasks: list[Todo], job: Job, client: Any, progress: bool,
                into: Records) -> None:
    """The tasks on a ``dask.distributed`` cluster, then every worker's writes waited for."""
    try:
        schedule.run_tasks(process_chunk, tasks, job, "cluster", progress=progress,
                           client=client, into=into)
    except BaseException:
        try:
            client.run(drain_writes)
        except Exception:  # the run's own error says more
            pass
        raise
    client.run(drain_writes)  # a write's error is raised here
