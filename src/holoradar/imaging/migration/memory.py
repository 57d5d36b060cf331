"""Refuse, before any work, an image volume that will not fit in memory."""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

__all__ = ["available_memory", "check_fits"]

_CHECK_ABOVE = 1 << 26  # bytes of peak memory above which migrate asks what is available


def available_memory() -> int:
    """Bytes of memory available to this process now (psutil where installed, else
    the free physical pages)."""
    try:
        import psutil
    except ImportError:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    return int(psutil.virtual_memory().available)


def check_fits(hologram: Any, planes: int, upsample: Any, dtype: Any, *,
               factor: float) -> None:
    """Refuse, before any work, an image volume that will not fit in memory.

    Parameters
    ----------
    hologram : Hologram
        The data (its leading axes and grid give the volume's shape).
    planes : int
        Planes per leading index (frequencies included for ``combine="none"``).
    upsample : int
        Output pixels per pitch.
    dtype : numpy dtype or None
        Working precision (None: complex64 for complex64 data, else complex128).
    factor : float
        Peak memory of the computation in units of the output volume.

    Raises
    ------
    MemoryError
        ``factor`` x the volume exceeds :func:`available_memory`; the message gives
        the volume's size and the ways out. Below 64 MiB it is not asked.
    """
    work = np.dtype(dtype) if dtype is not None else np.dtype(
        np.complex64 if hologram.data.dtype == np.complex64 else np.complex128)
    u = int(upsample) if isinstance(upsample, int | np.integer) and upsample >= 1 else 1
    ny, nx = hologram.data.shape[-2:]
    lead = hologram.data.shape[:-3] if hologram.is_wideband else hologram.data.shape[:-2]
    oy, ox = u * (ny - 1) + 1, u * (nx - 1) + 1
    size = math.prod(lead) * planes * oy * ox * work.itemsize
    if factor * size < _CHECK_ABOVE:
        return   # asking the system (~0.1-0.3 ms) would cost a small plane 5-10%
    avail = available_memory()
    if factor * size > avail:
        gib = 2.0**30
        cheaper = "" if work == np.complex64 else ", dtype=numpy.complex64 (half the size)"
        raise MemoryError(
            f"the image volume ({planes} planes x {oy} x {ox} pixels"
            f"{' x ' + str(int(np.prod(lead))) if lead else ''}, {work.name}) takes "
            f"{size / gib:.2f} GiB and about {factor * size / gib:.2f} GiB while it is "
            f"computed, more than the {avail / gib:.2f} GiB of memory available: image "
            f"fewer planes at a time{cheaper}, or store a survey frame by frame "
            "(holoradar batch writes a survey store)")
