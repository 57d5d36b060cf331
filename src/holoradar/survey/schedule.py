"""Running the tasks on Dask: a local scheduler, or a ``dask.distributed`` cluster.

No scheduling of our own: the frames are cut into tasks of a few frames each
and handed to Dask. ``scheduler`` names a local scheduler (``"processes"``,
``"threads"``, ``"synchronous"``) or is the address of a running
``dask.distributed`` scheduler (``"tcp://host:8786"``).
"""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Sequence
from contextlib import nullcontext
from typing import Any

__all__ = ["DEFAULT_SCHEDULER", "LOCAL", "check_scheduler", "cluster_workers", "connect",
           "local_workers", "process_pool", "run_tasks", "split", "stop_requested"]

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


def local_workers(name: str) -> int:
    """Workers of a local scheduler (Dask's ``num_workers`` setting, else the cores)."""
    import dask

    if name == "synchronous":
        return 1
    return int(dask.config.get("num_workers", None) or os.cpu_count() or 1)


def run_tasks(func: Any, tasks: list[list[Any]], job: Any, scheduler: str, *,
              progress: bool = False, client: Any = None) -> list[dict[str, Any]]:
    """``func(task, job)`` for every task on ``scheduler``; the records of all frames.

    A task that raises stops the run: the local schedulers stop handing out
    tasks; on a cluster the remaining ones are cancelled. The exception is
    raised here. So is KeyboardInterrupt (Ctrl-C), once the local workers have
    stopped: each finishes the frame in hand (``func`` asks :func:`stop_requested`
    between frames) and starts no other; a second Ctrl-C while they finish
    terminates worker processes at once.
    """
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
        return [r for recs in results for r in recs]
    from distributed import as_completed

    futures = client.map(func, tasks, job=job, pure=False)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=sum(len(t) for t in tasks), desc="survey", unit="frame")
    out: list[dict[str, Any]] = []
    try:
        for fut in as_completed(futures, loop=client.loop):
            recs = fut.result()  # a task's exception is raised here
            out.extend(recs)
            if bar is not None:
                bar.update(len(recs))
    except BaseException:
        client.cancel(futures)
        raise
    finally:
        if bar is not None:
            bar.close()
    return out


_LOCAL_STOP = threading.Event()
"""Set after Ctrl-C: the caller's own threads (the threads and synchronous schedulers)
stop after the frame in hand."""

_WORKER_STOP: list[Any] = []
"""In a worker process: its pool's stop event (set by the caller after Ctrl-C)."""


def stop_requested() -> bool:
    """Whether the run was interrupted (Ctrl-C): a task stops before its next frame."""
    return _LOCAL_STOP.is_set() or bool(_WORKER_STOP and _WORKER_STOP[0].is_set())


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
            ctx.set_forkserver_preload(["holoradar.survey.worker", "h5py"])
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
