"""The room a run's images take on the store's disk, checked before any is imaged."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

from .frames import FrameGeometry
from .settings import Settings
from .store import frame_bytes

__all__ = ["bytes_text", "folder_bytes", "plan_space"]


def bytes_text(n: float) -> str:
    """Bytes for a person: ``3.43 GB`` (powers of 1000).

    Examples
    --------
    >>> bytes_text(3.43e9), bytes_text(468512), bytes_text(512)
    ('3.43 GB', '469 kB', '512 bytes')
    """
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}" if n < 10 * scale else f"{n / scale:.0f} {unit}"
    return f"{int(n)} bytes"


def folder_bytes(path: Path) -> int:
    """The bytes of every file under ``path`` (what replacing that folder frees)."""
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())


def plan_space(target: Path, settings: Settings, geometry: FrameGeometry, n_frames: int, *,
               reclaimed: int = 0) -> dict[str, Any]:
    """The store's growth for ``n_frames`` images; ValueError when the disk cannot hold it.

    ``reclaimed``: bytes freed once the new store is in place (an old store replaced).
    The size before compression is the bound: compression saves only about a tenth.
    The result is the plan :func:`~holoradar.survey.run_batch` gives its ``on_start``.
    """
    per = frame_bytes(settings, geometry)
    need = n_frames * per
    free = shutil.disk_usage(target.parent).free + reclaimed
    shape = geometry.image_shape(settings.z.size, settings.upsample)
    dtype = "float32" if geometry.dtype == "complex64" else "float64"
    if need > free:
        raise ValueError(
            f"store {str(target)!r} would need up to {bytes_text(need)} for {n_frames} frames "
            f"({bytes_text(per)} each: {shape[0]} planes of {shape[2]} x {shape[1]} pixels, I and "
            f"Q as {dtype}) but its disk has {bytes_text(free)} free: free some space, put the "
            "store on another disk, or image fewer planes or at a smaller upsample")
    return {"frames": n_frames, "bytes": need, "bytes_per_frame": per,
            "image_shape": list(shape), "dtype": dtype, "free": free, "store": str(target)}
