"""The survey store: one Zarr (v3) group holding every frame's image.

Layout (``survey.zarr``; dimensions named, so ``xarray.open_zarr`` reads it)::

    image       (frame, z, y, x, iq)  float64 (float32 for complex64 frames); I = iq 0,
                                      Q = iq 1; chunks of several frames (up to
                                      16 MiB, :func:`frames_per_chunk`), compressed
                                      (Blosc LZ4, bit shuffle), each chunk's
                                      CRC-32C checked before it is decompressed;
                                      NaN until written
    z           (z,)     ranges of the planes from the aperture, m
    y, x        (y,) (x,)  pixel offsets from the frame's centre, m (the same for all)
    position    (frame, xyz)  world position (x, y, z) of the frame's centre, m
    finished    (frame,) when the frame was written, seconds since 1970-01-01 UTC
    done        (frame,) True once the frame's image and position are complete
    frame_name  (frame,) the file's name; frame_path: its absolute path (the key)
    attributes  holoradar_survey (layout version), settings, geometry (JSON), created;
                skipped (the frames a run could not image, by absolute path: why);
                skipped_stamp (for those found bad when read or imaged: the file's
                size and modification time, so that a rerun does not read them again)

The per-frame arrays share the image's chunking along ``frame`` (stores written
before chunked writing hold one frame a chunk, and are resumed as they are). A
frame's world pixel is ``(position[f, 0] + x, position[f, 1] + y)``
(:func:`~holoradar.survey.open_survey` calls the columns ``frame_x``,
``frame_y``, ``frame_z``). A task owns whole chunks: it writes the images of its
frames in a chunk with one write, then their positions and times, then their
``done`` flags, last (Zarr writes each chunk to a temporary file and renames
it), so a run killed at any moment leaves a store whose frames marked done are
complete and whose other frames read as NaN (or, if the kill fell between the
image and ``done`` writes, hold an image a rerun writes again). The
store itself is laid out in a temporary folder beside the target and renamed
into place: it exists complete or not at all. Stores written before the images
were compressed (their chunks plain) are read and resumed as they are: Zarr
takes each array's codecs from its own metadata.
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
from .settings import Settings, _show

__all__ = [
    "CHUNK_BYTES",
    "LAYOUT",
    "create_store",
    "describe_store",
    "file_stamp",
    "frame_bytes",
    "frames_per_chunk",
    "is_survey",
    "note_skipped",
    "read_index",
    "register_frames",
    "remembered_bad",
    "write_frame",
    "write_frames",
]

LAYOUT = "1"
"""Version of the store layout (attribute ``holoradar_survey``)."""

_PER_FRAME = ("position", "finished", "done")  # chunked along frame as the image
_NAMES = ("frame_name", "frame_path")                               # written by the driver
FRAME_ARRAYS = ("image", *_PER_FRAME, *_NAMES)
_NAME_CHUNK = 1024
CHUNK_BYTES = 16 * 2**20
"""Most bytes (before compression) of the images in one chunk: several frames share a
chunk when theirs are small, so that a frame is not four writes of its own (each write
through Zarr costs a millisecond or more besides its bytes), while a task (one chunk)
stays short enough to balance the workers and two chunks in memory stay small."""
_MOST_FRAMES_PER_CHUNK = 64


def frames_per_chunk(per_frame: int, n_frames: int) -> int:
    """Frames per chunk of a new store: as many as fit in :data:`CHUNK_BYTES`, at most
    64, and at most a sixteenth of the survey (so that even a small survey makes 16
    tasks, enough for a few workers to share evenly).

    Examples
    --------
    >>> frames_per_chunk(571536, 120), frames_per_chunk(32768, 200), frames_per_chunk(2**24, 9)
    (8, 13, 1)
    """
    return max(1, min(_MOST_FRAMES_PER_CHUNK, CHUNK_BYTES // max(1, per_frame),
                      -(-n_frames // 16)))


def _image_codecs() -> list[Any]:
    """The image's compressor: Blosc's LZ4 after a bit shuffle.

    Images are float noise in their low mantissa bits, so no codec takes them far.
    The shuffle groups the sign, exponent and high mantissa bits, which repeat across
    a smooth (band-limited) image. Measured on a 61-plane frame of a 16 x 16 array
    upsampled 8 times (14.3 MB, float64): the bit shuffle and LZ4 keep 89.4% of the
    bytes in 31 ms a frame, a byte shuffle 90.1% in 38 ms, plain chunks take 18 ms;
    on 9 planes of 128 x 128 (2.4 MB) 90.8% in 5.5 ms against 93.4% in 7.8 ms (plain
    4.0 ms); Zarr's default (Zstandard, no shuffle) kept 95.5% at four times the time.
    """
    from zarr.codecs import BloscCodec, Crc32cCodec

    # The checksum last: a damaged chunk is found by its CRC-32C before the Blosc
    # decompressor sees it (a truncated chunk crashed the interpreter there).
    return [BloscCodec(cname="lz4", clevel=5, shuffle="bitshuffle"), Crc32cCodec()]


def is_survey(path: Path) -> bool:
    """True when ``path`` is a survey store written by this module."""
    import zarr

    if not path.is_dir():
        return False
    try:
        g = zarr.open_group(str(path), mode="r", use_consolidated=False)
        return str(g.attrs.get("holoradar_survey", "")) == LAYOUT
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
                 replace: bool = False, chunk: int = 1) -> None:
    """Lay out an empty survey store at ``target`` (replacing an old one if ``replace``),
    its per-frame arrays in chunks of ``chunk`` frames (:func:`frames_per_chunk`).

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
            # Small numbers are stored plain (a chunk of a few bytes does not compress);
            # the images compressed (_image_codecs), names with Zarr's default.
            kw = {} if name in _NAMES else \
                {"compressors": _image_codecs() if name == "image" else None}
            a = g.create_array(name, shape=shape, chunks=chunks, dtype=dtype, fill_value=fill,
                               dimension_names=list(dims), **kw)
            a.attrs.update(attrs)
            return a

        k = max(1, int(chunk))
        arr("image", (0, nz, oy, ox, 2), (k, nz, oy, ox, 2), real, ("frame", "z", "y", "x", "iq"),
            np.nan, long_name="reconstructed field, I (iq = 0) and Q (iq = 1)", units="1")
        step = (geometry.pitch[0] / settings.upsample, geometry.pitch[1] / settings.upsample)
        for name, values, what in (
                ("z", settings.z, "range of the image planes from the aperture"),
                ("y", pixel_offsets(oy, step[1]), "pixel y offset from the frame's centre"),
                ("x", pixel_offsets(ox, step[0]), "pixel x offset from the frame's centre")):
            a = arr(name, (values.size,), (values.size,), np.float64, (name,), np.nan,
                    long_name=what, units="m")
            a[:] = values
        arr("position", (0, 3), (k, 3), np.float64, ("frame", "xyz"), np.nan,
            long_name="world position (x, y, z) of the frame's centre", units="m")
        arr("finished", (0,), (k,), np.float64, ("frame",), np.nan,
            long_name="when the frame was written (UTC)",
            units="seconds since 1970-01-01 00:00:00", calendar="standard")
        arr("done", (0,), (k,), bool, ("frame",), False,
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


def frame_bytes(settings: Settings, geometry: FrameGeometry) -> int:
    """Bytes of one frame's image in a store, before compression (its chunk, at most).

    Examples
    --------
    >>> geo = FrameGeometry(16, 16, (0.01, 0.01), (9.9e9,), False, False, 0.0, "complex128")
    >>> frame_bytes(Settings.make([0.1, 0.2], None, "angular", 8), geo)  # 2 x 121 x 121 x 2 x 8
    468512
    """
    nz, oy, ox = geometry.image_shape(settings.z.size, settings.upsample)
    return nz * oy * ox * 2 * (4 if geometry.dtype == "complex64" else 8)


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

    attrs = zarr.open_group(str(target), mode="r", use_consolidated=False).attrs
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

    g = zarr.open_group(str(target), mode="r+", use_consolidated=False)
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
        g = zarr.open_group(store, mode="r+", use_consolidated=False)
        # A frame's image is never all NaN (the fill value): written without Zarr's scan
        # for empty chunks (a millisecond or more for a chunk of a few MB).
        h = {name: _always_write(g[name]) for name in ("image", *_PER_FRAME)}
        _HANDLES.clear()  # one run at a time per process: drop the last run's handles
        _HANDLES[key] = h
    return h


def _always_write(arr: Any) -> Any:
    """``arr`` with Zarr's ``write_empty_chunks`` (its API since Zarr 3.1; as it is before)."""
    try:
        return arr.with_config({"write_empty_chunks": True})
    except (AttributeError, TypeError, ValueError):
        return arr


def write_frame(store: str, token: str, slot: int, data: np.ndarray,
                position: tuple[float, float, float]) -> None:
    """Write one frame's complex image ``data`` (nz, ny', nx') and position, then mark it done."""
    write_frames(store, token, [slot], as_block([data], _handles(store, token)["image"].dtype),
                 [position])


def as_block(images: Sequence[np.ndarray], real: Any) -> np.ndarray:
    """Complex images (each nz, ny', nx') as one ``(k, nz, ny', nx', 2)`` block of I and Q
    in the store's ``real`` dtype (the parts copied, no arithmetic)."""
    block = np.empty((len(images), *np.shape(images[0]), 2), dtype=real)
    for j, data in enumerate(images):
        block[j, ..., 0] = data.real
        block[j, ..., 1] = data.imag
    return block


def chunk_of(store: str, token: str) -> int:
    """Frames per chunk of the store's per-frame arrays (1 for stores made before)."""
    return int(_handles(store, token)["image"].chunks[0])


def write_frames(store: str, token: str, slots: Sequence[int], block: np.ndarray,
                 positions: Sequence[tuple[float, float, float]]) -> None:
    """Write the images ``block`` (k, nz, ny', nx', 2) of the frames in ``slots`` (k
    distinct slots, ascending) and their positions, then mark them done.

    The caller owns the chunks these slots lie in (no other task writes them). Each
    array is written once for all the slots (one write per chunk touched): images
    first, then positions and times, ``done`` last, so a frame marked done is
    complete whatever stops the run.
    """
    if not len(slots):
        return
    h = _handles(store, token)
    idx = np.asarray(slots, dtype=np.intp)
    lo, hi = int(idx[0]), int(idx[-1]) + 1
    run = hi - lo == idx.size  # contiguous slots: a plain slice (whole chunks unread)

    def put(arr: Any, values: np.ndarray) -> None:
        if run:
            arr[lo:hi] = values
        else:
            arr.oindex[idx] = values

    put(h["image"], block)
    put(h["position"], np.asarray(positions, np.float64).reshape(idx.size, 3))
    put(h["finished"], np.full(idx.size, time.time()))
    put(h["done"], np.ones(idx.size, bool))  # last: done means complete


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
    g = zarr.open_group(str(target), mode="r", use_consolidated=False)
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


def file_stamp(path: str | os.PathLike[str]) -> list[int] | None:
    """A file's ``[size, modification time in ns]``, or None if it cannot be seen."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return [int(st.st_size), int(st.st_mtime_ns)]


@_damaged_as_value_error
def note_skipped(target: Path, skipped: dict[str, str], tried: Sequence[str],
                 stamps: dict[str, list[int]] | None = None) -> None:
    """Record in the store's attributes why frames could not be imaged.

    ``skipped`` maps the absolute path of each frame this run skipped to the reason;
    ``tried`` lists the absolute paths of every frame this run was given: their old
    entries are replaced by this run's outcome (a frame imaged since loses its
    entry). ``stamps`` maps the paths of the frames found bad when read or imaged to
    their file's :func:`file_stamp`: while the file keeps that stamp, a rerun skips it
    without reading it (:func:`remembered_bad`). The attributes are rewritten only when
    they change.
    """
    import zarr

    g = zarr.open_group(str(target), mode="r+", use_consolidated=False)
    gone = set(tried)
    old = {str(k): str(v) for k, v in dict(g.attrs.get("skipped", {}) or {}).items()}
    old_st = {str(k): [int(u) for u in v]
              for k, v in dict(g.attrs.get("skipped_stamp", {}) or {}).items()}
    new = {k: v for k, v in old.items() if k not in gone}
    new.update(skipped)
    new_st = {k: v for k, v in old_st.items() if k not in gone}
    new_st.update({k: list(v) for k, v in (stamps or {}).items() if k in skipped})
    changed = {}
    if new != old:
        changed["skipped"] = new
    if new_st != old_st:
        changed["skipped_stamp"] = new_st
    if changed:
        g.attrs.update(changed)


@_damaged_as_value_error
def remembered_bad(target: Path) -> dict[str, str]:
    """The frames earlier runs found bad when reading or imaging them, and whose file has
    not changed since (same size and modification time): absolute path -> reason."""
    import zarr

    attrs = zarr.open_group(str(target), mode="r", use_consolidated=False).attrs
    reasons = {str(k): str(v) for k, v in dict(attrs.get("skipped", {}) or {}).items()}
    stamps = dict(attrs.get("skipped_stamp", {}) or {})
    return {p: reasons[p] for p, st in stamps.items()
            if p in reasons and file_stamp(p) == [int(u) for u in st]}


@_damaged_as_value_error
def describe_store(target: Path, checksums: bool = True) -> dict[str, Any]:
    """What a survey store holds: frames stored and expected, planes, grid, settings,
    frames not stored (and why) and frames marked done whose image is missing.

    Reads the small arrays and lists the image's chunk files; where the chunks carry a
    CRC-32C, each chunk's bytes are read and checked against it (nothing is
    decompressed: about the disk's speed).

    Parameters
    ----------
    target : Path
        The store (a ``.zarr`` folder that :func:`holoradar.survey.run_batch` wrote).
    checksums : bool
        Check each chunk's CRC-32C (default); False: only what the files' sizes tell.

    Returns
    -------
    dict
        ``store``, ``created``, ``frames_stored``, ``frames_expected`` (the frames
        registered, and those skipped before they could be: missing, empty or
        unreadable files), ``not_stored`` and ``damaged`` (lists of ``{"name",
        "path", "reason"}``), ``settings``, ``geometry``, ``image_shape`` (nz, ny',
        nx'), ``ground`` (the medium in words), ``pixel_m`` (x, y step), ``dtype``
        (of the I and Q values),
        ``compressors`` (names; empty for a store written before compression),
        ``extent_m`` (x min, x max, y min, y max of the stored frames' centres;
        None if none), ``bytes_on_disk`` and ``georeferenced`` (the CRS of the frames'
        positions, ``"EPSG:..."``, or None: local metres).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> geo = FrameGeometry(4, 4, (0.01, 0.01), (9.9e9,), False, False, 0.0, "complex128")
    >>> create_store(d / "s.zarr", Settings.make([0.1, 0.2], None, "angular", 1), geo)
    >>> register_frames(d / "s.zarr", [d / "a.nc", d / "b.nc"])
    [0, 1]
    >>> write_frame(str(d / "s.zarr"), "run-1", 1, np.ones((2, 4, 4), complex), (1.0, 0.0, 0.0))
    >>> info = describe_store(d / "s.zarr")
    >>> info["frames_stored"], info["frames_expected"], info["image_shape"], info["damaged"]
    (1, 2, [2, 4, 4], [])
    >>> info["not_stored"][0]["name"]
    'a.nc'
    """
    idx = read_index(target)
    g, attrs, n = idx["group"], idx["attrs"], idx["n"]
    image = g["image"]
    done, paths, names = idx["done"], list(idx["frame_path"]), list(idx["frame_name"])
    skipped = {str(k): str(v) for k, v in dict(attrs.get("skipped", {}) or {}).items()}
    not_stored = [{"name": names[i], "path": paths[i],
                   "reason": skipped.get(paths[i], "not imaged yet (its run was cut short, "
                                                   "or is still running)")}
                  for i in range(n) if paths[i] and not done[i]]
    known = set(paths)
    not_stored += [{"name": Path(p).name, "path": p, "reason": r}
                   for p, r in skipped.items() if p not in known]
    plain = not image.compressors
    per_chunk = int(image.chunks[0])  # frames a chunk holds (1 in stores made before)
    full = per_chunk * int(np.prod(image.shape[1:])) * image.dtype.itemsize
    damaged = []
    checked = checksums and any(type(c).__name__ == "Crc32cCodec" for c in image.compressors)
    crc_ok: dict[Path, bool] = {}
    for i in np.nonzero(done)[0]:
        chunk = Path(target, "image", *image.metadata.encode_chunk_key(
            (int(i) // per_chunk, *([0] * (image.ndim - 1)))).split("/"))
        size = chunk.stat().st_size if chunk.is_file() else None
        if checked and size is not None and chunk not in crc_ok:
            crc_ok[chunk] = _crc_holds(chunk)
        reason = ("marked done but its image chunk is missing" if size is None else
                  f"its image chunk holds {size} of {full} bytes" if plain and size != full
                  else "its image chunk fails its CRC-32C checksum (damaged on disk)"
                  if checked and not crc_ok[chunk]
                  else "marked done but its position is not a number"
                  if not np.all(np.isfinite(idx["position"][i])) else None)
        if reason is not None:
            damaged.append({"name": names[i], "path": paths[i], "reason": reason})
    fx, fy = idx["frame_x"][done], idx["frame_y"][done]
    fx, fy = fx[np.isfinite(fx)], fy[np.isfinite(fy)]
    xo, yo = idx["x"], idx["y"]
    return {
        "store": str(target), "created": attrs.get("created"),
        "frames_stored": int(done.sum()),
        "frames_expected": n - sum(not p for p in paths) + len(set(skipped) - known),
        "not_stored": not_stored, "damaged": damaged,
        "settings": attrs["settings"], "geometry": attrs["geometry"],
        "ground": _show(attrs["settings"].get("medium")),
        "image_shape": [int(v) for v in image.shape[1:-1]],
        "pixel_m": [float(xo[1] - xo[0]) if xo.size > 1 else None,
                    float(yo[1] - yo[0]) if yo.size > 1 else None],
        "dtype": str(image.dtype),
        "compressors": [type(c).__name__.removesuffix("Codec").lower()
                        for c in image.compressors],
        "extent_m": [float(fx.min()), float(fx.max()), float(fy.min()), float(fy.max())]
        if fx.size and fy.size else None,
        "bytes_on_disk": sum(f.stat().st_size for f in Path(target).rglob("*") if f.is_file()),
        # Whether the frames' positions are eastings and northings of a known CRS (a map
        # can place them) or a local survey's metres.
        "georeferenced": attrs.get("crs"),
    }


@_damaged_as_value_error
def read_images(index: dict[str, Any], frames: Sequence[int],
                plane: int | None = None) -> np.ndarray:
    """Complex images of ``frames`` (k, nz, ny', nx'), or of one ``plane`` (k, ny', nx')."""
    img = index["group"]["image"]
    sel = np.asarray(list(frames), dtype=int)
    if sel.size == 0:
        shape = img.shape[1:-1] if plane is None else img.shape[2:-1]
        return np.zeros((0, *shape), complex)
    try:
        raw = img.oindex[sel] if plane is None else img.oindex[sel, int(plane)]
    except Exception as exc:  # a damaged chunk (its checksum, its codec): name its frames
        raise ValueError(_damaged_frames(index, img, sel, exc)) from None
    # A missing chunk reads as the fill value (NaN): a frame marked done without its
    # image, named (a written image is finite: the batch refuses others).
    done = index.get("done")
    empty = [int(i) for i, r in zip(sel, raw, strict=True)
             if done is not None and bool(done[int(i)]) and not np.all(np.isfinite(r))]
    if empty:
        names = ", ".join(str(index["frame_name"][i]) for i in empty)
        where = index.get("path", "the survey store")
        raise ValueError(f"store {str(where)!r}: frame(s) {names} damaged (marked done but "
                         "the image chunk is missing or holds no numbers): image them "
                         "again with holoradar batch (a rerun repairs them), or search the "
                         "others")
    out = np.empty(raw.shape[:-1], np.complex64 if raw.dtype == np.float32 else complex)
    out.real = raw[..., 0]
    out.imag = raw[..., 1]
    return out


def _crc_holds(chunk: Path) -> bool:
    """Whether a chunk file's last four bytes are the CRC-32C of the rest (Zarr's crc32c
    codec, little-endian): its bytes read, nothing decompressed."""
    import google_crc32c

    try:
        data = chunk.read_bytes()
    except OSError:
        return False
    return len(data) > 4 and int.from_bytes(data[-4:], "little") == \
        google_crc32c.value(data[:-4])


def _damaged_frames(index: dict[str, Any], img: Any, sel: np.ndarray, exc: Exception) -> str:
    """Which of ``sel``'s frames cannot be read, as one sentence with the way out."""
    bad = []
    for i in sel:
        try:
            img.oindex[[int(i)]]
        except Exception:
            bad.append(str(index["frame_name"][int(i)]))
    names = ", ".join(bad) if bad else "some"
    where = index.get("path", "the survey store")
    text = " ".join(str(exc).split())
    why = ("the image chunk fails its CRC-32C checksum: damaged on disk"
           if "checksum" in text.lower() else f"{type(exc).__name__}: {text[:160]}")
    return (f"store {str(where)!r}: frame(s) {names} damaged ({why}): image them again "
            "with holoradar batch (a rerun repairs them), or search the others")


def stored_crs(target: Path) -> Any:
    """The coordinate reference system of a store's frame positions (a ``pyproj.CRS``),
    or None where the survey was made without one."""
    import zarr

    text = zarr.open_group(str(target), mode="r", use_consolidated=False).attrs.get("crs")
    if not text:
        return None
    from ..io.crs import as_crs

    return as_crs(text, "the store's crs")


def check_crs(target: Path, crs: Any) -> None:
    """Refuse a CRS other than the one a store's frames were placed in.

    Raises
    ------
    ValueError
        Named ``crs``.
    """
    from ..io.crs import crs_name

    have = stored_crs(target)
    if have is not None and not have.equals(crs):
        raise ValueError(f"crs: the store's frame positions are in {crs_name(have)}, this "
                         f"run gives {crs_name(crs)}: give the same, or a new store")


def set_crs(target: Path, crs: Any) -> None:
    """Keep ``crs`` (a ``pyproj.CRS``) with a store (its ``crs`` attribute, the CRS's
    authority code or WKT)."""
    import zarr

    auth = crs.to_authority()
    g = zarr.open_group(str(target), mode="r+", use_consolidated=False)
    g.attrs["crs"] = f"{auth[0]}:{auth[1]}" if auth else crs.to_wkt()


def consolidate(target: Path) -> None:
    """Write the store's consolidated metadata (one document of every array's metadata),
    which ``xarray.open_zarr`` and other readers look for first (without it xarray warns
    on every open). holoradar's own reads do not use it: a run cut short leaves it as
    of the run before, and the arrays themselves are the truth; each finished run
    writes it again."""
    import warnings

    import zarr

    with warnings.catch_warnings():
        # zarr says on every call that consolidated metadata is not (yet) in the Zarr 3
        # specification: known and chosen (xarray and others read it first), not a
        # fault of this store, so not the user's to read after every batch.
        warnings.filterwarnings("ignore", message="Consolidated metadata is currently not")
        zarr.consolidate_metadata(str(target))
