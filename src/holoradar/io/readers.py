"""Read the numeric variables of a user's file, whatever its format, without running code.

Each reader returns ``{name: ndarray}`` of the file's numeric arrays (and a
note of what else it holds); :mod:`holoradar.io.layout` then builds a hologram
from them. Nothing is unpickled or evaluated: NumPy files are opened with
``allow_pickle=False`` and an object array is refused; MATLAB v5 files are
parsed by ``scipy.io.loadmat`` (a data format, no code); MATLAB v7.3 and HDF5
by h5py; CSV as text numbers. A declared array size is checked against the
bytes the file actually holds (and against :data:`MAX_ARRAY_BYTES`) before
anything is allocated, so a damaged header cannot exhaust the memory.

Formats
-------
``.npz``   every array of the archive, by its name
``.npy``   one array, named ``data``
``.mat``   MATLAB v4/v5/v7 (scipy.io) or v7.3 (HDF5): every numeric variable,
           with MATLAB's own axis order (rows first, as ``size()`` shows them)
``.h5``    HDF5 (``.hdf5``, ``.he5``): every dataset by its path
           (``group/name``) and numeric attributes as ``path@attr``
``.csv``   a header row of column names, then one row per element (and per
           frequency): each column becomes a 1-D variable
``.nc``    a NetCDF file not written by holoradar: every variable
"""

from __future__ import annotations

import atexit
import csv
import io
import json
import threading
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["MAX_ARRAY_BYTES", "READERS", "read_variables"]

MAX_ARRAY_BYTES = 8 * 2**30
"""Largest single array a reader will allocate (8 GiB); a bigger declared size is
refused as a damaged or hostile header."""

_PICKLE = ("holds a Python object array ({what}); holoradar never unpickles data "
           "from a file because unpickling can run arbitrary code. Store plain numeric "
           "arrays (real or complex numbers) instead")


def _npy_header(fp: Any, what: str) -> tuple[tuple[int, ...], np.dtype, bool]:
    fmt = np.lib.format
    try:
        version = fmt.read_magic(fp)
        if version == (1, 0):
            shape, fortran, dtype = fmt.read_array_header_1_0(fp)
        else:
            shape, fortran, dtype = fmt.read_array_header_2_0(fp)
    except (ValueError, OSError, EOFError, SyntaxError) as exc:
        raise ValueError(f"{what} is not a valid NumPy .npy array ({exc})") from None
    if dtype.hasobject:
        raise ValueError(f"{what} " + _PICKLE.format(what=f"dtype {dtype}"))
    return tuple(int(s) for s in shape), dtype, bool(fortran)


def _check_size(shape: tuple[int, ...], dtype: np.dtype, available: int, what: str) -> None:
    need = int(np.prod(shape, dtype=object)) * dtype.itemsize
    if need > MAX_ARRAY_BYTES:
        raise ValueError(f"{what} declares an array of shape {shape} ({need / 2**30:.3g} GiB), "
                         f"more than the {MAX_ARRAY_BYTES / 2**30:.0f} GiB limit: a damaged "
                         "header?")
    if need > available:
        raise ValueError(f"{what} declares an array of shape {shape} {dtype} ({need} bytes) "
                         f"but holds only {available} bytes: the file is truncated or damaged")


def _read_npy_stream(fp: Any, available: int, what: str) -> np.ndarray:
    start = fp.tell()
    shape, dtype, fortran = _npy_header(fp, what)
    _check_size(shape, dtype, available - (fp.tell() - start), what)
    n = int(np.prod(shape, dtype=np.int64))
    buf = fp.read(n * dtype.itemsize)
    if len(buf) != n * dtype.itemsize:
        raise ValueError(f"{what} is truncated: {len(buf)} of {n * dtype.itemsize} bytes")
    arr = np.frombuffer(buf, dtype=dtype, count=n)
    arr = arr.reshape(shape[::-1]).T if fortran else arr.reshape(shape)
    return np.array(arr, dtype=arr.dtype.newbyteorder("="))  # owned, writeable, native order


def read_npy(path: Path) -> dict[str, np.ndarray]:
    """A ``.npy`` file: one array, returned as the variable ``data``."""
    with open(path, "rb") as fp:
        return {"data": _read_npy_stream(fp, path.stat().st_size, f"{path.name}")}


def read_npz(path: Path) -> dict[str, np.ndarray]:
    """A ``.npz`` archive: every member array by its name (``name.npy`` -> ``name``)."""
    return _read_zip(path, path.name)


def _read_zip(source: Any, label: str) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    try:
        zf = zipfile.ZipFile(source)
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        raise ValueError(f"{label} is not a valid .npz archive ({exc})") from None
    with zf:
        for info in zf.infolist():
            name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
            what = f"variable {name!r} in {label}"
            if info.file_size > MAX_ARRAY_BYTES + 4096:
                raise ValueError(f"{what} is {info.file_size / 2**30:.3g} GiB uncompressed, "
                                 f"more than the {MAX_ARRAY_BYTES / 2**30:.0f} GiB limit")
            try:
                raw = zf.read(info)
            except (zipfile.BadZipFile, OSError, EOFError, ValueError) as exc:
                raise ValueError(f"{what} cannot be read: the archive is damaged ({exc})") \
                    from None
            out[name] = _read_npy_stream(io.BytesIO(raw), len(raw), what)
    return out


def _mat_header_version(path: Path) -> int:
    with open(path, "rb") as fp:
        head = fp.read(128)
    if len(head) == 128 and head[:6] == b"MATLAB":
        endian = head[126:128]
        v = head[124:126]
        return int.from_bytes(v, "little" if endian == b"IM" else "big")
    return 0


def read_mat(path: Path) -> dict[str, np.ndarray]:
    """A MATLAB file: v4/v5/v7 through ``scipy.io.loadmat``, v7.3 (HDF5) through h5py.

    Numeric variables keep MATLAB's axis order (a v7.3 file stores them
    transposed; they are turned back). Structs, cells, strings and objects are
    listed but not read.
    """
    if _mat_header_version(path) == 0x0200:
        return _read_hdf5(path, matlab=True)
    from scipy.io import loadmat, whosmat

    for name, shape, _cls in whosmat(path):
        # complex128 bounds every MATLAB numeric class
        _check_size(tuple(shape), np.dtype(np.complex128), MAX_ARRAY_BYTES,
                    f"variable {name!r} in {path.name}")
    raw = loadmat(path, squeeze_me=False, mat_dtype=False, chars_as_strings=True)
    out: dict[str, np.ndarray] = {}
    other: list[str] = []
    for name, value in raw.items():
        if not name.startswith("__"):
            _mat_value(name, value, out, other, 0)
    if other:
        out["__other__"] = np.array(other)
    return out


def _mat_value(name: str, value: Any, out: dict[str, np.ndarray], other: list[str],
               depth: int) -> None:
    """One MATLAB value: a number array as ``name``; a 1 x 1 struct's fields as
    ``name.field`` (nested structs likewise, four levels at most); anything else listed
    in ``other`` by what it is."""
    arr = np.asarray(value) if isinstance(value, np.ndarray) else None
    if arr is not None and arr.dtype.kind in "biufc":
        out[name] = np.array(arr)
    elif arr is not None and arr.dtype.kind == "U" and arr.size == 1:  # a char array
        out[name] = np.array(str(arr.reshape(()).item())[:256])
    elif arr is not None and arr.dtype.names and arr.size == 1 and depth < 4:
        rec = arr.reshape(-1)[0]
        for field in arr.dtype.names:
            inner = rec[field]
            # loadmat wraps each field in an object array of one element
            if isinstance(inner, np.ndarray) and inner.dtype == object and inner.size == 1:
                inner = inner.reshape(-1)[0]
            _mat_value(f"{name}.{field}", inner, out, other, depth + 1)
    elif arr is not None and arr.dtype.names:
        other.append(f"{name} (a struct array of {arr.size}: fields "
                     f"{', '.join(arr.dtype.names)})")
    else:
        what = "a cell" if arr is not None and arr.dtype == object else "not numeric"
        other.append(f"{name} ({what})")


def _from_compound(arr: np.ndarray) -> np.ndarray | None:
    names = arr.dtype.names or ()
    for re_name, im_name in (("real", "imag"), ("r", "i"), ("re", "im")):
        if re_name in names and im_name in names:
            return arr[re_name] + 1j * arr[im_name]
    return None


def _read_hdf5(path: Path, *, matlab: bool = False) -> dict[str, np.ndarray]:
    import h5py

    out: dict[str, np.ndarray] = {}
    other: list[str] = []
    total = [0]

    def visit(name: str, obj: Any) -> None:
        if isinstance(obj, h5py.Dataset):
            if matlab and name.startswith("#refs#"):
                return
            dtype = obj.dtype
            if obj.shape is None:
                other.append(name)
                return
            if dtype.kind not in "biufc" and not (dtype.names and _compound_ok(dtype)):
                other.append(name)
                return
            if obj.external or obj.is_virtual:
                # data kept in other files: never followed (a crafted file could point
                # at any file the user can read)
                other.append(f"{name} (stored in other files: not read)")
                return
            total[0] += obj.size * dtype.itemsize
            _check_size((total[0],), np.dtype(np.uint8), MAX_ARRAY_BYTES,
                        f"{path.name} in all")
            _check_size(tuple(obj.shape), dtype, MAX_ARRAY_BYTES, f"dataset {name!r} in "
                        f"{path.name}")
            arr = obj[()]
            if dtype.names:
                arr = _from_compound(np.asarray(arr))
            arr = np.asarray(arr)
            if matlab:
                if obj.attrs.get("MATLAB_class", b"") in (b"char", "char"):
                    other.append(name)
                    return
                arr = arr.T  # MATLAB is column-major: h5py shows the axes reversed
            out[name] = np.array(arr)
            if not matlab:
                _attrs(obj.attrs, name)
        elif not matlab:
            _attrs(obj.attrs, name)

    def _attrs(attrs: Any, prefix: str) -> None:
        for key in attrs:
            try:
                v = np.asarray(attrs[key])
            except (OSError, TypeError, ValueError):
                continue
            if v.dtype.kind in "biufc" and v.size <= 1_000_000:
                out[f"{prefix}@{key}"] = v
            elif v.dtype.kind in "SUO" and v.size == 1:  # a short text: an identity, units
                text = v.reshape(()).item()
                text = text.decode("utf-8", "replace") if isinstance(text, bytes) else text
                if isinstance(text, str) and len(text) <= 256:
                    out[f"{prefix}@{key}"] = np.array(text)

    try:
        with h5py.File(path, "r") as f:
            if not matlab:
                _attrs(f.attrs, "")
            f.visititems(visit)
    except ValueError:
        raise
    except Exception as exc:  # the HDF5 layer fails in many ways on a damaged file
        raise ValueError(f"{path.name} is not a readable HDF5 file ({type(exc).__name__}: "
                         f"{exc})") from None
    if other:
        out["__other__"] = np.array(other)
    return out


def _compound_ok(dtype: np.dtype) -> bool:
    names = set(dtype.names or ())
    return bool({"real", "imag"} <= names or {"r", "i"} <= names or {"re", "im"} <= names)


def read_hdf5(path: Path) -> dict[str, np.ndarray]:
    """An HDF5 file: every numeric dataset by its path, numeric attributes as
    ``path@name`` (``@name`` for the file's own); complex compounds (real/imag)
    become complex."""
    return _read_hdf5(path)


def read_csv(path: Path) -> dict[str, np.ndarray]:
    """A CSV table: a header row of column names, then rows of numbers.

    Each column becomes a 1-D variable named by its header (spaces stripped).
    Typical layout: ``x, y, I, Q`` (one row per element), or ``x, y, frequency,
    amplitude, phase``. Lines starting with ``#`` are comments.
    """
    size = path.stat().st_size
    if size > MAX_ARRAY_BYTES:
        raise ValueError(f"{path.name} is larger than the {MAX_ARRAY_BYTES / 2**30:.0f} GiB "
                         "limit for a CSV table")
    # utf-8-sig: a spreadsheet's byte-order mark is not part of the first column's name
    with open(path, newline="", encoding="utf-8-sig", errors="strict") as fh:
        lines = [line for line in fh if line.strip() and not line.lstrip().startswith("#")]
    delimiter = _delimiter(lines[:20])
    rows = [r for r in csv.reader(lines, delimiter=delimiter) if any(c.strip() for c in r)]
    if not rows:
        raise ValueError(f"{path.name} holds no rows")
    header = [h.strip() for h in rows[0]]
    if not all(header) or len(set(header)) != len(header):
        raise ValueError(f"{path.name}: the first row must name every column once, got "
                         f"{header}")
    if all(is_number(h) for h in header):
        raise ValueError(f"{path.name}: the first row must be a header of column names "
                         f"(e.g. x,y,I,Q), got numbers {header}")
    body = rows[1:]
    if not body:
        raise ValueError(f"{path.name} has a header but no data rows")
    table = np.empty((len(body), len(header)))
    for n, row in enumerate(body, start=2):
        if len(row) != len(header):
            raise ValueError(f"{path.name} line {n}: {len(row)} values for {len(header)} "
                             f"columns {header}")
        try:
            # with ';' or tabs between columns a decimal comma is common (1,5 = 1.5)
            table[n - 2] = [float(c.replace(",", ".") if delimiter != "," else c)
                            for c in row]
        except ValueError:
            raise ValueError(f"{path.name} line {n}: not all numbers: {row} (columns "
                             f"separated by {delimiter!r})") from None
    return {h: table[:, j].copy() for j, h in enumerate(header)}


def _delimiter(lines: list[str]) -> str:
    """The column separator of a CSV export: ',', ';', a tab or spaces."""
    if not lines:
        return ","
    try:
        return csv.Sniffer().sniff("".join(lines), delimiters=",;\t").delimiter
    except csv.Error:
        return ","


def is_number(text: str) -> bool:
    """Whether a text reads as a number."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def _shorten(text: str, width: int) -> str:
    """``text`` on one line, at most ``width`` characters: cut at a word boundary and
    marked `` ...`` (a library's long message, kept readable).

    Examples
    --------
    >>> _shorten("one two  three", 20), _shorten("one two three four", 14)
    ('one two three', 'one two ...')
    >>> _shorten("x" * 30, 12)
    'xxxxxxxx ...'
    """
    text = " ".join(str(text).split())
    if len(text) <= width:
        return text
    cut = text[:width - 4]
    space = cut.rfind(" ")
    if space >= len(cut) // 2:  # a word boundary not too far back; else one long word, cut
        cut = cut[:space]
    return cut.rstrip(" ,;:") + " ..."


_NETCDF_MAGIC = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")


def _file_signature(path: Path) -> str | None:
    """Why ``path`` cannot be NetCDF by its first bytes (None: it may be): empty, text,
    or another binary format. NetCDF-3 starts ``CDF``, NetCDF-4 with HDF5's signature
    (at offset 0, or 512, 1024, ... after a user block)."""
    try:
        with open(path, "rb") as f:
            head = f.read(4096)
    except OSError:
        return None
    if not head:
        return "the file is empty"
    if any(head.startswith(m) for m in _NETCDF_MAGIC) or any(
            head[o:o + 8] == _NETCDF_MAGIC[-1] for o in (512, 1024, 2048)):
        return None
    try:
        head.decode("utf-8")
    except UnicodeDecodeError:
        return "its first bytes are neither NetCDF-3 nor HDF5's"
    return "it is text"


def read_netcdf_variables(path: Path) -> dict[str, np.ndarray]:
    """A NetCDF file not written by holoradar (NetCDF-4 or NetCDF-3): every numeric
    variable by name, CF-decoded (``scale_factor``, ``add_offset``, ``_FillValue`` applied,
    as any NetCDF tool shows them), numeric global attributes as ``@name``."""
    import xarray as xr

    out: dict[str, np.ndarray] = {}
    other: list[str] = []
    total = 0
    kind = _file_signature(path)
    if kind is not None:
        raise ValueError(f"{path.name} is not a NetCDF file ({kind}): holoradar reads "
                         "NetCDF-4/HDF5 and NetCDF-3 .nc files; for a table or another "
                         "format give its own suffix (.csv, .txt with --layout wide, .npz, "
                         ".mat, .h5)")
    try:
        ds = xr.open_dataset(path, decode_times=False, decode_timedelta=False)
    except (ValueError, OSError, TypeError, KeyError) as exc:
        raise ValueError(f"{path.name} is not a readable NetCDF file "
                         f"({type(exc).__name__}: {_shorten(str(exc), 200)})") from None
    with ds:
        for name, var in ds.variables.items():
            if var.dtype.kind not in "biufc":
                other.append(str(name))
                continue
            _check_size(tuple(var.shape), var.dtype, MAX_ARRAY_BYTES,
                        f"variable {name!r} in {path.name}")
            total += var.size * var.dtype.itemsize
            _check_size((total,), np.dtype(np.uint8), MAX_ARRAY_BYTES, f"{path.name} in all")
            out[str(name)] = np.array(var.values)
        for key, v in ds.attrs.items():
            a = np.asarray(v)
            if a.dtype.kind in "biufc" and a.size <= 1_000_000:
                out[f"@{key}"] = a
    if other:
        out["__other__"] = np.array(other)
    return out


READERS = {
    ".npz": read_npz,
    ".npy": read_npy,
    ".mat": read_mat,
    ".h5": read_hdf5,
    ".hdf5": read_hdf5,
    ".he5": read_hdf5,
    ".csv": read_csv,
    ".nc": read_netcdf_variables,
    ".nc4": read_netcdf_variables,
}

# Parsers written in C (scipy's MATLAB reader, the HDF5 library) can crash the whole
# interpreter on a damaged file (seen when fuzzing: a segmentation fault in loadmat).
# They run in a separate Python process (``python -m holoradar.io._parse_server``,
# started once and kept): its arrays come back as .npz bytes read by the pure-Python
# reader above, so a crash is one clear error and nothing is unpickled. A plain
# subprocess, not multiprocessing: it does not import the caller's script again and it
# works inside daemon processes (Dask workers).
_ISOLATED = {read_mat, read_hdf5, read_netcdf_variables}


def pack(variables: dict[str, np.ndarray]) -> bytes:
    """Arrays as the bytes of an ``.npz`` archive (any names; never pickled)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_STORED) as zf:
        for name, arr in variables.items():
            with zf.open(f"{name}.npy", "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.asarray(arr), allow_pickle=False)
    return buf.getvalue()


class _ParserProcess:
    """The parser process: one request at a time, restarted after a crash."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.proc: Any = None

    def _start(self) -> None:
        import subprocess
        import sys

        self.proc = subprocess.Popen([sys.executable, "-m", "holoradar.io._parse_server"],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL)

    def close(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.stdin.close()
            try:
                self.proc.wait(timeout=2)
            except Exception:  # it will be killed with the interpreter
                self.proc.kill()
        self.proc = None

    def parse(self, reader: Any, path: Path) -> bytes:
        request = (json.dumps([reader.__name__, str(path.resolve())]) + "\n").encode()
        with self.lock:
            if self.proc is None or self.proc.poll() is not None:
                self._start()
            try:
                self.proc.stdin.write(request)
                self.proc.stdin.flush()
                head = self.proc.stdout.read(8)
                blob = self.proc.stdout.read(int.from_bytes(head, "big")) \
                    if len(head) == 8 else b""
            except OSError:
                blob = b""
            if not blob:
                code = self.proc.poll()
                self.close()
                raise ValueError(f"{path.name}: the {path.suffix} parser crashed on this file "
                                 f"(exit code {code}): it is damaged or not a valid "
                                 f"{path.suffix} file")
        return blob


_PARSER = _ParserProcess()
atexit.register(_PARSER.close)


def _isolated(reader: Any, path: Path) -> dict[str, np.ndarray]:
    blob = _PARSER.parse(reader, path)
    if blob[:1] == b"E":
        raise ValueError(blob[1:].decode("utf-8", "replace"))
    return read_npz_bytes(blob[1:], path.name)


def read_npz_bytes(blob: bytes, what: str) -> dict[str, np.ndarray]:
    """The arrays of an ``.npz`` archive held in memory (see :func:`read_npz`)."""
    return _read_zip(io.BytesIO(blob), what)


def read_variables(path: str | Path) -> dict[str, np.ndarray]:
    """Every numeric variable of a file, by name (see the module's list of formats).

    Raises
    ------
    ValueError
        Unknown suffix, missing/empty/damaged file, a pickled object array,
        a declared size beyond the file or :data:`MAX_ARRAY_BYTES`.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "a.npz"
    >>> np.savez(p, data=np.ones((2, 3)), x=np.arange(3.0))
    >>> sorted(read_variables(p))
    ['data', 'x']
    """
    src = Path(path)
    reader = READERS.get(src.suffix.lower())
    if reader is None:
        raise ValueError(f"path {src.name!r}: unknown format {src.suffix!r}; holoradar reads "
                         f"{', '.join(sorted(READERS))}, and a scanner's wide text table of "
                         "any suffix with layout 'wide,...' (a header row naming X, Y and "
                         "each frequency twice)")
    if not src.is_file():
        raise ValueError(f"path {str(src)!r} is not a file")
    if src.stat().st_size == 0:
        raise ValueError(f"path {str(src)!r} is empty")
    try:
        return _isolated(reader, src) if reader in _ISOLATED else reader(src)
    except ValueError:
        raise
    except (MemoryError, RecursionError) as exc:
        raise ValueError(f"{src.name} could not be read ({type(exc).__name__}): a damaged "
                         "header?") from None
    except Exception as exc:  # parsers of damaged files fail in many ways: name the file
        raise ValueError(f"{src.name} is not a readable {src.suffix} file "
                         f"({type(exc).__name__}: {exc})") from None
