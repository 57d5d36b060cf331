"""Running the tasks on Dask: a local scheduler, or a ``dask.distributed`` cluster.

No scheduling of our own: the frames are cut into tasks of a few frames each
and handed to Dask. ``scheduler`` names a local scheduler (``"processes"``,
``"threads"``, ``"synchronous"``) or is the address of a running
``dask.distributed`` scheduler (``"tcp://host:8786"``).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from contextlib import nullcontext
from typing import Any

__all__ = ["DEFAULT_SCHEDULER", "LOCAL", "check_scheduler", "cluster_workers", "connect",
           "local_workers", "process_pool", "run_tasks", "split"]

LOCAL = ("processes", "threads", "synchronous")
DEFAULT_SCHEDULER = "processes"
"""The local scheduler used by default. Reading a frame (NetCDF through xarray and
h5netcdf) holds the GIL most of the time, so threads do not scale (slower than
one thread, measured); processes do (docs/surveys.md gives the figures)."""

_POOL: dict[int, Any] = {}


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
    raised here.
    """
    if scheduler in LOCAL:
        # Here, not at import: concurrent.futures.process brings in multiprocessing.
        from concurrent.futures.process import BrokenProcessPool

        import dask
        from dask.diagnostics import ProgressBar

        delayed = [dask.delayed(func, pure=False)(t, job) for t in tasks]
        extra = {"pool": process_pool(local_workers(scheduler))} \
            if scheduler == "processes" else {}
        with ProgressBar(minimum=1.0, out=sys.stderr) if progress else nullcontext():
            try:
                results = dask.compute(*delayed, scheduler=scheduler, **extra)
            except BrokenProcessPool as exc:
                _POOL.clear()
                raise RuntimeError(
                    "a worker process of the local 'processes' scheduler died. Run from a "
                    "script? Its processes import the script again: put its code under "
                    "`if __name__ == '__main__':`, or pass scheduler='threads'") from exc
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


def process_pool(workers: int) -> Any:
    """A pool of ``workers`` processes kept for the session (started once: later runs
    skip the start-up, a second or so of imports per process).

    The processes are forked from a server that has imported the survey code
    (``forkserver``, where the platform has it; else ``spawn``), so they start
    fast and share no threads or locks with the caller.
    """
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    pool = _POOL.get(workers)
    if pool is None:
        method = "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"
        ctx = mp.get_context(method)
        if method == "forkserver":
            ctx.set_forkserver_preload(["holoradar.survey.worker", "h5py"])
        pool = ProcessPoolExecutor(workers, mp_context=ctx)
        for old in _POOL.values():  # another size asked: let the old pool's processes go
            old.shutdown(wait=False)
        _POOL.clear()
        _POOL[workers] = pool
    return pool


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
