"""Running the tasks: in the caller's process, on a local cluster, or on Dask.

The frames to image are cut into tasks of whole chunks of the store
(:func:`plan_tasks`: no two tasks write one chunk). ``workers`` (a positive
integer) runs them in the caller's process (1) or on a
``dask.distributed.LocalCluster`` of that many single-threaded worker processes
started for the run (:func:`local_cluster`); ``scheduler`` names one of Dask's
local schedulers (``"processes"``, ``"threads"``, ``"synchronous"``, the last
the caller's process) or is the address of a running ``dask.distributed``
scheduler (``"tcp://host:8786"``).
"""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Callable, Sequence
from contextlib import nullcontext
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["DEFAULT_SCHEDULER", "LOCAL", "check_scheduler", "check_workers", "cluster_workers",
           "connect", "local_cluster", "local_workers", "plan_tasks", "process_pool",
           "run_here", "run_tasks", "split", "stop_requested", "usable_cores"]

LOCAL = ("processes", "threads", "synchronous")
DEFAULT_SCHEDULER = "processes"
"""The local scheduler used by default. Reading a frame (NetCDF through xarray and
h5netcdf) holds the GIL most of the time, so threads do not scale (slower than
one thread, measured); processes do (docs/surveys.md gives the figures)."""

_POOL: dict[int, tuple[Any, Any]] = {}  # workers -> (the session's pool, its stop event)


def check_scheduler(scheduler: str | None) -> str:
    """The scheduler to use: a local name or a distributed address (``ValueError`` if neither).

    Examples
    --------
    >>> check_scheduler(None), check_scheduler("threads"), check_scheduler("tcp://10.0.0.1:8786")
    ('processes', 'threads', 'tcp://10.0.0.1:8786')
    """
    if scheduler is None:
        return DEFAULT_SCHEDULER
    if not isinstance(scheduler, str) or not scheduler.strip():
        raise ValueError(f"scheduler must be None, a local scheduler {LOCAL} or the address of "
                         f"a dask.distributed scheduler, got {scheduler!r}")
    s = scheduler.strip()
    if s in LOCAL:
        return s
    if ":" in s:
        return s
    raise ValueError(f"scheduler must be one of {LOCAL} or the address of a dask.distributed "
                     f"scheduler such as 'tcp://127.0.0.1:8786', got {scheduler!r}")


def split(items: Sequence[Any], workers: int, *, most: int = 4) -> list[list[Any]]:
    """Cut ``items`` into tasks: about 16 tasks per worker for balance, at most ``most``
    frames each (a task is a few ms of Dask overhead; a frame tens of ms).

    Examples
    --------
    >>> [len(t) for t in split(list(range(10)), 2)]
    [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]
    >>> [len(t) for t in split(list(range(200)), 2)][:3]
    [4, 4, 4]
    """
    size = max(1, min(most, len(items) // (16 * max(1, workers))))
    return [list(items[i:i + size]) for i in range(0, len(items), size)]


def plan_tasks(todo: Sequence[tuple[int, str, str]], chunk: int, *,
               least: int = 1) -> list[list[tuple[int, str, str]]]:
    """Tasks of whole chunks: the frames ``(slot, path, name)`` grouped by the store's chunk
    (``slot // chunk``), in slot order; neighbouring chunks joined while a task holds
    fewer than ``least`` frames (a resumed store may leave one or two frames a chunk).

    Examples
    --------
    >>> todo = [(s, f"f{s}.nc", f"f{s}.nc") for s in (0, 1, 2, 5, 6, 9)]
    >>> [[t[0] for t in task] for task in plan_tasks(todo, 4)]
    [[0, 1, 2], [5, 6], [9]]
    >>> [[t[0] for t in task] for task in plan_tasks(todo, 4, least=3)]
    [[0, 1, 2], [5, 6, 9]]
    """
    tasks: list[list[tuple[int, str, str]]] = []
    last = None
    for item in sorted(todo, key=lambda t: t[0]):
        group = item[0] // max(1, chunk)
        if group != last and (not tasks or len(tasks[-1]) >= least):
            tasks.append([])
        tasks[-1].append(item)
        last = group
    return tasks


def check_workers(workers: Any) -> int | None:
    """``workers`` as an int >= 1 (None stays None: the default); ``ValueError`` otherwise.

    Examples
    --------
    >>> check_workers(2), check_workers(None)
    (2, None)
    >>> check_workers(0)
    Traceback (most recent call last):
    ...
    ValueError: workers must be a positive integer (the number of worker processes), got 0
    """
    if workers is None:
        return None
    if isinstance(workers, bool) or not isinstance(workers, int | np.integer) or workers < 1:
        raise ValueError("workers must be a positive integer (the number of worker "
                         f"processes), got {workers!r}")
    return int(workers)


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity where the platform tells it)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def local_workers(name: str) -> int:
    """Workers of a local scheduler (Dask's ``num_workers`` setting, else the cores)."""
    import dask

    if name == "synchronous":
        return 1
    return int(dask.config.get("num_workers", None) or os.cpu_count() or 1)


def run_here(func: Callable[..., list[dict[str, Any]]], tasks: list[list[Any]], job: Any, *,
             progress: bool = False, into: list[dict[str, Any]] | None = None
             ) -> list[dict[str, Any]]:
    """``func(task, job)`` for every task in the caller's process, in turn (one worker).

    No Dask: a task's frames are imaged here and its chunks written by a thread of this
    process. Ctrl-C stops the frame in hand; the task writes what it had imaged and waits
    for its writes (``func`` does) before KeyboardInterrupt goes on to the caller.
    ``into``: records are appended there as tasks finish (kept if the run stops).
    """
    out: list[dict[str, Any]] = [] if into is None else into
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=sum(len(t) for t in tasks), desc="survey", unit="frame")
    _LOCAL_STOP.clear()
    try:
        for task in tasks:
            recs = func(task, job)
            out.extend(recs)
            if bar is not None:
                bar.update(len(recs))
    except KeyboardInterrupt:
        _LOCAL_STOP.set()
        raise
    finally:
        if bar is not None:
            bar.close()
    return out


def run_tasks(func: Any, tasks: list[list[Any]], job: Any, scheduler: str, *,
              progress: bool = False, client: Any = None,
              into: list[dict[str, Any]] | None = None) -> list[dict[str, Any]]:
    """``func(task, job)`` for every task on ``scheduler``; the records of all frames.

    A task that raises stops the run: the local schedulers stop handing out
    tasks; on a cluster the remaining ones are cancelled. The exception is
    raised here. So is KeyboardInterrupt (Ctrl-C), once the workers have
    stopped: each finishes the frame in hand (``func`` asks :func:`stop_requested`
    between frames), stores what it imaged, and starts no other; a second Ctrl-C
    while they finish terminates local worker processes at once (on a cluster:
    cancels the tasks). ``into``: records are appended there as tasks finish.
    """
    if scheduler == "synchronous":
        return run_here(func, tasks, job, progress=progress, into=into)
    if scheduler in LOCAL:
        # Here, not at import: concurrent.futures.process brings in multiprocessing.
        from concurrent.futures.process import BrokenProcessPool

        import dask
        from dask.diagnostics import ProgressBar

        delayed = [dask.delayed(func, pure=False)(t, job) for t in tasks]
        pool: Any = None
        stop = _LOCAL_STOP
        if scheduler == "processes":
            pool, stop = process_pool(local_workers(scheduler), with_stop=True)
        elif scheduler == "threads":
            # A pool of this run's own, so that an interrupted run can wait for the frames
            # its threads are imaging before the caller counts what is stored.
            from concurrent.futures import ThreadPoolExecutor

            pool = ThreadPoolExecutor(local_workers(scheduler))
        extra = {} if pool is None else {"pool": pool}
        stop.clear()
        _LOCAL_STOP.clear()
        with ProgressBar(minimum=1.0, out=sys.stderr) if progress else nullcontext():
            try:
                results = dask.compute(*delayed, scheduler=scheduler, **extra)
            except BrokenProcessPool as exc:
                _POOL.clear()
                raise RuntimeError(
                    "a worker process of the local 'processes' scheduler died. Run from a "
                    "script? Its processes import the script again: put its code under "
                    "`if __name__ == '__main__':`, or pass scheduler='threads'") from exc
            except KeyboardInterrupt:
                _stop(pool, stop, scheduler)
                raise
            finally:
                if scheduler == "threads":
                    pool.shutdown(wait=True)
        recs = [r for rs in results for r in rs]
        if into is not None:
            into.extend(recs)
        return recs
    return _run_on_cluster(func, tasks, job, client, progress=progress, into=into)


def _run_on_cluster(func: Any, tasks: list[list[Any]], job: Any, client: Any, *,
                    progress: bool, into: list[dict[str, Any]] | None) -> list[dict[str, Any]]:
    """The tasks on a ``dask.distributed`` cluster (see :func:`run_tasks`).

    Ctrl-C: the run's stop file (``job.stop_file``) is made, which every task checks
    before each frame (the workers share no memory with the caller, only the store's
    file system); then every task is waited for: a running one stores the frames it
    imaged and returns, the others return at once. A second Ctrl-C cancels them.
    """
    from distributed import as_completed, wait

    futures = client.map(func, tasks, job=job, pure=False)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=sum(len(t) for t in tasks), desc="survey", unit="frame")
    out: list[dict[str, Any]] = [] if into is None else into
    try:
        for fut in as_completed(futures, loop=client.loop):
            recs = fut.result()  # a task's exception is raised here
            out.extend(recs)
            if bar is not None:
                bar.update(len(recs))
    except KeyboardInterrupt:
        try:
            if job.stop_file:
                Path(job.stop_file).touch()
            wait(futures)
        except BaseException:
            client.cancel(futures)
        raise
    except BaseException:
        client.cancel(futures)
        raise
    finally:
        if bar is not None:
            bar.close()
    return out


WORKER_ENV = {"HOLORADAR_THREADS": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
              "MKL_NUM_THREADS": "1"}
"""The environment of a local cluster's workers: one thread each for holoradar's
FFTs and pool, and for BLAS."""


def local_cluster(workers: int) -> tuple[Any, Any]:
    """A ``dask.distributed.LocalCluster`` of ``workers`` processes of one thread each, and
    its client, for one run (the caller closes both). Its dashboard takes a free port.

    Each worker imports what a task needs as it starts
    (:mod:`holoradar.survey.warm`: the imaging code, SciPy's FFT, h5py, Zarr),
    while the caller lays out the store, and ignores Ctrl-C (the caller stops the
    tasks), and runs its FFTs and BLAS on one thread (:data:`WORKER_ENV`: N workers
    on N cores, not N x N threads waiting on one another), with glibc's own handling of
    freed memory (Dask's ``MALLOC_TRIM_THRESHOLD_`` left out: :func:`_spawn_environ`).
    No dashboard; the
    cluster's own log lines are silenced (a worker's heartbeat error as the scheduler
    stops on Ctrl-C reached the terminal; the tasks' errors come back through their
    futures).
    """
    import logging

    import dask
    from distributed import Client, LocalCluster

    # The workers inherit this process's environment at spawn: where an earlier Dask
    # nanny in it left MALLOC_TRIM_THRESHOLD_ in os.environ, leave it out for them too.
    inherited = os.environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    try:
        with dask.config.set({"distributed.nanny.pre-spawn-environ": _spawn_environ()}):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0", silence_logs=logging.CRITICAL,
                                   preload=["holoradar.survey.warm"], env=WORKER_ENV)
    finally:
        if inherited is not None:
            os.environ["MALLOC_TRIM_THRESHOLD_"] = inherited
    try:
        client = Client(cluster, set_as_default=False)
    except BaseException:
        cluster.close()
        raise
    return cluster, client


def _spawn_environ() -> dict[str, Any]:
    """Dask's environment for new worker processes, less ``MALLOC_TRIM_THRESHOLD_``.

    Dask sets it (64 KiB) so that a long-lived worker hands freed memory back to the
    system; setting it at all also fixes glibc's threshold for serving large blocks by
    fresh mappings, so every array of an imaged frame (hundreds of KiB to MiB) comes
    back as new pages, zeroed by the system at first touch: `load` + `migrate` of a
    128 x 128 frame took 31-33 ms of CPU in such a worker against 20-23 ms without it
    (and 23-26 ms in a plain process). A survey's workers live for one run.
    """
    import dask

    env = dict(dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {})
    env.pop("MALLOC_TRIM_THRESHOLD_", None)
    return env


_LOCAL_STOP = threading.Event()
"""Set after Ctrl-C: the caller's own threads (the threads and synchronous schedulers)
stop after the frame in hand."""

_WORKER_STOP: list[Any] = []
"""In a worker process: its pool's stop event (set by the caller after Ctrl-C)."""


def stop_requested(stop_file: str | None = None) -> bool:
    """Whether the run was interrupted (Ctrl-C): a task stops before its next frame.

    ``stop_file``: the run's stop file (a cluster's run), whose existence says so."""
    return _LOCAL_STOP.is_set() or bool(_WORKER_STOP and _WORKER_STOP[0].is_set()) \
        or (stop_file is not None and os.path.exists(stop_file))


def process_pool(workers: int, *, with_stop: bool = False) -> Any:
    """A pool of ``workers`` processes kept for the session (started once: later runs
    skip the start-up, a second or so of imports per process).

    The processes are forked from a server that has imported the survey code
    (``forkserver``, where the platform has it; else ``spawn``), so they start
    fast and share no threads or locks with the caller. ``with_stop``: also return
    the event that asks its workers to stop (:func:`stop_requested`).
    """
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    entry = _POOL.get(workers)
    if entry is None:
        method = "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"
        ctx = mp.get_context(method)
        if method == "forkserver":
            ctx.set_forkserver_preload(["holoradar.survey.warm"])
        stop = ctx.Event()
        entry = (ProcessPoolExecutor(workers, mp_context=ctx, initializer=_start_worker,
                                     initargs=(stop,)), stop)
        for old, _ in _POOL.values():  # another size asked: let the old pool's processes go
            old.shutdown(wait=False)
        _POOL.clear()
        if not _POOL_CLOSED_AT_EXIT:
            import atexit

            atexit.register(_close_pools)
            _POOL_CLOSED_AT_EXIT.append(True)
        _POOL[workers] = entry
    return entry if with_stop else entry[0]


_POOL_CLOSED_AT_EXIT: list[bool] = []


def _close_pools() -> None:
    """At exit, before modules are torn down: shut the session's pool, which would
    otherwise be collected after concurrent.futures and print "Exception ignored"."""
    for pool, _ in list(_POOL.values()):
        pool.shutdown(wait=True)
    _POOL.clear()


def _start_worker(stop: Any) -> None:
    """Run in each worker process as it starts: keep the pool's stop event, and leave
    Ctrl-C to the caller.

    A terminal sends SIGINT to the whole process group, workers included; left to
    themselves they raise KeyboardInterrupt inside a task and print its traceback (and
    Dask's failure to pickle it) over the user's console. The caller sets ``stop``
    instead, and each worker stops after the frame in hand.
    """
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _WORKER_STOP[:] = [stop]


def _stop(pool: Any, stop: Any, scheduler: str) -> None:
    """After Ctrl-C: stop the local workers, so that the store no longer changes.

    Each worker finishes the frame in hand and starts no other (a frame is written
    whole and marked done last, so the store stays consistent either way, but the
    count the caller reports is then final); tasks not started are cancelled. A
    second Ctrl-C while they finish terminates worker processes at once.
    """
    stop.set()
    _LOCAL_STOP.set()
    if pool is None:  # synchronous: the interrupted frame was the caller's own
        return
    for key, (p, _) in list(_POOL.items()):  # a pool shut down serves no other run
        if p is pool:
            del _POOL[key]
    try:
        pool.shutdown(wait=True, cancel_futures=True)
    except KeyboardInterrupt:
        if scheduler == "processes":
            # The executor keeps its processes in a private attribute (Python 3.14
            # adds terminate_workers()).
            for proc in list((getattr(pool, "_processes", None) or {}).values()):
                proc.terminate()
        raise


def connect(address: str) -> Any:
    """A ``distributed.Client`` of the scheduler at ``address`` (``ValueError`` if unreachable)."""
    from distributed import Client

    try:
        return Client(address, set_as_default=False, timeout="20s")
    except (OSError, TimeoutError) as exc:
        raise ValueError(f"scheduler: cannot reach a dask.distributed scheduler at "
                         f"{address!r} ({type(exc).__name__}: {exc})") from None


def cluster_workers(client: Any) -> int:
    """Threads of all workers of a cluster."""
    return max(1, sum(client.nthreads().values()))
