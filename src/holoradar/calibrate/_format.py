"""The calibration file's codec: NetCDF-4 encoding, checked decoding, atomic writing.

Layout and guarantees: :mod:`holoradar.calibrate.store`. This module does not
import :class:`~holoradar.calibrate.calibration.Calibration`: it encodes what a
calibration holds (its attributes) and decodes into the class it is given, so
that both :meth:`Calibration.save`/:meth:`Calibration.load` and the functions
of :mod:`.store` use it without an import cycle.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..io.netcdf import source_from_json, source_to_json
from ..io.output import check_output, write_via_temp

FORMAT = "1"
SUFFIXES = (".nc", ".nc4")


def _version() -> str:
    from .._version import __version__

    return __version__


def _iq(a: np.ndarray) -> np.ndarray:
    return np.stack([a.real, a.imag], axis=-1).astype(np.float64)


def to_dataset(cal: Any) -> Any:
    """The ``xarray.Dataset`` of a :class:`Calibration` (layout: :mod:`.store`)."""
    import xarray as xr

    fy, yx = ("frequency", "y", "x", "iq"), ("y", "x")

    def var(dims: tuple[str, ...], values: np.ndarray, long_name: str, units: str) -> Any:
        return xr.Variable(dims, values, {"long_name": long_name, "units": units})

    data = {
        "dc": var(fy, np.stack([cal.dc_i, cal.dc_q], axis=-1), "DC offset of the raw I and Q "
                  "channels", "1"),
        "iq_gain": var(("frequency",), np.asarray(cal.iq_gain, float), "gain of the Q channel "
                       "relative to I, as delivered", "1"),
        "iq_phase": var(("frequency",), np.asarray(cal.iq_phase, float), "phase error of the Q "
                        "channel, as delivered", "rad"),
        "response": var(("frequency", "iq"), _iq(cal.response), "complex response common to "
                        "all elements", "1"),
        "element_gain": var(fy, _iq(cal.gains), "complex gain of each element relative to "
                            "the response", "1"),
        "dead": var(yx, cal.dead.astype(np.int8), "1 = dead element", "1"),
        "noisy": var(yx, cal.noisy.astype(np.int8), "1 = noisy element", "1"),
    }
    coords = {
        "x": xr.Variable(("x",), np.asarray(cal.x, float), {"long_name": "element x",
                                                            "units": "m", "axis": "X"}),
        "y": xr.Variable(("y",), np.asarray(cal.y, float), {"long_name": "element y",
                                                            "units": "m", "axis": "Y"}),
        "frequency": xr.Variable(("frequency",), cal.frequencies, {
            "long_name": "frequency", "units": "Hz", "standard_name": "radiation_frequency"}),
        # A numeric component with its meanings (CF has no variable-length strings).
        "iq": xr.Variable(("iq",), np.array([0, 1], np.int8), {
            "long_name": "component: I or real part, Q or imaginary part", "units": "1",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "in_phase_or_real quadrature_or_imaginary"}),
    }
    attrs: dict[str, Any] = {
        "Conventions": "CF-1.8", "holoradar_kind": "Calibration",
        "holoradar_calibration_format": FORMAT, "holoradar_version": _version(),
        "device": cal.device, "iq_sign": cal.iq_sign, "wideband": int(cal.is_wideband),
        "provenance": json.dumps(cal.provenance, sort_keys=True), "sha256": cal.checksum,
    }
    src = source_to_json(cal.source)
    if src is not None:
        attrs["source"] = src
    return xr.Dataset(data, coords=coords, attrs=attrs)


def from_dataset(cls: type[Any], ds: Any, what: str) -> Any:
    """Rebuild the calibration (of class ``cls``) that :func:`to_dataset` stored, checking
    everything."""
    kind = ds.attrs.get("holoradar_kind")
    if kind != "Calibration":
        found = f"a holoradar {kind} file" if kind else "not a holoradar file"
        raise ValueError(f"{what} is not a holoradar calibration ({found}; variables "
                         f"{sorted(map(str, ds.variables))})")
    fmt = str(ds.attrs.get("holoradar_calibration_format"))
    if fmt != FORMAT:
        raise ValueError(f"{what}: calibration format {fmt!r} is not known (this holoradar "
                         f"reads format {FORMAT!r})")
    need = ["dc", "iq_gain", "iq_phase", "response", "element_gain", "dead", "noisy", "x", "y",
            "frequency"]
    missing = [n for n in need if n not in ds.variables]
    missing += [a for a in ("device", "iq_sign", "wideband", "provenance", "sha256")
                if a not in ds.attrs]
    if missing:
        raise ValueError(f"{what}: the calibration lacks {missing}")
    dims = {"dc": ("frequency", "y", "x", "iq"), "element_gain": ("frequency", "y", "x", "iq"),
            "iq_gain": ("frequency",), "iq_phase": ("frequency",),
            "response": ("frequency", "iq"), "dead": ("y", "x"), "noisy": ("y", "x")}
    v: dict[str, np.ndarray] = {}
    for name, d in dims.items():
        if tuple(ds[name].dims) != d:
            raise ValueError(f"{what}: variable {name!r} must have dimensions {d}, got "
                             f"{tuple(ds[name].dims)}")
        arr = np.asarray(ds[name].values)
        if not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
            raise ValueError(f"{what}: variable {name!r} must hold numbers, got {arr.dtype}")
        v[name] = arr
    if ds.sizes.get("iq") != 2:
        raise ValueError(f"{what}: dimension 'iq' must have size 2, got {ds.sizes.get('iq')}")
    for name in ("dead", "noisy"):
        if not np.all(np.isin(v[name], (0, 1))):
            raise ValueError(f"{what}: {name!r} must hold 0 or 1")
    f = np.asarray(ds["frequency"].values, float).ravel()
    wide = int(ds.attrs["wideband"])
    if wide not in (0, 1) or (not wide and f.size != 1):
        raise ValueError(f"{what}: attribute 'wideband' must be 1, or 0 with one frequency")
    try:
        provenance = json.loads(str(ds.attrs["provenance"]))
    except ValueError:
        raise ValueError(f"{what}: the provenance attribute is not JSON") from None
    if not isinstance(provenance, dict):
        raise ValueError(f"{what}: the provenance attribute must be a JSON object")
    src = ds.attrs.get("source")
    try:
        cal = _build(cls, ds, v, f, wide, src, provenance)
    except (ValueError, TypeError, KeyError, IndexError) as exc:
        raise ValueError(f"{what}: {exc}") from None
    if cal.checksum != str(ds.attrs["sha256"]):
        raise ValueError(f"{what}: the content does not match its sha256 checksum: the file is "
                         "damaged or was edited")
    return cal


def _build(cls: type[Any], ds: Any, v: dict[str, np.ndarray], f: np.ndarray, wide: int,
           src: Any, provenance: dict[str, Any]) -> Any:
    return cls(
        str(ds.attrs["device"]), np.asarray(ds["x"].values, float),
        np.asarray(ds["y"].values, float), f if wide else float(f[0]),
        iq_sign=str(ds.attrs["iq_sign"]),
        response=v["response"][..., 0] + 1j * v["response"][..., 1],
        gains=v["element_gain"][..., 0] + 1j * v["element_gain"][..., 1],
        dc_i=v["dc"][..., 0], dc_q=v["dc"][..., 1], iq_gain=v["iq_gain"],
        iq_phase=v["iq_phase"], dead=v["dead"].astype(bool), noisy=v["noisy"].astype(bool),
        source=None if src is None else source_from_json(str(src)), provenance=provenance)


def write_file(cal: Any, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Write the calibration ``cal`` to ``path`` (see :meth:`Calibration.save`)."""
    target = check_output(path, suffixes=SUFFIXES, overwrite=overwrite)
    ds = to_dataset(cal)
    encoding = {name: {"_FillValue": None} for name in ds.variables if name != "iq"}

    def write(tmp: Path) -> None:
        ds.to_netcdf(tmp, engine="h5netcdf", encoding=encoding, invalid_netcdf=False)

    return write_via_temp(target, write)


def read_file(cls: type[Any], path: str | os.PathLike[str]) -> Any:
    """Read a calibration file into class ``cls`` (see :meth:`Calibration.load`)."""
    import h5py
    import xarray as xr

    src = Path(path)
    if not src.is_file():
        raise ValueError(f"calibration {str(src)!r} is not a file")
    if src.stat().st_size == 0:
        raise ValueError(f"calibration {str(src)!r} is empty")
    def touch(_name: str, obj: Any) -> None:
        dict(obj.attrs)
        if isinstance(obj, h5py.Dataset):
            obj[()]

    try:  # h5py fails cleanly on a damaged file: read it all before xarray opens it
        with h5py.File(src, "r") as f:
            dict(f.attrs)
            f.visititems(touch)
    except Exception as exc:
        raise ValueError(f"calibration {str(src)!r} is not a readable NetCDF-4/HDF5 file "
                         f"({type(exc).__name__}: {exc})") from None
    try:
        with xr.open_dataset(src, engine="h5netcdf") as ds:
            ds.load()
            return from_dataset(cls, ds, what=f"calibration {str(src)!r}")
    except ValueError:
        raise
    except Exception as exc:  # a damaged file can fail in the HDF5 layer in many ways
        raise ValueError(f"calibration {str(src)!r} is not a readable NetCDF-4/HDF5 file "
                         f"({type(exc).__name__}: {exc})") from None
