"""Wall-clock timing shared by the benchmarks: the times of repeated calls, and their
best (the least disturbed by other work on a shared machine) or median (what a user
sees on it). Imported by the scripts beside it (run as ``python benchmarks/NAME.py``,
which puts this folder on the path)."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import Any


def times(fn: Callable[[], Any], n: int, *, warm: bool = True) -> list[float]:
    """Seconds of ``n`` calls of ``fn``, after one untimed call when ``warm`` (plans,
    caches and imports built)."""
    if warm:
        fn()
    out = []
    for _ in range(n):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return out


def best(fn: Callable[[], Any], n: int = 3, *, warm: bool = True) -> float:
    """The fastest of ``n`` calls (see :func:`times`)."""
    return min(times(fn, n, warm=warm))


def median(fn: Callable[[], Any], n: int = 3, *, warm: bool = True) -> float:
    """The median of ``n`` calls (see :func:`times`)."""
    return statistics.median(times(fn, n, warm=warm))
