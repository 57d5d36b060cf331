"""Files: save and load holograms and images (NetCDF-4).

``save(obj, path)`` writes a :class:`~holoradar.Hologram` or
:class:`~holoradar.Image` to ``path`` (``.nc``), refusing to overwrite an
existing file unless ``overwrite=True``, checking the folder first and writing
atomically (a temporary file beside it, renamed) with the user's umask.
``load(path)`` gives the object back, equal to what was saved (the file layout
is described in :mod:`holoradar.io.netcdf`), and reads a user's own files
(NumPy, MATLAB, HDF5, CSV, foreign NetCDF) given a :class:`Layout`.
"""

from __future__ import annotations

import contextlib
import json
import os
import warnings
import weakref
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..data.hologram import Hologram, Image
from ..data.plausibility import check_plausible
from .gpr import GPR_SUFFIXES, read_gpr
from .layout import LENGTH_UNITS, Layout, assemble
from .netcdf import content, from_dataset, read_direct, read_history
from .netcdf_write import write_content
from .output import check_output, write_via_temp
from .readers import read_variables

__all__ = ["Layout", "NonFiniteWarning", "load", "read_history", "read_sidecar", "read_variables",
           "save"]

NETCDF_SUFFIXES = (".nc", ".nc4")


#: The steps read with each hologram :func:`load` returned from holoradar's own file
#: (held weakly: gone with the hologram), which :func:`save` writes again before its own.
LOADED_HISTORY: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def save(obj: Hologram | Image, path: str | os.PathLike[str], *, overwrite: bool = False,
         history: list[dict[str, Any]] | None = None) -> Path:
    """Write a Hologram or Image to a NetCDF-4 file.

    Parameters
    ----------
    obj : Hologram or Image
    path : str or path-like
        Output file, ending in ``.nc`` (or ``.nc4``); its folder must exist.
    overwrite : bool
        Replace an existing file (default False: an existing file is an error).
    history : list of dict, optional
        Processing steps that led to ``obj`` (each with ``step``, ``parameters``,
        ...); a ``save`` step is appended. A hologram read by :func:`load` from
        holoradar's file and saved as it is keeps that file's steps before these.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ValueError
        Not a Hologram or Image, wrong suffix, missing folder, existing file.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> import holoradar as hr
    >>> h = hr.Hologram(np.ones((2, 3)), [0.0, 0.01, 0.02], [0.0, 0.01], 9.9e9)
    >>> p = save(h, pathlib.Path(tempfile.mkdtemp()) / "h.nc")
    >>> bool(np.array_equal(load(p).data, h.data))
    True
    """
    if not isinstance(obj, Hologram | Image):
        raise ValueError(f"obj must be a holoradar.Hologram or holoradar.Image, got "
                         f"{type(obj).__name__}")
    target = check_output(path, suffixes=NETCDF_SUFFIXES, overwrite=overwrite)
    earlier = LOADED_HISTORY.get(obj, []) if isinstance(obj, Hologram) else []
    c = content(obj, [*earlier, *(history or [])] if earlier else history)
    return write_via_temp(target, lambda tmp: write_content(tmp, c))


def load(path: str | os.PathLike[str], *, layout: Layout | Mapping[str, Any] | str | None = None,
         check: bool = True, iq_check: bool = True) -> Hologram | Image:
    """Read a hologram or image: a holoradar NetCDF file, or a user's file of arrays.

    Parameters
    ----------
    path : str or path-like
        ``.nc`` written by :func:`save` (an equal object comes back), or a
        user's file: ``.npz``, ``.npy``, ``.mat`` (v5 and v7.3), ``.h5``/``.hdf5``,
        ``.csv`` or a foreign ``.nc``; see :mod:`holoradar.io.readers`; a GPR
        vendor's line of traces (``.DZT``, ``.DT1``, ``.RD3``/``.RAD``, SEG-Y, through
        impdar: :func:`holoradar.io.gpr.read_gpr`) as a line scan, its positions from
        the header or the layout's ``pitch``.
    layout : Layout, dict or str, optional
        For a user's file: which variable is the field, the axes, the units
        (:class:`~holoradar.io.layout.Layout`; a string is its ``key=value,...``
        form). A JSON sidecar (same name, ``.json``) may hold a ``"layout"`` and
        the coordinates; these arguments override it.
    check : bool
        Refuse a hologram whose numbers look like a unit mistake (pitch against
        wavelength, a frequency in GHz, all zeros): see
        :func:`~holoradar.data.plausibility.check_plausible`. For a user's file
        whose layout does not declare ``iq_sign``, also check the I/Q sign
        (:func:`~holoradar.imaging.iq.check_iq_sign`, a few milliseconds for a
        16 x 16 array).
    iq_check : bool
        With ``check``, the I/Q sign check above (default True). A survey checks its
        first frame only: every frame of one device shares the convention, and the
        check would cost as much as imaging a small frame.

    Raises
    ------
    ValueError
        The file is missing, empty, truncated or damaged, holds a pickled object
        array, lacks a variable (the message lists what it holds and what is
        needed), or looks like a unit mistake.

    Warns
    -----
    IQSignWarning
        A user's file whose data focus behind the array, not in front: recorded
        as ``I - iQ`` (the engineering convention), with the fix (``iq_sign=I-iQ``
        in the layout, or :func:`holoradar.conjugate`).

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> import holoradar as hr
    >>> img = hr.Image(np.zeros((2, 3)), np.arange(3.0), np.arange(2.0), np.array([0.4]),
    ...                9.9e9, has_z_axis=False)
    >>> p = save(img, pathlib.Path(tempfile.mkdtemp()) / "i.nc")
    >>> load(p).data.shape
    (2, 3)

    A user's file, coordinates in millimetres and the frequency in GHz:

    >>> q = pathlib.Path(tempfile.mkdtemp()) / "scan.npz"
    >>> x = np.arange(16) * 25.0
    >>> np.savez(q, I=np.ones((16, 16)), Q=np.zeros((16, 16)), x=x, y=x, f=9.9)
    >>> h = load(q, layout="units=mm, frequency_unit=GHz")
    >>> h.pitch, h.frequency
    ((0.025, 0.025), 9900000000.0)
    """
    src = Path(path)
    try:
        return _load(src, layout, check, iq_check)
    except ValueError as exc:
        if src.name in str(exc) or src.with_suffix(".json").name in str(exc):
            raise   # it names the file (or its sidecar) already
        # Every refusal names the file it is about.
        try:
            named = type(exc)(f"{src.name}: {exc}")
        except TypeError:   # a subclass with other arguments
            named = ValueError(f"{src.name}: {exc}")
        raise named from exc


def _load(src: Path, layout: Any, check: bool, iq_check: bool) -> Hologram | Image:
    lay = as_layout(layout)
    obj = None
    device = False
    used = lay          # the layout the file was read with (a sidecar's merged in)
    # holoradar's own file: its layout is its own (a response table still applies)
    if src.suffix.lower() in NETCDF_SUFFIXES and (lay is None or lay.given <= {"response"}):
        try:  # holoradar's own file, read in one pass (a survey reads thousands)
            obj = read_direct(src)
        except Exception:  # not ours, or damaged: decided below
            obj = None
        if obj is None and is_holoradar_netcdf(src):
            obj = _load_netcdf(src)  # ours but odd: the xarray reader names the problem
    if obj is not None and isinstance(obj, Hologram):
        # Its steps so far, for the next save of this same object (a hologram holds
        # no history of its own).
        with contextlib.suppress(Exception):
            LOADED_HISTORY[obj] = [s for s in read_history(src) if isinstance(s, dict)]
    if obj is None and lay is not None and lay.wide is not None:
        obj = _wide(src, lay)
        device = "iq_sign" not in lay.given
    if obj is None and src.suffix.lower() in GPR_SUFFIXES:
        # A GPR vendor's line of traces (through impdar): real traces carry no I/Q sign.
        pitch = None if lay is None or lay.pitch is None else \
            lay.pitch * LENGTH_UNITS[lay.length_unit]
        obj = read_gpr(src, pitch=pitch)
    if obj is None:
        variables = read_variables(src)
        sidecar = src.with_suffix(".json")
        side_layout = None
        if sidecar.is_file():
            extra, side_layout = read_sidecar(sidecar)
            variables = {**extra, **variables}  # the file's own arrays win
        kind = variables.get("holoradar_kind")
        if kind is not None and kind.dtype.kind == "U" and str(kind) == "Image":
            obj = _npz_image(variables, src.name)
        else:
            full = (side_layout or Layout()).merged(lay)
            used = full
            obj = assemble(variables, full, what=src.name)
            device = "iq_sign" not in full.given
    if isinstance(obj, Image):
        _warn_non_finite(obj, src.name)
    response = _response(used, src)
    if response is not None and isinstance(obj, Hologram):
        from .response import apply_response

        # The response is in the device's convention, as the data were recorded.
        conj = used is not None and getattr(used, "iq_sign", "I+iQ") == "I-iQ"
        obj = apply_response(obj, response, conjugate=conj)
    if check and isinstance(obj, Hologram):
        check_plausible(obj, what=src.name)
        if device and iq_check:
            # A device's own export whose layout does not say its I/Q sign: data in the
            # engineering convention (I - jQ) would image as a blur without a word.
            from ..imaging.iq import warn_if_conjugated

            warn_if_conjugated(obj, what=src.name, fix=_IQ_FIX, stacklevel=3)
    return obj


_IQ_FIX = ("declare it in the layout, iq_sign=I-iQ (holoradar --layout '...,iq_sign=I-iQ', "
           "hr.load(path, layout='...,iq_sign=I-iQ')), or image hr.conjugate(hologram)")


class NonFiniteWarning(UserWarning):
    """A file's image holds NaN or infinite samples (a damaged file, or one written so)."""


def _warn_non_finite(img: Image, what: str) -> None:
    """Say so where an image holds NaN or infinite samples (a hologram with them is
    refused: it cannot be imaged; an image is still shown, its gaps blank)."""
    data = np.asarray(img.data)
    bad = data.size - int(np.count_nonzero(np.isfinite(data)))
    if bad:
        warnings.warn(f"{what}: {bad} of {data.size} samples are NaN or infinite (a damaged "
                      "file?): they show blank and are left out of peaks and levels",
                      NonFiniteWarning, stacklevel=4)


def _response(lay: Layout | None, src: Path) -> Path | None:
    """The layout's response table, a path relative to the data file's folder."""
    if lay is None or lay.response is None:
        return None
    p = Path(lay.response)
    p = p if p.is_absolute() or p.exists() else src.parent / p
    if not p.is_file():
        raise ValueError(f"layout response: {lay.response!r} is not a file")
    return p


def _wide(src: Path, lay: Layout) -> Hologram:
    """A scanner's wide text table (:mod:`holoradar.io.wide`) gathered into a hologram."""
    from dataclasses import replace

    from .wide import read_wide

    if not src.is_file():
        raise ValueError(f"path {str(src)!r} is not a file")
    unit = lay.frequency_unit if "frequency_unit" in lay.given else None
    variables, _ = read_wide(src, unit, lay.wide)
    pair = {"i": "I", "q": "Q"} if lay.wide == "reim" else {"amplitude": "amplitude",
                                                           "phase": "phase"}
    full = replace(lay, wide=None, x="x", y="y", frequency="frequency", frequency_unit="Hz",
                   data=None, **pair)
    return assemble(variables, full, what=src.name)


def _npz_image(v: dict[str, np.ndarray], what: str) -> Image:
    """An image that ``holoradar image --out img.npz`` wrote."""
    missing = [k for k in ("data", "x", "y", "z", "frequency") if k not in v]
    if missing:
        raise ValueError(f"{what}: an image file lacks {missing}")
    f = v["frequency"]
    return Image(v["data"], v["x"], v["y"], np.atleast_1d(v["z"]),
                 float(f) if f.ndim == 0 else f, str(v.get("method", "angular")),
                 has_z_axis=bool(v.get("has_z_axis", np.array(True))))


def as_layout(layout: Any) -> Layout | None:
    if layout is None or isinstance(layout, Layout):
        return layout
    if isinstance(layout, str):
        return Layout.parse(layout)
    if isinstance(layout, Mapping):
        return Layout.from_mapping(layout)
    raise ValueError(f"layout must be a holoradar.io.Layout, a dict or 'key=value,...' text, "
                     f"got {type(layout).__name__}")


def is_holoradar_netcdf(src: Path) -> bool:
    """Whether a file is a holoradar NetCDF file (False for one h5py cannot open: the
    generic reader then reads a NetCDF-3 file or names the damage)."""
    import h5py

    try:
        with h5py.File(src, "r") as f:
            return "holoradar_kind" in f.attrs
    except Exception:  # not HDF5 (a NetCDF-3 file, or damaged)
        return False


def read_sidecar(path: Path) -> tuple[dict[str, np.ndarray], Layout | None]:
    """A JSON sidecar: its numeric entries (numbers or lists of numbers) as variables,
    and its ``"layout"`` object as a :class:`Layout`."""
    if path.stat().st_size > 64 * 2**20:
        raise ValueError(f"sidecar {path.name} is larger than 64 MiB")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except RecursionError:
        raise ValueError(f"sidecar {path.name} is nested too deeply to be a layout") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise ValueError(f"sidecar {path.name} is not valid JSON ({exc})") from None
    if not isinstance(doc, dict):
        raise ValueError(f"sidecar {path.name} must hold a JSON object, got "
                         f"{type(doc).__name__}")
    lay = doc.get("layout")
    # The grid's own entries must be numbers: skipping an x given as {"start": ...}
    # would image on a made-up grid, or fail later naming the wrong cause.
    grid = {"x", "y", "frequency"} | ({v for k in ("x", "y", "frequency")
                                       if isinstance(v := lay.get(k), str)}
                                      if isinstance(lay, dict) else set())
    extra: dict[str, np.ndarray] = {}
    for key, value in doc.items():
        if key == "layout":
            continue
        arr = None
        if not isinstance(value, bool):
            try:
                arr = np.asarray(value, dtype=float)
            except (TypeError, ValueError, OverflowError, RecursionError):
                arr = None
        if arr is not None and arr.ndim <= 2:
            extra[key] = arr
        elif key in grid:
            shown = json.dumps(value)
            kind = {dict: "an object", list: "a list", str: "a string", bool: "a boolean"}.get(
                type(value), type(value).__name__)
            raise ValueError(f"sidecar {path.name}: {key!r} must be a number or a list of "
                             f"numbers (e.g. \"{key}\": [-0.1875, -0.1625, ...]), got {kind} "
                             f"{shown if len(shown) <= 60 else shown[:57] + '...'}")
    return extra, (None if lay is None else Layout.from_mapping(lay, f"sidecar {path.name} "
                                                                     "layout"))


def _load_netcdf(src: Path) -> Hologram | Image:
    """A holoradar file through xarray: the slower reader, whose errors explain."""
    import xarray as xr

    try:
        with xr.open_dataset(src, engine="h5netcdf") as ds:
            ds.load()
            return from_dataset(ds, what=str(src))
    except ValueError:
        raise
    except Exception as exc:  # a damaged file can fail in the HDF5 layer in many ways
        raise ValueError(f"path {str(src)!r} is not a readable NetCDF-4/HDF5 file "
                         f"({type(exc).__name__}: {exc})") from None
