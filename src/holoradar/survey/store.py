"""The survey store: one Zarr (v3) group holding every frame's image.

Layout (``survey.zarr``; dimensions named, so ``xarray.open_zarr`` reads it)::

    image       (frame, z, y, x, iq)  float64 (float32 for complex64 frames); I = iq 0,
                                      Q = iq 1; one chunk per frame, uncompressed;
                                      NaN until written
    z           (z,)     ranges of the planes from the aperture, m
    y, x        (y,) (x,)  pixel offsets from the frame's centre, m (the same for all)
    position    (frame, xyz)  world position (x, y, z) of the frame's centre, m
    finished    (frame,) when the frame was written, s since 1970-01-01 UTC
    done        (frame,) True once the frame's image and position are complete
    frame_name  (frame,) the file's name; frame_path: its absolute path (the key)
    attributes  holoradar_survey (layout version), settings, geometry (JSON)

A frame's world pixel is ``(position[f, 0] + x, position[f, 1] + y)``
(:func:`~holoradar.survey.open_survey` calls the columns ``frame_x``,
``frame_y``, ``frame_z``). Each frame writes its own chunks (the image first,
``done`` last; Zarr writes each chunk to a temporary file and renames it), so a
run killed at any moment leaves a store whose frames marked done are complete
and whose other frames read as NaN. The
store itself is laid out in a temporary folder beside the target and renamed
into place: it exists complete or not at all.
"""

from __future__ import annotations

import functools
import os
import shutil
import tempfile
import time
import uuid
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .frames import FrameGeometry
from .settings import Settings

__all__ = ["LAYOUT", "create_store", "is_survey", "read_index", "register_frames",
           "write_frame"]

LAYOUT = "1"
"""Version of the store layout (attribute ``holoradar_survey``)."""

_PER_FRAME = ("position", "finished", "done")  # one chunk per frame
_NAMES = ("frame_name", "frame_path")                               # written by the driver
FRAME_ARRAYS = ("image", *_PER_FRAME, *_NAMES)
_NAME_CHUNK = 1024


def is_survey(path: Path) -> bool:
    """True when ``path`` is a survey store written by this module."""
    import zarr

    if not path.is_dir():
        return False
    try:
        return str(zarr.open_group(str(path), mode="r").attrs.get("holoradar_survey", "")) \
            == LAYOUT
    except Exception:  # not a Zarr group at all
        return False


def pixel_offsets(n: int, step: float) -> np.ndarray:
    """Offsets of ``n`` pixels at ``step`` from their centre, metres (exactly symmetric).

    Examples
    --------
    >>> pixel_offsets(4, 0.01)
    array([-0.015, -0.005,  0.005,  0.015])
    """
    return (np.arange(n) - (n - 1) / 2) * step


def create_store(target: Path, settings: Settings, geometry: FrameGeometry, *,
                 replace: bool = False) -> None:
    """Lay out an empty survey store at ``target`` (replacing an old one if ``replace``).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> geo = FrameGeometry(4, 4, (0.01, 0.01), (9.9e9,), False, False, 0.0, "complex128")
    >>> create_store(d / "s.zarr", Settings.make([0.1, 0.2], None, "angular", 1), geo)
    >>> register_frames(d / "s.zarr", [d / "a.nc", d / "b.nc"])
    [0, 1]
    >>> write_frame(str(d / "s.zarr"), "run-1", 1, np.ones((2, 4, 4), complex), (1.0, 0.0, 0.0))
    >>> idx = read_index(d / "s.zarr")
    >>> idx["n"], idx["done"].tolist(), idx["frame_x"][1], list(idx["frame_name"])
    (2, [False, True], np.float64(1.0), ['a.nc', 'b.nc'])
    """
    import zarr

    nz, oy, ox = geometry.image_shape(settings.z.size, settings.upsample)
    real = np.float32 if geometry.dtype == "complex64" else np.float64
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent))
    try:
        os.chmod(tmp, _dir_mode())  # mkdtemp makes 0700: give it the user's usual bits
        g = zarr.open_group(str(tmp), mode="w", zarr_format=3)

        def arr(name: str, shape: tuple[int, ...], chunks: tuple[int, ...], dtype: Any,
                dims: Sequence[str], fill: Any, **attrs: Any) -> Any:
            # Numbers are stored plain: a chunk of a few bytes does not compress, and
            # zstd takes images (float noise in the mantissas) down by about 5% at half
            # again the time of writing them.
            kw = {} if name in _NAMES else {"compressors": None}
            a = g.create_array(name, shape=shape, chunks=chunks, dtype=dtype, fill_value=fill,
                               dimension_names=list(dims), **kw)
            a.attrs.update(attrs)
            return a

        arr("image", (0, nz, oy, ox, 2), (1, nz, oy, ox, 2), real, ("frame", "z", "y", "x", "iq"),
            np.nan, long_name="reconstructed field, I (iq = 0) and Q (iq = 1)", units="1")
        step = (geometry.pitch[0] / settings.upsample, geometry.pitch[1] / settings.upsample)
        for name, values, what in (
                ("z", settings.z, "range of the image planes from the aperture"),
                ("y", pixel_offsets(oy, step[1]), "pixel y offset from the frame's centre"),
                ("x", pixel_offsets(ox, step[0]), "pixel x offset from the frame's centre")):
            a = arr(name, (values.size,), (values.size,), np.float64, (name,), np.nan,
                    long_name=what, units="m")
            a[:] = values
        arr("position", (0, 3), (1, 3), np.float64, ("frame", "xyz"), np.nan,
            long_name="world position (x, y, z) of the frame's centre", units="m")
        arr("finished", (0,), (1,), np.float64, ("frame",), np.nan,
            long_name="when the frame was written (UTC)", units="s since 1970-01-01")
        arr("done", (0,), (1,), bool, ("frame",), False,
            long_name="the frame's image and position are complete")
        arr("frame_name", (0,), (_NAME_CHUNK,), str, ("frame",), "",
            long_name="file name of the frame")
        arr("frame_path", (0,), (_NAME_CHUNK,), str, ("frame",), "",
            long_name="absolute path of the frame's file (the key for resuming)")
        g.attrs.update({"holoradar_survey": LAYOUT, "settings": settings.to_dict(),
                        "geometry": geometry.to_dict(),
                        "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())})
        old = None
        if replace and target.exists():
            old = target.with_name(f".{target.name}.{uuid.uuid4().hex}.old")
            os.rename(target, old)
        try:
            os.rename(tmp, target)
        except BaseException:
            if old is not None:
                os.rename(old, target)  # put the old store back
            raise
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _dir_mode() -> int:
    """Permission bits a new folder gets from ``mkdir()``: ``0o777`` less the umask."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o777 & ~mask


def _damaged_as_value_error(fn: Callable[..., Any]) -> Callable[..., Any]:
    """A store whose files were damaged (truncated, bit-flipped, removed) makes zarr and
    its codecs raise many kinds of errors: turn them into one ValueError naming the store."""

    @functools.wraps(fn)
    def wrapper(target: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            return fn(target, *args, **kwargs)
        except ValueError:
            raise
        except Exception as exc:  # zarr, numcodecs and the file system fail in many ways
            where = target if isinstance(target, str | os.PathLike) else \
                target.get("path", "the survey") if isinstance(target, dict) else "the survey"
            raise ValueError(f"store {str(where)!r} is damaged or unreadable "
                             f"({type(exc).__name__}: {exc})") from None

    return wrapper


@_damaged_as_value_error
def stored_settings(target: Path) -> tuple[Settings, FrameGeometry]:
    """The settings and geometry a store was made with."""
    import zarr

    attrs = zarr.open_group(str(target), mode="r").attrs
    return Settings.from_dict(dict(attrs["settings"])), \
        FrameGeometry.from_dict(dict(attrs["geometry"]))


@_damaged_as_value_error
def register_frames(target: Path, paths: Sequence[Path]) -> list[int]:
    """The slot of every frame (absolute paths), adding slots for new ones.

    Slots are keyed by ``frame_path``; a slot whose path is empty (left by a run
    killed while registering) is reused. Arrays are grown to a common length,
    never shrunk.
    """
    import zarr

    g = zarr.open_group(str(target), mode="r+")
    known_list = [str(p) for p in g["frame_path"][:]]
    length = max(g[a].shape[0] for a in FRAME_ARRAYS)
    known = {p: i for i, p in enumerate(known_list) if p}
    # Free: slots without a path (a registration cut short); no frame was ever imaged there.
    free = [i for i, p in enumerate(known_list) if not p] + list(range(len(known_list), length))
    slots: list[int] = []
    new: list[tuple[int, Path]] = []
    for p in paths:
        key = str(p)
        if key not in known:
            if free:
                known[key] = free.pop(0)
            else:
                known[key] = length
                length += 1
            new.append((known[key], p))
        slots.append(known[key])
    n = length
    for a in FRAME_ARRAYS:  # frame_path last: the registry grows once all arrays have
        arr = g[a]
        if arr.shape[0] != n:
            arr.resize((n, *arr.shape[1:]))
    if new:
        names = g["frame_name"]
        keys = g["frame_path"]
        cur_n, cur_k = names[:], keys[:]
        for slot, p in new:
            cur_n[slot], cur_k[slot] = p.name, str(p)
        names[:] = cur_n
        keys[:] = cur_k
    return slots


_HANDLES: dict[tuple[str, str], dict[str, Any]] = {}


def _handles(store: str, token: str) -> dict[str, Any]:
    """The store's per-frame arrays, opened once per process and run (``token``)."""
    import zarr

    key = (store, token)
    h = _HANDLES.get(key)
    if h is None:
        g = zarr.open_group(store, mode="r+")
        h = {name: g[name] for name in ("image", *_PER_FRAME)}
        _HANDLES.clear()  # one run at a time per process: drop the last run's handles
        _HANDLES[key] = h
    return h


def write_frame(store: str, token: str, slot: int, data: np.ndarray,
                position: tuple[float, float, float]) -> None:
    """Write one frame's complex image ``data`` (nz, ny', nx') and position, then mark it done."""
    h = _handles(store, token)
    img = h["image"]
    block = np.empty((*data.shape, 2), dtype=img.dtype)
    block[..., 0] = data.real
    block[..., 1] = data.imag
    img[slot] = block
    h["position"][slot] = np.asarray(position, np.float64)
    h["finished"][slot] = time.time()
    h["done"][slot] = True  # last: done means complete


@_damaged_as_value_error
def read_index(target: Path) -> dict[str, Any]:
    """The small arrays of a store (per frame and coordinates) and its attributes.

    ``n`` is the number of frames every array holds (a run killed while growing
    the store may leave some arrays longer; the extra slots are ignored).
    """
    import zarr

    if not is_survey(target):
        raise ValueError(f"store {str(target)!r} is not a holoradar survey store (no "
                         f"'holoradar_survey' = {LAYOUT!r} attribute in a Zarr group)")
    g = zarr.open_group(str(target), mode="r")
    n = min(g[a].shape[0] for a in FRAME_ARRAYS)
    out: dict[str, Any] = {"n": n, "group": g, "attrs": dict(g.attrs), "path": str(target)}
    for a in (*_PER_FRAME, *_NAMES):
        out[a] = np.asarray(g[a][:n])
    for a in ("z", "y", "x"):
        out[a] = np.asarray(g[a][:])
    out["done"] = out["done"].astype(bool)
    for k, a in enumerate(("frame_x", "frame_y", "frame_z")):
        out[a] = out["position"][:, k].copy()
    out["frame_name"] = out["frame_name"].astype(object)
    out["frame_path"] = out["frame_path"].astype(object)
    return out


@_damaged_as_value_error
def read_images(index: dict[str, Any], frames: Sequence[int],
                plane: int | None = None) -> np.ndarray:
    """Complex images of ``frames`` (k, nz, ny', nx'), or of one ``plane`` (k, ny', nx')."""
    img = index["group"]["image"]
    sel = np.asarray(list(frames), dtype=int)
    if sel.size == 0:
        shape = img.shape[1:-1] if plane is None else img.shape[2:-1]
        return np.zeros((0, *shape), complex)
    raw = img.oindex[sel] if plane is None else img.oindex[sel, int(plane)]
    out = np.empty(raw.shape[:-1], np.complex64 if raw.dtype == np.float32 else complex)
    out.real = raw[..., 0]
    out.imag = raw[..., 1]
    return out
