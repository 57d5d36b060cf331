"""One pool of threads for the array work that NumPy does without the GIL, and the
number of threads an FFT may take.

Both are every core unless the environment variable ``HOLORADAR_THREADS`` (a
positive whole number, read at import and by :func:`apply_environment`) says
fewer: a survey's worker processes set it to 1, so that N workers on N cores do
not each spread their FFTs over all of them and wait on one another.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from functools import cache


def _from_environment() -> int | None:
    raw = os.environ.get("HOLORADAR_THREADS", "").strip()
    if not raw:
        return None
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        raise ValueError(f"HOLORADAR_THREADS must be a whole number >= 1, got {raw!r}")
    return n


LIMIT = _from_environment()
"""Threads allowed by ``HOLORADAR_THREADS``; None: every core."""

POOL_SIZE = LIMIT or os.cpu_count() or 1
"""Threads of :func:`pool` (read it as ``_threads.POOL_SIZE``: it follows
:func:`apply_environment`)."""


def apply_environment() -> None:
    """Read ``HOLORADAR_THREADS`` again (a worker process whose environment was set
    after this module was imported), before the pool is first used."""
    global LIMIT, POOL_SIZE
    LIMIT = _from_environment()
    POOL_SIZE = LIMIT or os.cpu_count() or 1
    pool.cache_clear()

_SMALL_FFT = 128 * 128
"""Below this many points an FFT runs on one thread (threads cost more than they share)."""


def fft_workers(points: int) -> int:
    """``workers=`` for a ``scipy.fft`` call on ``points`` points per transform: one
    thread for a small grid, else every core (-1) or ``HOLORADAR_THREADS``.

    Examples
    --------
    >>> fft_workers(64 * 64)
    1
    """
    if points < _SMALL_FFT:
        return 1
    return LIMIT if LIMIT is not None else -1


@cache
def pool() -> ThreadPoolExecutor:
    """The process's thread pool, one thread per core (made on first use)."""
    return ThreadPoolExecutor(max_workers=POOL_SIZE, thread_name_prefix="holoradar")
