"""One pool of threads for the array work that NumPy does without the GIL."""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from functools import cache

POOL_SIZE = os.cpu_count() or 1


@cache
def pool() -> ThreadPoolExecutor:
    """The process's thread pool, one thread per core (made on first use)."""
    return ThreadPoolExecutor(max_workers=POOL_SIZE, thread_name_prefix="holoradar")
