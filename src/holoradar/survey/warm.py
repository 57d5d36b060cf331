"""Imported by each worker process as it starts: what a task needs, imported once.

A worker's first frame would otherwise pay the imports of the imaging code,
SciPy's FFT, h5py and Zarr (a second or more on a busy machine). Also the
``dask_setup`` hook of a ``dask.distributed`` worker's ``preload``: the worker
then ignores Ctrl-C, which a terminal sends to the whole process group; the
caller stops the tasks (:func:`~holoradar.survey.schedule.run_tasks`).
"""

from __future__ import annotations

import signal
import threading
from typing import Any

from .. import _threads
from .worker import warm

__all__ = ["dask_setup"]

_threads.apply_environment()
warm()


def dask_setup(worker: Any) -> None:
    """A ``dask.distributed`` worker's preload hook: leave Ctrl-C to the caller, and
    take the thread limit its environment sets (``HOLORADAR_THREADS``)."""
    _threads.apply_environment()
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
