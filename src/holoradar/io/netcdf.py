"""Holograms and images as NetCDF-4 files (xarray + h5netcdf), readable by any NetCDF tool.

Layout of a file:

* one data variable, ``hologram`` or ``image``, real, with a last dimension
  ``iq`` of size 2: index 0 the in-phase part I, index 1 the quadrature Q, the
  complex sample being ``I + iQ`` (time dependence ``exp(-i omega t)``); no
  complex type is needed to read it. The ``iq`` coordinate holds 0 and 1 with
  ``flag_values`` and ``flag_meanings = "in_phase quadrature"`` (CF has no
  variable-length string coordinates); An image whose values are real (an
  amplitude map such as a survey's mosaic) is stored as they are, float64 or
  float32, without the ``iq`` dimension, and read back real;
* its other dimensions: leading frames ``frame0``, ``frame1``, ... , then
  ``frequency`` (a wideband hologram), ``z`` (an image with planes), ``y``, ``x``;
* coordinates in metres and hertz with CF ``units`` and ``long_name``: ``x``,
  ``y`` (``axis`` X and Y: element coordinates in the aperture's own plane; image
  pixels in the image's frame), ``z`` (``axis`` Z, ``positive = "down"``: ranges
  of an image's planes), ``frequency`` (``standard_name = "radiation_frequency"``);
  a single frequency, or the single plane of an image without a plane axis, is a
  scalar coordinate (no dimension of length one; files of earlier versions held
  them as 1-D variables and read alike);
* global attributes: ``holoradar_kind`` (``Hologram`` or ``Image``),
  ``holoradar_conventions`` (the version of these conventions), ``monostatic``,
  the pose (``pose_center_m``, ``pose_tilt_rad``, ``pose_azimuth_rad``), the
  source as JSON (``source``) and its type (``source_type``), a transmitter
  beside the receiver (``tx_offset_m``, three numbers), the image's ``method`` and
  ``has_z_axis``, the ground of the last step that named one as numbers
  (``ground`` "layered" or "free space"; ``ground_z_interfaces_m`` top-down,
  ``ground_eps_real`` and ``ground_eps_imag`` from the air down), and a processing
  ``history`` (JSON list of steps: name, parameters, holoradar's version, UTC time);
* ``polarization`` (a hologram that records one field component): three numbers,
  the unit vector (x, y, z) in world axes (the medium's frame, not the aperture's
  own) of the electric-field component the elements record, e.g. ``[0, 1, 0]``
  for E_y. Absent: the scalar model (``Hologram.polarization`` is None), as in
  every file written before the vector model.

The ``source`` JSON holds ``type`` (``PlaneWave``, ``PointSource``,
``GaussianBeam`` or ``Dipole``) and the source's fields: numbers, lists of three
numbers (positions, axes, a source's own ``polarization``: a unit vector in world
axes, or null), complex numbers as ``{"re": ..., "im": ...}`` (``amplitude``, and
each of a ``Dipole``'s three ``moment`` components).

Reading parses numbers and JSON only: nothing is unpickled or evaluated.
"""

from __future__ import annotations

import dataclasses
import json
import os
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from ..data.hologram import Hologram, Image
from ..data.pose import Pose
from ..physics.dipole import Dipole
from ..physics.sources import GaussianBeam, PlaneWave, PointSource

__all__ = ["CONVENTIONS", "NetcdfContent", "NetcdfVariable", "content", "from_dataset",
           "read_history", "to_dataset"]

CONVENTIONS = "1"
_SOURCES = {cls.__name__: cls for cls in (PlaneWave, PointSource, GaussianBeam, Dipole)}


def _version() -> str:
    from .._version import __version__

    return __version__


def _jsonable(v: Any) -> Any:
    if isinstance(v, np.ndarray):
        return [_jsonable(e) for e in v.tolist()]
    if isinstance(v, complex | np.complexfloating):
        return {"re": float(np.real(v)), "im": float(np.imag(v))}
    if isinstance(v, np.bool_ | bool):
        return bool(v)
    if isinstance(v, np.floating | np.integer):
        return v.item()
    if isinstance(v, list | tuple):
        return [_jsonable(e) for e in v]
    return v


def source_to_json(source: Any) -> str | None:
    """The source as JSON text (its type and fields), or None."""
    if source is None:
        return None
    if type(source).__name__ not in _SOURCES:
        raise ValueError(f"source of type {type(source).__name__} cannot be saved")
    fields = {f.name: _jsonable(getattr(source, f.name)) for f in dataclasses.fields(source)}
    return json.dumps({"type": type(source).__name__, **fields})


def _from_jsonable(v: Any) -> Any:
    """Undo :func:`_jsonable`'s complex numbers (``{"re", "im"}``), in lists too."""
    if isinstance(v, dict) and set(v) == {"re", "im"}:
        return complex(v["re"], v["im"])
    if isinstance(v, list):
        return [_from_jsonable(e) for e in v]
    return v


def source_from_json(text: str) -> Any:
    """Rebuild a source from :func:`source_to_json`'s text (known types only).

    Examples
    --------
    >>> d = source_from_json(source_to_json(Dipole((-0.2, 0, 0.2), moment=(0, 1j, 0))))
    >>> d.moment.tolist(), d.amplitude
    ([0j, 1j, 0j], (1+0j))
    >>> source_from_json(source_to_json(PlaneWave(polarization=(0, 1, 0)))).polarization
    (0.0, 1.0, 0.0)
    """
    try:
        spec = json.loads(text)
        cls = _SOURCES[spec.pop("type")]
        names = {f.name for f in dataclasses.fields(cls)}
        kw = {}
        for k, v in spec.items():
            if k not in names:
                raise KeyError(k)
            kw[k] = _from_jsonable(v)
        out = cls(**kw)
        for k in ("axis", "position", "center", "polarization"):
            # Stored exactly as the source held them (already normalised): set them
            # back bit for bit, after the constructor has validated them.
            if kw.get(k) is not None and hasattr(out, k):
                stored = np.asarray(kw[k], float)
                if stored.shape != np.shape(getattr(out, k)) or not np.allclose(
                        stored, getattr(out, k), rtol=1e-12, atol=1e-15):
                    raise ValueError(f"{k} {kw[k]!r} is not in normal form")
                if isinstance(getattr(out, k), tuple):  # a source's polarization
                    object.__setattr__(out, k, tuple(float(e) for e in stored))
                else:
                    stored.setflags(write=getattr(out, k).flags.writeable)
                    object.__setattr__(out, k, stored)
        return out
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise ValueError(f"the file's 'source' attribute is not a holoradar source: {exc}; "
                         f"known types {sorted(_SOURCES)}") from None


def _split_iq(data: np.ndarray) -> np.ndarray:
    real = np.float32 if data.dtype == np.complex64 else np.float64
    return np.stack([data.real, data.imag], axis=-1).astype(real, copy=False)


def _coord(values: np.ndarray, dim: str, units: str, long_name: str,
           axis: str | None = None) -> NetcdfVariable:
    attrs = {"units": units, "long_name": long_name}
    if axis is not None:
        attrs["axis"] = axis
    return NetcdfVariable((dim,), np.asarray(values, float), attrs)


def _frequency(obj: Any) -> NetcdfVariable:
    """The frequency coordinate: an axis of a band, a scalar coordinate of one."""
    attrs = {"units": "Hz", "long_name": "frequency", "standard_name": "radiation_frequency"}
    f = obj.frequency
    if isinstance(f, np.ndarray):
        return NetcdfVariable(("frequency",), np.asarray(f, float), attrs)
    return NetcdfVariable((), np.asarray(float(f)), attrs)


@dataclasses.dataclass(frozen=True)
class NetcdfVariable:
    """One variable of a file: its dimension names, values and attributes."""

    dims: tuple[str, ...]
    values: np.ndarray
    attrs: dict[str, Any]


@dataclasses.dataclass(frozen=True)
class NetcdfContent:
    """What a holoradar file holds, before any library writes it: the data variable
    (``name``), the coordinates (dimension coordinates, and scalar ones such as a
    single frequency) and the global attributes.

    :func:`to_dataset` makes an ``xarray.Dataset`` of it; ``holoradar.save`` writes it
    through h5netcdf directly (:mod:`holoradar.io.netcdf_write`), without xarray's
    import (pandas, dask: a second or more in a fresh process)."""

    name: str
    data: NetcdfVariable
    coords: dict[str, NetcdfVariable]
    attrs: dict[str, Any]


def _ground_attributes(steps: list[Any]) -> dict[str, Any]:
    """The ground of the last step that names one (``parameters.medium``) as numbers:
    ``ground_z_interfaces_m`` (top-down), ``ground_eps_real`` and ``ground_eps_imag``
    (the air first: one more than the interfaces); a step whose medium is null: free
    space (``ground = "free space"``)."""
    for step in reversed(steps):
        params = step.get("parameters") if isinstance(step, dict) else None
        if not isinstance(params, dict) or "medium" not in params:
            continue
        m = params["medium"]
        if m is None:
            return {"ground": "free space"}
        try:
            eps = [complex(str(e).replace(" ", "")) for e in m["eps"]]
            zi = [float(z) for z in m["z_interfaces"]]
        except (KeyError, TypeError, ValueError):
            return {}
        return {"ground": "layered", "ground_z_interfaces_m": np.asarray(zi, float),
                "ground_eps_real": np.asarray([e.real for e in eps], float),
                "ground_eps_imag": np.asarray([e.imag for e in eps], float)}
    return {}


def to_dataset(obj: Hologram | Image, history: list[dict[str, Any]] | None = None) -> Any:
    """An ``xarray.Dataset`` holding ``obj`` (see the module text for the layout).

    Examples
    --------
    >>> import numpy as np
    >>> h = Hologram(np.ones((2, 3)), [0.0, 0.01, 0.02], [0.0, 0.01], 9.9e9)
    >>> ds = to_dataset(h)
    >>> ds["hologram"].dims, ds.attrs["holoradar_kind"]
    (('y', 'x', 'iq'), 'Hologram')
    """
    import xarray as xr

    c = content(obj, history)
    coords = {k: xr.Variable(v.dims, v.values, v.attrs) for k, v in c.coords.items()}
    return xr.Dataset({c.name: xr.Variable(c.data.dims, c.data.values, c.data.attrs)},
                      coords=coords, attrs=c.attrs)


def content(obj: Hologram | Image, history: list[dict[str, Any]] | None = None) -> NetcdfContent:
    """What the file of ``obj`` holds (see the module text for the layout), the
    ``save`` step appended to its history.

    Examples
    --------
    >>> import numpy as np
    >>> h = Hologram(np.ones((2, 3)), [0.0, 0.01, 0.02], [0.0, 0.01], 9.9e9)
    >>> c = content(h)
    >>> c.name, c.data.dims, c.coords["frequency"].dims
    ('hologram', ('y', 'x', 'iq'), ())
    """
    now = datetime.now(UTC).isoformat(timespec="seconds")
    # An image's own steps (an inversion's solver, say) come before those given.
    own = list(getattr(obj, "history", ()) or ())
    steps = [{**step, "holoradar": step.get("holoradar", _version()),
              "time": step.get("time", now)} if isinstance(step, dict) else step
             for step in own + [s for s in (history or []) if s not in own]]
    attrs: dict[str, Any] = {"Conventions": "CF-1.8", "holoradar_conventions": CONVENTIONS,
                             "holoradar_version": _version(),
                             "iq_convention": "sample = I + iQ (iq index 0, 1); time "
                                              "dependence exp(-i omega t)"}
    coords: dict[str, NetcdfVariable] = {
        # CF has no string coordinates of variable length: the component is a small
        # integer whose meaning flag_values/flag_meanings say.
        "iq": NetcdfVariable(("iq",), np.array([0, 1], np.int8), {
            "long_name": "component of the complex sample: in-phase I, quadrature Q",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "in_phase quadrature", "units": "1"}),
        "frequency": _frequency(obj),
    }
    if isinstance(obj, Hologram):
        kind, var = "Hologram", "hologram"
        core = (["frequency"] if obj.is_wideband else []) + ["y", "x"]
        coords["x"] = _coord(obj.x, "x", "m", "element x in the aperture's own plane", "X")
        coords["y"] = _coord(obj.y, "y", "m", "element y in the aperture's own plane", "Y")
        p = obj.pose
        attrs.update(monostatic=int(obj.monostatic), wideband=int(obj.is_wideband),
                     pose_center_m=np.asarray(p.center, float), pose_tilt_rad=float(p.tilt),
                     pose_azimuth_rad=float(p.azimuth))
        src = source_to_json(obj.source)
        if src is not None:
            attrs["source"] = src
            attrs["source_type"] = type(obj.source).__name__
        if obj.polarization is not None:
            attrs["polarization"] = np.asarray(obj.polarization, float)
        if obj.tx_offset is not None:
            attrs["tx_offset_m"] = np.asarray(obj.tx_offset, float)
        long_name = "received field at the elements"
    elif isinstance(obj, Image):
        kind, var = "Image", "image"
        core = (["z"] if obj.has_z_axis else []) + ["y", "x"]
        coords["x"] = _coord(obj.x, "x", "m", "pixel x", "X")
        coords["y"] = _coord(obj.y, "y", "m", "pixel y", "Y")
        z = np.asarray(obj.z, float)
        zattrs = {"units": "m", "long_name": "range of the image planes from the aperture",
                  "axis": "Z", "positive": "down"}
        # A single plane without a plane axis: a scalar coordinate (no unused dimension).
        coords["z"] = NetcdfVariable(("z",), z, zattrs) if obj.has_z_axis else \
            NetcdfVariable((), np.asarray(float(z.ravel()[0])), zattrs)
        attrs.update(method=str(obj.method), has_z_axis=int(obj.has_z_axis),
                     wideband=int(isinstance(obj.frequency, np.ndarray)))
        long_name = "reconstructed field"
    else:
        raise ValueError(f"obj must be a holoradar.Hologram or holoradar.Image, got "
                         f"{type(obj).__name__}")
    data = np.asarray(obj.data)
    lead = [f"frame{i}" for i in range(data.ndim - len(core))]
    steps.append({"step": "save", "parameters": {"kind": kind}, "holoradar": _version(),
                  "time": now})
    attrs["holoradar_kind"] = kind
    attrs["history"] = json.dumps(steps)
    attrs.update(_ground_attributes(steps))
    if kind == "Image" and not np.iscomplexobj(data):
        # A real image (an amplitude map): its values as they are, not I and Q = 0 at
        # twice the size read back as complex.
        del coords["iq"], attrs["iq_convention"]
        values = NetcdfVariable((*lead, *core), data.astype(
            np.float32 if data.dtype == np.float32 else np.float64, copy=False),
            {"long_name": f"{long_name} (real values)", "units": "1"})
    else:
        values = NetcdfVariable((*lead, *core, "iq"), _split_iq(data),
                                {"long_name": long_name, "units": "1"})
    return NetcdfContent(var, values, coords, attrs)


def _tx_offset(value: Any, what: str) -> tuple[float, ...] | None:
    """The stored ``tx_offset_m`` attribute (3 numbers, metres), or None."""
    if value is None:
        return None
    d = np.asarray(value, float).ravel()
    if d.size != 3:
        raise ValueError(f"{what}: tx_offset_m must hold 3 numbers (metres), got {d.size}")
    return tuple(float(v) for v in d)


def _polarization(value: Any, what: str) -> np.ndarray | None:
    """The ``polarization`` attribute: None when absent (the scalar model), else a unit
    vector of three numbers."""
    if value is None:
        return None
    try:
        pol = np.array(value, dtype=float).ravel()
    except (TypeError, ValueError):
        pol = np.empty(0)
    if pol.size != 3 or not np.all(np.isfinite(pol)) or \
            not abs(float(np.linalg.norm(pol)) - 1) < 1e-6:
        raise ValueError(f"{what}: the 'polarization' attribute must be a unit vector of 3 "
                         f"numbers (x, y, z in world axes), got {value!r}")
    return pol


def _need(ds: Any, names: list[str], what: str) -> None:
    missing = [n for n in names if n not in ds.variables and n not in ds.attrs]
    if missing:
        found = sorted(list(ds.variables) + list(ds.attrs))
        raise ValueError(f"{what}: missing {missing}; found {found}")


def from_dataset(ds: Any, what: str = "file") -> Hologram | Image:
    """Rebuild the Hologram or Image that :func:`to_dataset` stored."""
    kind = ds.attrs.get("holoradar_kind")
    if kind not in ("Hologram", "Image"):
        raise ValueError(f"{what} is not a holoradar file (no holoradar_kind attribute "
                         "'Hologram' or 'Image'); found variables "
                         f"{sorted(ds.variables)} (it was not written by holoradar.save)")
    var = kind.lower()
    _need(ds, [var, "x", "y", "frequency"], what)
    arr = ds[var]
    real = kind == "Image" and "iq" not in arr.dims  # a real image (an amplitude map)
    if not real and (arr.dims[-1] != "iq" or arr.shape[-1] != 2):
        raise ValueError(f"{what}: variable {var!r} must end in a dimension 'iq' of size 2 "
                         f"(I, Q), got dims {arr.dims} and shape {arr.shape}")
    raw = np.asarray(arr.values)
    if not np.issubdtype(raw.dtype, np.floating):
        raise ValueError(f"{what}: variable {var!r} must be real numbers, got {raw.dtype}")
    if real:
        data = raw.astype(np.float32 if raw.dtype == np.float32 else np.float64, copy=False)
    else:
        data = raw[..., 0] + 1j * raw[..., 1]
        if raw.dtype == np.float32:
            data = data.astype(np.complex64)
    x, y = np.asarray(ds["x"].values, float), np.asarray(ds["y"].values, float)
    f = np.asarray(ds["frequency"].values, float).ravel()
    wideband = bool(int(ds.attrs.get("wideband", f.size > 1)))
    freq: Any = f if wideband else (float(f[0]) if f.size == 1 else f)
    if kind == "Hologram":
        center = np.asarray(ds.attrs.get("pose_center_m", [0.0, 0.0, 0.0]), float).ravel()
        if center.size != 3:
            raise ValueError(f"{what}: pose_center_m must hold 3 numbers, got {center.size}")
        pose = Pose(tuple(float(c) for c in center), float(ds.attrs.get("pose_tilt_rad", 0.0)),
                    float(ds.attrs.get("pose_azimuth_rad", 0.0)))
        src = ds.attrs.get("source")
        pol = _polarization(ds.attrs.get("polarization"), what)
        out = Hologram(data, x, y, freq,
                       source=None if src is None else source_from_json(str(src)),
                       monostatic=bool(int(ds.attrs.get("monostatic", 0))),
                       pose=None if pose.is_identity else pose, polarization=pol,
                       tx_offset=_tx_offset(ds.attrs.get("tx_offset_m"), what))
        if pol is not None and np.allclose(pol, out.polarization, rtol=0, atol=1e-12):
            pol.setflags(write=False)  # the stored unit vector, bit for bit
            object.__setattr__(out, "polarization", pol)
        return out
    _need(ds, ["z"], what)
    has_z = bool(int(ds.attrs.get("has_z_axis", 1)))
    z = np.asarray(ds["z"].values, float).ravel()
    need = (z.size,) if has_z else ()
    if data.shape[-2:] != (y.size, x.size) or (has_z and data.shape[-3:-2] != need):
        raise ValueError(f"{what}: image of shape {data.shape} does not match z {z.size}, "
                         f"y {y.size}, x {x.size}")
    try:
        steps = json.loads(str(ds.attrs.get("history", "[]")))
    except ValueError:
        steps = []
    history = tuple(s for s in steps if isinstance(s, dict)) if isinstance(steps, list) else ()
    return Image(data, x, y, z, freq, str(ds.attrs.get("method", "angular")), has_z_axis=has_z,
                 history=history)


class _Variable:
    """The little of an xarray variable that :func:`from_dataset` uses."""

    def __init__(self, dims: tuple[str, ...], values: np.ndarray) -> None:
        self.dims, self.values, self.shape = dims, values, values.shape


class _H5View:
    """A holoradar file read with h5py directly: the attributes, and each variable's
    dimension names (from its NetCDF-4 dimension list) and values."""

    def __init__(self, f: Any) -> None:
        self.attrs = {k: _attr(v) for k, v in f.attrs.items() if not k.startswith("_")}
        self.variables: dict[str, _Variable] = {}
        for name, ds in f.items():
            refs = ds.attrs.get("DIMENSION_LIST")
            if refs is None:
                dims = (name,) if ds.ndim == 1 else ()
            else:
                dims = tuple(f[r[0]].name.lstrip("/") for r in refs)
            if len(dims) != ds.ndim:
                raise KeyError(name)
            values = ds[()]
            if values.dtype.kind in "SO":  # NetCDF strings (the iq labels)
                values = values.astype(str)
            self.variables[name] = _Variable(dims, np.asarray(values))

    def __getitem__(self, name: str) -> _Variable:
        return self.variables[name]


def _attr(v: Any) -> Any:
    if isinstance(v, bytes | np.bytes_):
        return v.decode("utf-8", "replace")
    if isinstance(v, np.ndarray) and v.size == 1 and v.dtype.kind in "biuf":
        return v.reshape(()).item()
    return v


def read_direct(path: str | os.PathLike[str]) -> Hologram | Image:
    """Read a holoradar file with h5py, without xarray: the same object as
    ``from_dataset(xarray.open_dataset(path))`` in a tenth of the time (what a
    survey of small frames spends most of its time on).

    Raises ``KeyError``/``OSError``/``ValueError`` on anything unexpected; the caller
    then takes the xarray path, whose messages explain the problem.
    """
    import h5py

    with h5py.File(path, "r") as f:
        view = _H5View(f)
    return from_dataset(view, what=str(path))


def read_history(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The processing history stored in a holoradar NetCDF file (a list of steps).

    Read as the file's global attribute through h5py (what ``holoradar image`` does for
    every input: xarray's import and open cost ten times more); a file h5py cannot
    read is opened with xarray, whose errors explain it."""
    try:
        import h5py

        with h5py.File(Path(path), "r") as f:
            text = _attr(f.attrs.get("history", "[]"))
    except (OSError, KeyError):
        import xarray as xr

        with xr.open_dataset(Path(path), engine="h5netcdf") as ds:
            text = ds.attrs.get("history", "[]")
    try:
        return list(json.loads(text))
    except (ValueError, TypeError):
        raise ValueError(f"{path}: the history attribute is not JSON") from None
