"""The one cache facility: named caches, each bounded in bytes or in entries.

What the package keeps between calls (transfer functions and the plans built from
them, the compiled sum's plans, Bessel tables of the layered Green's function, the
last few migrations) lives in caches made here by :func:`named_cache`, each least
recently used out beyond its bound. :func:`cache_report` says what each holds;
:func:`clear_caches` frees them all (or one, by name). They are thread-safe: a
value is made outside the lock (two threads may make the same one; the first kept
wins).

Examples
--------
>>> c = named_cache("example squares", max_entries=2)
>>> c.get(("a",), lambda: 1), c.get(("b",), lambda: 2), c.get(("c",), lambda: 3)
(1, 2, 3)
>>> cache_report()["example squares"]["entries"]   # "a" made room for "c"
2
>>> clear_caches("example squares"); cache_report()["example squares"]["entries"]
0
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Any

__all__ = ["BoundedCache", "cache_report", "clear_caches", "named_cache"]


class BoundedCache:
    """Least-recently-used values, bounded in bytes (a value's ``nbytes``; values
    without it count 0) and/or in entries.

    Parameters
    ----------
    name : str
        What it holds, in words (the key of :func:`cache_report`).
    max_bytes : int, optional
        The most bytes kept (a value larger than this is made but not kept).
    max_entries : int, optional
        The most values kept.
    """

    def __init__(self, name: str, max_bytes: int | None = None,
                 max_entries: int | None = None) -> None:
        self.name = name
        self.max_bytes = max_bytes
        self.max_entries = max_entries
        self._data: OrderedDict[Hashable, Any] = OrderedDict()
        self._bytes = 0
        self._lock = threading.Lock()

    def get(self, key: Hashable, make: Callable[[], Any]) -> Any:
        """The value kept under ``key``, or ``make()``'s, kept."""
        hit = self.lookup(key)
        if hit is not None:
            return hit
        value = make()
        self.put(key, value)
        return value

    def lookup(self, key: Hashable) -> Any:
        """The value kept under ``key`` (now the most recently used), or None."""
        with self._lock:
            if key in self._data:
                self._data.move_to_end(key)
                return self._data[key]
        return None

    def put(self, key: Hashable, value: Any, replace: bool = False) -> None:
        """Keep ``value`` under ``key`` (unless another is kept there already and not
        ``replace``), the least recently used out beyond the bounds."""
        size = int(getattr(value, "nbytes", 0))
        if self.max_bytes is not None and size > self.max_bytes:
            if replace:   # not kept, and what was kept under the key is stale
                with self._lock:
                    if key in self._data:
                        self._bytes -= int(getattr(self._data.pop(key), "nbytes", 0))
            return
        with self._lock:
            if key in self._data:
                if not replace:
                    return
                self._bytes -= int(getattr(self._data.pop(key), "nbytes", 0))
            self._data[key] = value
            self._bytes += size
            while self._data and (
                    (self.max_bytes is not None and self._bytes > self.max_bytes)
                    or (self.max_entries is not None and len(self._data) > self.max_entries)):
                _, old = self._data.popitem(last=False)
                self._bytes -= int(getattr(old, "nbytes", 0))

    def clear(self) -> None:
        """Free every value."""
        with self._lock:
            self._data.clear()
            self._bytes = 0

    @property
    def nbytes(self) -> int:
        """The bytes kept."""
        return self._bytes

    def __len__(self) -> int:
        return len(self._data)


_REGISTRY: dict[str, BoundedCache] = {}
_REGISTRY_LOCK = threading.Lock()


def named_cache(name: str, max_bytes: int | None = None,
                max_entries: int | None = None) -> BoundedCache:
    """The cache called ``name``, made with these bounds on first use.

    Raises
    ------
    ValueError
        Neither bound given.
    """
    if max_bytes is None and max_entries is None:
        raise ValueError(f"cache {name!r} needs max_bytes or max_entries")
    with _REGISTRY_LOCK:
        cache = _REGISTRY.get(name)
        if cache is None:
            cache = _REGISTRY[name] = BoundedCache(name, max_bytes, max_entries)
        return cache


def clear_caches(name: str | None = None) -> None:
    """Free every named cache, or the one called ``name``."""
    with _REGISTRY_LOCK:
        caches = list(_REGISTRY.values()) if name is None else [_REGISTRY[name]]
    for cache in caches:
        cache.clear()


def cache_report() -> dict[str, dict[str, int | None]]:
    """Each named cache's ``entries``, ``bytes`` and bounds (``max_bytes``,
    ``max_entries``)."""
    with _REGISTRY_LOCK:
        caches = list(_REGISTRY.values())
    return {c.name: {"entries": len(c), "bytes": c.nbytes, "max_bytes": c.max_bytes,
                     "max_entries": c.max_entries} for c in caches}
