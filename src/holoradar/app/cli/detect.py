"""``holoradar detect``: the objects in an image, a hologram or a survey, as a table.

FILE is one of

* an image file (what ``holoradar image`` or ``holoradar mosaic`` writes): a plane
  is searched as it is; a volume needs ``--hologram`` (the hologram it was imaged
  from: each object is the point response fitted to it, unbiased in range) or
  ``--z`` (one plane of it, from the image alone);
* a hologram file: imaged first on the planes ``--z`` (required) through the ground
  flags, four pixels per pitch, then searched with the hologram's fit;
* a survey store (``.zarr`` from ``holoradar batch``): each frame searched with its
  own hologram (the frame's file, read again) on all stored planes, or with ``--z``
  on one stored plane from the images alone; the objects are placed in survey
  coordinates from the frames' positions, and an object seen by several
  overlapping frames is reported once (by the frame it lies nearest the centre of).

The table (``hr.detect``'s columns; a store's also ``frame``) goes to the terminal
and, with ``-o``, to a CSV, JSON or GeoJSON file chosen by its suffix.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from pathlib import Path
from typing import Any

import click
import numpy as np

from .common import (
    Reporter,
    _plain,
    check_planes,
    depth_ranges,
    layout_option,
    medium_from_options,
    medium_options,
    output_options,
    refuse_outside_planes,
)

__all__ = ["COMMANDS", "geojson", "table_lines"]

_SUFFIXES = [".csv", ".json", ".geojson"]
_KINDS = ("point", "line", "area")
_GEOMETRY = ("x", "y", "x_start", "y_start", "x_end", "y_end")


# ---------------------------------------------------------------- option parsing

def _eps_interval(text: str | None) -> tuple[float, float] | None:
    from ...analysis.detect.table import as_eps_interval

    if text is None:
        return None
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        pair = (float(parts[0]), float(parts[1]))
        return as_eps_interval(pair)
    except ValueError:
        raise click.BadParameter(f"expected LO,HI: two real permittivities >= 1 with LO <= HI, "
                                 f"e.g. 2.2,2.8; got {text!r}", param_hint="--eps-interval") \
            from None


def _false_alarm(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = math.nan
    if not 0 < v <= 0.1:
        raise click.BadParameter("expected the expected number of false objects per resolution "
                                 f"cell, a number in (0, 0.1] such as 1e-3; got {text!r}",
                                 param_hint="--false-alarm")
    return v


def _kinds(text: str) -> tuple[str, ...]:
    ks = tuple(k.strip() for k in text.split(",") if k.strip())
    if not ks or any(k not in _KINDS for k in ks):
        raise click.BadParameter(f"expected a comma-separated list of {', '.join(_KINDS)}; "
                                 f"got {text!r}", param_hint="--kinds")
    return ks


def _ground_given(spec: dict[str, Any]) -> bool:
    return any(spec.get(k) is not None for k in ("eps", "z_surface", "layers", "medium_file",
                                                  "tan_delta", "sigma"))


# ---------------------------------------------------------------- the inputs

def _history_medium(path: Path) -> Any:
    """The ground a holoradar image file was made through (its history's migrate step)."""
    from ...io import read_history
    from ...physics.medium import Medium

    if path.suffix.lower() not in (".nc", ".nc4"):
        return None
    try:
        steps = read_history(path)
    except (ValueError, OSError):
        return None
    for step in reversed(steps):
        if isinstance(step, dict) and step.get("step") == "migrate":
            g = (step.get("parameters") or {}).get("medium")
            if not g:
                return None
            try:
                return Medium(tuple(float(z) for z in g["z_interfaces"]),
                              tuple(complex(str(e).replace(" ", "")) for e in g["eps"]))
            except (KeyError, TypeError, ValueError):
                return None
    return None


def _options_of(img: Any) -> dict[str, Any]:
    """``migrate``'s settings an image shows: its method and working precision."""
    opts: dict[str, Any] = {}
    if getattr(img, "method", "angular") in ("angular", "fresnel"):
        opts["method"] = img.method
    if np.asarray(img.data).dtype == np.complex64:
        opts["dtype"] = np.complex64
    return opts


def _detect(img: Any, **kwargs: Any) -> Any:
    """``hr.detect``, without the aliasing warnings of its own migrations (the user's data
    were warned of when imaged)."""
    from ..._validate import AliasingWarning
    from ...analysis.detect import detect

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AliasingWarning)
        return detect(img, **kwargs)


def _fit(img: Any, holo: Any, medium: Any, opts: dict[str, Any], args: dict[str, Any],
         name: str, advice: str) -> Any:
    """``detect`` with the hologram's fit; its refusals name the option (or the frame) that
    gave it and say what to do in the command's terms (``advice``)."""
    try:
        return _detect(img, hologram=holo, medium=medium, migrate_options=opts, **args)
    except ValueError as exc:
        msg = str(exc)
        if msg.startswith("image is not"):
            differ = re.search(r"\(they differ by [^)]*\)", msg)
            raise ValueError(f"{name}: the image is not this hologram's migration"
                             f"{' ' + differ.group(0) if differ else ''}: {advice}") from None
        if msg.startswith("image does not come"):
            raise ValueError(f"{name}: the image's grid is not this hologram's elements at a "
                             f"whole upsampling: {advice}") from None
        if msg.startswith("hologram must hold one frame"):
            raise ValueError(f"{name}: the hologram holds several frames (data shape "
                             f"{np.shape(holo.data)}); {advice}") from None
        if msg.startswith("hologram must lie on a level aperture"):
            raise ValueError(f"{name}: the hologram's array is tilted (its pose), which "
                             f"the point fit does not support yet; {advice}") from None
        if msg.startswith("hologram"):
            raise ValueError(f"{name}: {msg}") from None
        raise


def _level(holo: Any, medium: Any) -> tuple[Any, Any]:
    """A level hologram at a height as the fit takes it: on its own plane (identity pose)
    with the ground seen from that plane, as ``migrate`` images it (ranges from the
    array); its position across is left to the caller."""
    from dataclasses import replace

    from ...data.pose import IDENTITY

    return replace(holo, pose=IDENTITY), _from_array(medium, float(holo.pose.center[2]))


def _from_array(medium: Any, height: float) -> Any:
    """The ground seen from an array at world height ``height`` (``migrate``'s shift):
    interfaces at ranges from the array, so that depths below the surface come out."""
    from ...imaging.oblique import _shifted

    if medium is None or height == 0.0:
        return medium
    return _shifted(medium, height)


def _from_image(path: Path, img: Any, z: str | None, hologram: Path | None,
                medium: Any, layout: str | None, check: bool,
                args: dict[str, Any]) -> tuple[Any, dict[str, Any]]:
    from .common import read_hologram

    info: dict[str, Any] = {"input": "image"}
    if hologram is not None:
        if z is not None:
            raise click.BadParameter("give --hologram (the fit on every plane) or --z (one "
                                     "plane, from the image alone), not both", param_hint="--z")
        holo = read_hologram(hologram, layout, check)
        info["hologram"] = str(hologram)
        if holo.pose.is_level:
            holo, medium = _level(holo, medium)
        return _fit(img, holo, medium, _options_of(img), args, "--hologram",
                    "give the hologram FILE was imaged from (with the ground flags it was "
                    "imaged through), or --z RANGE to search one plane from the image "
                    "alone"), info
    volume = bool(img.has_z_axis) and np.asarray(img.z).size > 1
    if z is not None:
        zs = depth_ranges(z)
        if np.ndim(zs) != 0:
            raise click.BadParameter(f"expected one range in metres (the plane to search), got "
                                     f"{z!r}", param_hint="--z")
        refuse_outside_planes(float(zs), np.asarray(img.z), "--z", f"{path.name}'s planes")
        img = img.plane(float(zs))
    elif volume:
        raise click.BadParameter(
            f"{path.name} is a volume of {np.asarray(img.z).size} planes: give --hologram "
            "HOLO.nc (the hologram it was imaged from: objects fitted in 3-D) or --z RANGE (one "
            "plane, from the image alone)", param_hint="FILE")
    return _detect(img, medium=medium, **args), info


def _from_hologram(path: Path, holo: Any, z: str | None, medium: Any,
                   spec: dict[str, Any], check: bool, args: dict[str, Any],
                   report: Reporter) -> tuple[Any, dict[str, Any]]:
    from ...imaging.migrate import migrate

    if z is None:
        raise click.BadParameter(f"{path.name} is a hologram: give --z, the planes to image it "
                                 "on (range(s) from the array in metres, e.g. 0.3:0.5:0.01)",
                                 param_hint="--z")
    zs = depth_ranges(z)
    check_planes(holo, zs, z, medium, spec, check)
    img = migrate(holo, zs, medium=medium, upsample=4, progress=report.progress)
    if holo.pose.is_level:
        # The image is on the array's own axes, its planes ranges from the array.
        holo, medium = _level(holo, medium)
    return _fit(img, holo, medium, {}, args, "FILE",
                "image it with holoradar image and search one plane of the image with "
                "--z"), {"input": "hologram", "upsample": 4}


def _from_store(path: Path, z: str | None, spec: dict[str, Any], args: dict[str, Any],
                report: Reporter) -> tuple[Any, dict[str, Any], Any]:
    """Every frame searched, the objects in survey coordinates, duplicates merged."""
    import pandas as pd

    from ...io import load
    from ...survey import frame_image
    from ...survey.store import read_index, stored_settings

    if _ground_given(spec):
        raise click.BadParameter("a survey store keeps the ground its frames were imaged "
                                 "through: give no ground flag", param_hint="--eps/--z-surface")
    settings, _ = stored_settings(path)
    medium = settings.medium
    idx = read_index(path)
    frames = [i for i in range(idx["n"]) if idx["done"][i]]
    if not frames:
        raise ValueError(f"{path.name} holds no finished frame")
    plane = None
    if z is not None:
        zs = depth_ranges(z)
        if np.ndim(zs) != 0:
            raise click.BadParameter(f"expected one range in metres (the stored plane to "
                                     f"search), got {z!r}", param_hint="--z")
        refuse_outside_planes(float(zs), settings.z, "--z", "stored planes")
        plane = float(zs)
    holograms: dict[int, Any] = {}
    if plane is None:
        for i in frames:
            fp = str(idx["frame_path"][i])
            try:
                holograms[i] = load(fp)
            except (ValueError, OSError) as exc:
                raise ValueError(f"frame {idx['frame_name'][i]}'s hologram {fp} cannot be read "
                                 f"({exc}): give --z RANGE to search one stored plane of each "
                                 "frame from the images alone") from None
    tables = []
    for i in frames:
        img = frame_image(path, i)
        name = str(idx["frame_name"][i])
        if plane is None:
            holo = holograms[i]
            c = holo.pose.center
            # The fit works in the frame's own coordinates (a level array at z = 0, the
            # ground seen from its height as migrate imaged it: the planes are ranges from
            # the array); the image's pixels are the frame's world position plus offsets.
            local = type(img)(img.data, img.x - c[0], img.y - c[1], img.z, img.frequency,
                              img.method, has_z_axis=True)
            opts = {"method": settings.method, **_options_of(img)}
            flat, seen = _level(holo, medium)
            df = _fit(local, flat, seen, opts, args, f"frame {name}",
                      f"its hologram {idx['frame_path'][i]} is not the file the store was "
                      "imaged from (changed since holoradar batch?): run holoradar batch "
                      "again, or give --z RANGE to search one stored plane of each frame "
                      "from the images alone")
            shift = (c[0], c[1])
        else:
            # The stored planes are ranges from the frame's array: its ground is seen from
            # the array's height (the frame's z).
            df = _detect(img.plane(plane), medium=_from_array(medium, float(idx["frame_z"][i])),
                         **args)
            shift = (0.0, 0.0)
        df = _to_survey(df, shift)
        # Each frame reports the objects under its array: one beyond it is seen from the
        # side, fitted poorly, and left to the frame above it.
        outlines = df.attrs.get("outlines") or {}
        df["_outline"] = pd.Series([outlines.get(n) for n in range(len(df))], index=df.index,
                                   dtype=object)
        under = df["x"].between(img.x[0], img.x[-1]) & df["y"].between(img.y[0], img.y[-1])
        df = df[under].reset_index(drop=True)
        df["frame"] = name
        df["_off"] = np.hypot(df["x"] - idx["frame_x"][i], df["y"] - idx["frame_y"][i])
        df["_cell"] = max(df.attrs["resolution_cell"][:2])
        tables.append(df)
        report.line(f"frame {name}: {len(df)} object(s)")
    cols = [*tables[0].columns]
    full = pd.concat([t for t in tables if len(t)], ignore_index=True) if any(
        len(t) for t in tables) else pd.DataFrame(columns=cols)
    merged = _merge(full)
    # The areas' outlines travel as a column through the concatenation and the merge.
    outlines = {n: o for n, o in enumerate(merged.pop("_outline")) if isinstance(o, list)} \
        if "_outline" in merged else {}
    merged.attrs = {"outlines": outlines}
    info = {"input": "survey", "frames": len(frames), "model": "hologram" if plane is None
            else "window", "plane_m": plane, "per_frame": [
                {"frame": str(idx["frame_name"][i]), "array_z_m": float(idx["frame_z"][i]),
                 "threshold": t.attrs.get("threshold"),
                 "n_cells": t.attrs.get("n_cells"), "resolution_cell": t.attrs.get(
                     "resolution_cell")} for i, t in zip(frames, tables, strict=True)]}
    return merged, info, medium


def _to_survey(df: Any, shift: tuple[float, float]) -> Any:
    """A frame's table moved across by ``shift`` (its array's position): positions, line
    ends and the areas' outlines."""
    dx, dy = float(shift[0]), float(shift[1])
    if dx == 0.0 and dy == 0.0:
        return df
    for col in ("x", "x_start", "x_end"):
        df[col] = df[col] + dx
    for col in ("y", "y_start", "y_end"):
        df[col] = df[col] + dy
    df.attrs["outlines"] = {k: [[float(u) + dx, float(v) + dy] for u, v in ring]
                            for k, ring in df.attrs.get("outlines", {}).items()}
    return df


def _merge(df: Any) -> Any:
    """One row per object: rows of one kind from different frames closer than a lateral
    resolution cell are one object, kept from the frame it lies nearest the centre of."""
    if df.empty:
        return df.drop(columns=["_off", "_cell"])
    order = df.sort_values("_off", kind="stable").index
    kept: list[int] = []
    for i in order:
        r = df.loc[i]
        if not any(df.loc[j, "kind"] == r["kind"] and df.loc[j, "frame"] != r["frame"]
                   and math.hypot(df.loc[j, "x"] - r["x"], df.loc[j, "y"] - r["y"])
                   < max(r["_cell"], df.loc[j, "_cell"]) for j in kept):
            kept.append(i)
    out = df.loc[kept]
    out = out.sort_values("amplitude_db", ascending=False, kind="stable")
    return out.drop(columns=["_off", "_cell"]).reset_index(drop=True)


# ---------------------------------------------------------------- outputs

def _records(df: Any) -> list[dict[str, Any]]:
    """The table's rows as plain JSON values (NaN and infinities as null)."""
    return [{str(k): _plain(v) for k, v in row.items()} for row in df.to_dict("records")]


def geojson(df: Any, metadata: dict[str, Any], frame: str) -> dict[str, Any]:
    """The objects as a GeoJSON FeatureCollection in a local metric frame.

    Points are ``Point``, lines ``LineString`` (their ends), areas ``Polygon``: the
    outline ``hr.detect`` found (``df.attrs["outlines"]``, keyed by row position, a
    closed ring), or without one the rectangle of their length, width and azimuth
    about the centre; the properties are the table's row. Coordinates are ``(x, y)``
    in metres in the scene's (or the survey's) frame, not longitude and latitude: the
    top-level ``coordinate_frame`` member says so (RFC 7946 dropped the ``crs``
    member).

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame([{"kind": "point", "x": 0.1, "y": 0.2}])
    >>> geojson(df, {}, "scene")["features"][0]["geometry"]
    {'type': 'Point', 'coordinates': [0.1, 0.2]}
    """
    features = []
    outlines = df.attrs.get("outlines") or {}
    for n, row in enumerate(_records(df)):
        kind = row.get("kind")
        ends = [row.get(k) for k in ("x_start", "y_start", "x_end", "y_end")]
        if kind == "line" and all(v is not None for v in ends):
            geom = {"type": "LineString", "coordinates": [ends[:2], ends[2:]]}
        elif kind == "area" and outlines.get(n):
            ring = [[float(u), float(v)] for u, v in outlines[n]]
            if ring[0] != ring[-1]:
                ring.append(list(ring[0]))
            geom = {"type": "Polygon", "coordinates": [ring]}
        elif kind == "area":
            length, width = row.get("length") or 0.0, row.get("width") or 0.0
            az = math.radians(row.get("azimuth_deg") or 0.0)
            u = (math.cos(az) * length / 2, math.sin(az) * length / 2)
            v = (-math.sin(az) * width / 2, math.cos(az) * width / 2)
            ring = [[row["x"] + a * u[0] + b * v[0], row["y"] + a * u[1] + b * v[1]]
                    for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))]
            geom = {"type": "Polygon", "coordinates": [ring]}
        else:
            geom = {"type": "Point", "coordinates": [row["x"], row["y"]]}
        features.append({"type": "Feature", "id": n + 1, "geometry": geom, "properties": row})
    return {"type": "FeatureCollection",
            "coordinate_frame": {
                "type": "local", "units": "m", "axes": ["x", "y"], "frame": frame,
                "note": "coordinates are metres in a local Cartesian frame (not longitude and "
                        "latitude); depths and ranges are in the properties"},
            "metadata": metadata, "features": features}


def _write(out: Path, df: Any, metadata: dict[str, Any], frame: str) -> None:
    from ..atomic import write_atomic

    suffix = out.suffix.lower()
    if suffix == ".csv":
        payload = df.to_csv(index=False).encode()
    elif suffix == ".geojson":
        payload = json.dumps(geojson(df, metadata, frame), indent=1, allow_nan=False).encode()
    else:
        payload = json.dumps({"metadata": metadata, "objects": _records(df)}, indent=1,
                             allow_nan=False).encode()
    write_atomic(out, payload)


def table_lines(df: Any) -> list[str]:
    """One line per object: kind, x, y, depth with its 95 % interval (or range +- its
    standard deviation without a ground), amplitude, SNR; a line's length and azimuth.

    Examples
    --------
    >>> import pandas as pd
    >>> row = {"kind": "point", "x": 0.1, "y": -0.02, "range": 0.42, "depth": 0.12,
    ...        "depth_low": 0.11, "depth_high": 0.13, "range_std": 1e-3,
    ...        "amplitude_db": -20.0, "snr_db": 35.0, "length": 0.0, "azimuth_deg": float("nan")}
    >>> print("\\n".join(table_lines(pd.DataFrame([row]))))
      #  kind      x cm    y cm  depth cm [95 %]         amp dB  SNR dB
      1  point     10.0    -2.0  12.0 [11.0, 13.0]        -20.0    35.0
    """
    depth = "depth" in df and bool(np.isfinite(df["depth"]).any())
    head = "depth cm [95 %]" if depth else "range cm +- std"
    lines = [f"  #  {'kind':<6} {'x cm':>7} {'y cm':>7}  {head:<22} {'amp dB':>7} {'SNR dB':>7}"]
    for n, r in enumerate(df.to_dict("records")):
        if depth and not np.isfinite(r["depth_low"]):
            # found on one plane, its range not fitted: the plane's depth, not a bound
            where = f"{r['depth'] * 100:.1f} (the plane's)"
        elif depth:
            where = f"{r['depth'] * 100:.1f} [{r['depth_low'] * 100:.1f}, " \
                    f"{r['depth_high'] * 100:.1f}]"
        else:
            where = f"{r['range'] * 100:.1f} +- {r['range_std'] * 100:.2f}"
        size = ""
        if r["kind"] != "point" and np.isfinite(r.get("length", np.nan)):
            size = f"  length {r['length'] * 100:.1f} cm"
            if np.isfinite(r.get("azimuth_deg", np.nan)):
                size += f" at {r['azimuth_deg']:.0f} deg"
        frame = f"  ({r['frame']})" if "frame" in r else ""
        lines.append(f"{n + 1:>3}  {r['kind']:<6} {r['x'] * 100:>7.1f} {r['y'] * 100:>7.1f}  "
                     f"{where:<22} {r['amplitude_db']:>7.1f} {r['snr_db']:>7.1f}{size}{frame}")
    return lines


def _medium_dict(medium: Any) -> Any:
    if medium is None:
        return None
    return {"z_interfaces_m": [float(v) for v in medium.z_interfaces],
            "eps": [{"re": float(complex(e).real), "im": float(complex(e).imag)}
                    for e in medium.eps]}


def detection_options(f: Any) -> Any:
    """The options that say what to search and how (``detect`` and ``report``): the
    planes of a hologram (``--z``), the ground, its permittivity interval, the
    false-alarm rate and the kinds."""
    for opt in reversed([
        click.option("--z", "z", default=None,
                     help="A hologram FILE: the planes to image it on (m: 0.4 or "
                          "start:stop:step). An image volume or a survey store: the one "
                          "plane to search from the image alone."),
        medium_options,
        click.option("--eps-interval", default=None, metavar="LO,HI",
                     help="Interval of the ground's real permittivity, e.g. 2.2,2.8: widens "
                          "the depth interval (needs a ground)."),
        click.option("--false-alarm", default="1e-3", show_default=True, metavar="P",
                     help="Expected false objects per resolution cell on noise: sets the "
                          "threshold from the image's own noise."),
        click.option("--kinds", default="point,line,area", show_default=True,
                     metavar="KIND,...",
                     help="Which kinds of object to report: point, line, area."),
    ]):
        f = opt(f)
    return f


# ---------------------------------------------------------------- the command

@click.command()
@click.argument("file", type=click.Path(exists=True, path_type=Path))
@detection_options
@click.option("--hologram", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None,
              help="An image FILE's hologram (the file it was imaged from): each object is "
                   "its point response fitted to it (unbiased position, with uncertainty).")
@click.option("-o", "--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="The table: .csv, .json (records and metadata) or .geojson (a "
                   "FeatureCollection in metres, for GIS).")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@layout_option
@output_options
def detect(file: Path, z: str | None, medium_spec: dict[str, Any], eps_interval: str | None,
           false_alarm: str, kinds: str, hologram: Path | None, out: Path | None, force: bool,
           layout: str | None, check: bool, report: Reporter) -> None:
    """List the objects in an image, a hologram or a survey store.

    FILE: an image (holoradar image/mosaic), a hologram (imaged on --z first) or a
    survey store (.zarr from holoradar batch: objects in survey coordinates).
    Prints one line per object; -o writes the table (.csv, .json, .geojson).
    """
    from ...data.hologram import Image
    from ...io import load
    from ...io.output import check_output
    from ...survey.store import is_survey

    inputs = [file] + ([hologram] if hologram is not None else [])
    if out is not None:
        check_output(out, suffixes=_SUFFIXES, inputs=inputs, overwrite=force, name="--out")
    interval = _eps_interval(eps_interval)
    args = {"false_alarm": _false_alarm(false_alarm), "kinds": _kinds(kinds)}
    store = file.is_dir()
    if store and not is_survey(file):
        raise click.BadParameter(f"{file} is a folder but not a survey store (holoradar batch "
                                 "writes one)", param_hint="FILE")
    if store and hologram is not None:
        raise click.BadParameter("a survey store's frames are fitted with their own "
                                 "holograms: give no --hologram", param_hint="--hologram")

    if store:
        if interval is not None:
            from ...survey.store import stored_settings

            m = stored_settings(file)[0].medium
            if m is None or not m.z_interfaces:
                raise click.BadParameter("needs a ground: the store was imaged in free space",
                                         param_hint="--eps-interval")
        df, info, medium = _from_store(file, z, medium_spec, {**args, "eps_interval": interval},
                                       report)
        frame = "survey: x, y are world metres (the frames' positions plus pixel offsets)"
    else:
        obj = load(file, layout=layout, check=check)
        freq = float(np.mean(np.atleast_1d(obj.frequency)))
        medium = medium_from_options(medium_spec, freq)
        is_image = isinstance(obj, Image)
        if medium is None and is_image and not _ground_given(medium_spec):
            medium = _history_medium(file)
            if medium is not None:
                report.line(f"ground from {file.name}'s history: the ground it was imaged "
                            "through")
        if interval is not None and (medium is None or not medium.z_interfaces):
            raise click.BadParameter("needs a ground: --eps and --z-surface (or an image made "
                                     "through one)", param_hint="--eps-interval")
        full = {**args, "eps_interval": interval}
        if is_image:
            df, info = _from_image(file, obj, z, hologram, medium, layout, check, full)
        else:
            if hologram is not None:
                raise click.BadParameter(f"{file.name} is itself a hologram: give no "
                                         "--hologram", param_hint="--hologram")
            df, info = _from_hologram(file, obj, z, medium, medium_spec, check, full, report)
        info.update(df.attrs)
        frame = "scene: x, y are metres on the image's axes"

    metadata = _plain({"source": str(file), **info, "false_alarm": args["false_alarm"],
                "kinds": list(args["kinds"]), "medium": _medium_dict(medium),
                "eps_interval": None if interval is None else list(interval),
                "columns": [str(c) for c in df.columns], "units": "m, dB, deg"})
    if out is not None:
        _write(out, df, metadata, frame)
    lines = table_lines(df) if len(df) else ["no object above the threshold"]
    counts = ", ".join(f"{int((df['kind'] == k).sum())} {k}(s)" for k in _KINDS
                       if (df["kind"] == k).any()) or "none"
    head = f"{file.name}: {len(df)} object(s) ({counts}), false alarm {args['false_alarm']:g} " \
           "per resolution cell"
    wrote = [f"wrote {out}"] if out is not None else []
    report.done({"objects": _records(df), "n_objects": len(df), "metadata": metadata,
                 "out": None if out is None else str(out)},
                [head, *lines, *wrote], result=[*lines, *wrote])


COMMANDS = [detect]
