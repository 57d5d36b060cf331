"""A source's device, settings and processing history, for the report to show.

A holoradar NetCDF file carries its device (array, frequencies, illumination, pose,
recorded polarisation) and a ``history`` attribute, a JSON list of the steps that
made it (docs/files.md). They are read from the file's attributes with h5py (no
xarray), and from the object itself where there is no file.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["device_rows", "file_attributes", "history_of", "store_rows"]

_CM = 100.0


def file_attributes(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The global attributes of a NetCDF-4 file (strings decoded; {} if unreadable).

    Examples
    --------
    >>> file_attributes("no/such/file.nc")
    {}
    """
    p = Path(path)
    if p.suffix.lower() not in (".nc", ".nc4") or not p.is_file():
        return {}
    try:
        import h5py

        with h5py.File(p, "r") as f:
            out = {}
            for k, v in f.attrs.items():
                if k.startswith("_"):
                    continue
                if isinstance(v, bytes | np.bytes_):
                    v = v.decode("utf-8", "replace")
                elif isinstance(v, np.ndarray) and v.size == 1:
                    v = v.reshape(()).item()
                elif isinstance(v, np.ndarray):
                    v = v.tolist()
                out[str(k)] = v
            return out
    except (OSError, ValueError):
        return {}


def history_of(attrs: dict[str, Any]) -> list[dict[str, Any]]:
    """The processing steps a file's attributes hold (oldest first; [] if none).

    Examples
    --------
    >>> history_of({"history": '[{"step": "simulate", "parameters": {}}]'})
    [{'step': 'simulate', 'parameters': {}}]
    >>> history_of({"history": "not json"})
    []
    """
    try:
        steps = json.loads(attrs.get("history", "[]"))
    except (TypeError, ValueError):
        return []
    return [s for s in steps if isinstance(s, dict)] if isinstance(steps, list) else []


def _frequencies(f: Any) -> str:
    f = np.atleast_1d(np.asarray(f, dtype=float))
    if f.size == 1:
        return f"{f[0] / 1e9:.4g} GHz"
    return f"{f.size} from {f[0] / 1e9:.4g} to {f[-1] / 1e9:.4g} GHz"


def _axis(v: Any) -> tuple[int, float]:
    v = np.asarray(v, dtype=float)
    return v.size, float(v[1] - v[0]) if v.size > 1 else float("nan")


def _source(attrs: dict[str, Any], obj: Any) -> str | None:
    src = getattr(obj, "source", None)
    if src is not None:
        return type(src).__name__ + _fields(src)
    text = attrs.get("source")
    if not text:
        return None
    try:
        d = json.loads(text)
    except (TypeError, ValueError):
        return str(text)
    if not isinstance(d, dict):
        return str(text)
    kind = d.pop("type", "source")
    return f"{kind} " + ", ".join(f"{k} = {v}" for k, v in d.items())


def _fields(src: Any) -> str:
    from dataclasses import fields, is_dataclass

    if not is_dataclass(src):
        return ""
    parts = []
    for f in fields(src):
        v = getattr(src, f.name)
        if isinstance(v, np.ndarray):
            v = np.round(v, 6).tolist()
        parts.append(f"{f.name} = {v}")
    return " (" + ", ".join(parts) + ")" if parts else ""


def device_rows(obj: Any, attrs: dict[str, Any]) -> list[tuple[str, str]]:
    """The device and its settings as (label, value) rows: the array or the image's
    grid, the frequencies, the illumination, the pose, the recorded polarisation, and
    the file's holoradar version.

    Parameters
    ----------
    obj : Hologram or Image
        What the source holds.
    attrs : dict
        Its file's attributes (:func:`file_attributes`; {} for an object).

    Examples
    --------
    >>> import numpy as np, holoradar as hr
    >>> x = (np.arange(16) - 7.5) * 0.0125
    >>> rows = dict(device_rows(hr.Hologram(np.ones((16, 16)), x, x, 9.9e9), {}))
    >>> rows["array"], rows["frequency"]
    ('16 x 16 elements at 1.25 x 1.25 cm pitch (20 x 20 cm)', '9.9 GHz')
    """
    from ..data.hologram import Image

    rows: list[tuple[str, str]] = []
    nx, sx = _axis(obj.x)
    ny, sy = _axis(obj.y)
    if isinstance(obj, Image):
        z = np.atleast_1d(np.asarray(obj.z, dtype=float))
        rows.append(("image", f"{nx} x {ny} pixels at {sx * _CM:.3g} x {sy * _CM:.3g} cm, "
                              f"{z.size} plane(s) at ranges {z[0] * _CM:.1f}"
                              + (f" to {z[-1] * _CM:.1f}" if z.size > 1 else "") + " cm"))
        rows.append(("imaging method", str(obj.method)))
    else:
        rows.append(("array", f"{nx} x {ny} elements at {sx * _CM:.3g} x {sy * _CM:.3g} cm "
                              f"pitch ({nx * sx * _CM:.3g} x {ny * sy * _CM:.3g} cm)"))
        rows.append(("recording", "scanned transceiver (monostatic)" if obj.monostatic
                     else "receiver array lit by a separate source"))
        src = _source(attrs, obj)
        if src:
            rows.append(("illumination", src))
        pose = getattr(obj, "pose", None)
        if pose is not None:
            c = [float(v) * _CM for v in pose.center]
            rows.append(("pose", f"centre ({c[0]:.1f}, {c[1]:.1f}, {c[2]:.1f}) cm, tilt "
                                 f"{np.degrees(pose.tilt):.1f} deg, azimuth "
                                 f"{np.degrees(pose.azimuth):.1f} deg"))
        pol = getattr(obj, "polarization", None)
        if pol is not None:
            rows.append(("recorded field", "unit vector (" + ", ".join(
                f"{float(v):.3g}" for v in np.asarray(pol).ravel()) + ") (x, y, z)"))
    if obj.frequency is not None:
        rows.append(("frequency", _frequencies(obj.frequency)))
    if "holoradar_version" in attrs:
        rows.append(("written by", f"holoradar {attrs['holoradar_version']}"))
    if "holoradar_conventions" in attrs:
        rows.append(("file layout", f"holoradar's NetCDF conventions, version "
                                    f"{attrs['holoradar_conventions']} ("
                                    f"{attrs.get('Conventions', 'CF')})"))
    return rows


def store_rows(store: Path) -> list[tuple[str, str]]:
    """A survey store's settings and frames as (label, value) rows."""
    from ..survey.store import describe_store

    d = describe_store(store)
    s, g = d["settings"], d["geometry"]
    z = np.asarray(s.get("z_m", []), dtype=float)
    rows = [("survey store", f"{d['frames_stored']} frame(s) stored of "
                             f"{d['frames_expected']}"),
            ("planes", f"{z.size} at ranges " + (f"{z[0] * _CM:.1f}" if z.size else "")
             + (f" to {z[-1] * _CM:.1f}" if z.size > 1 else "") + " cm from the arrays"),
            ("imaging method", f"{s.get('method')}, {s.get('upsample')} pixel(s) per pitch"),
            ("ground", str(d["ground"]))]
    if d["extent_m"]:
        x0, x1, y0, y1 = (v * _CM for v in d["extent_m"])
        rows.append(("frames' centres", f"x {x0:.1f} to {x1:.1f} cm, y {y0:.1f} to "
                                        f"{y1:.1f} cm"))
    px, py = (float(v) * _CM for v in g["pitch_m"])
    rows.append(("each frame's array", f"{g['nx']} x {g['ny']} elements at {px:.3g} x "
                                       f"{py:.3g} cm pitch, "
                 + ("scanned transceiver" if g["monostatic"] else "receiver array")
                 + f", {g['height_m'] * _CM:.1f} cm below the reference plane"))
    rows.append(("frequency", _frequencies(g["frequency_hz"])))
    if d["not_stored"]:
        rows.append(("not stored", "; ".join(f"{e['name']}: {e['reason']}"
                                             for e in d["not_stored"])))
    return rows
