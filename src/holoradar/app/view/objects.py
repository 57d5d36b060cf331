"""The objects the viewer overlays: read from ``holoradar detect``'s tables, drawn as glyphs.

An objects table is what :func:`holoradar.detect` returns (one row per object:
``kind``, ``x``, ``y``, ``range``, ``depth`` with ``depth_low``/``depth_high``,
``length``, ``width``, ``azimuth_deg``, a line's ``x_start`` ... ``y_end``,
``snr_db``; an area's outline in ``attrs["outlines"]``, keyed by row position)
or a file ``holoradar detect -o`` wrote (``.csv``, ``.json``, ``.geojson``).
Objects are numbered from 1 in the table's order, as the GeoJSON features'
``id``. Everything here is plain data for the page's Bokeh sources, in the
page's units: centimetres; the sections' vertical axis is the range less the
ground surface's (the page's depth, or the range without a ground).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from .display import CM

__all__ = ["TABLE_FIELDS", "outline_of", "overlay", "read_objects", "section_marks",
           "table_rows"]

#: The page's table: (source field, title).
TABLE_FIELDS = (("n", "#"), ("kind", "kind"), ("x", "x (cm)"), ("y", "y (cm)"),
                ("depth", "depth (cm) [95 %]"), ("size", "size (cm)"), ("snr", "SNR (dB)"))

_NEEDED = ("kind", "x", "y", "range")
_SUFFIXES = (".csv", ".json", ".geojson")


def read_objects(path: str | Path) -> Any:
    """An objects table from a file written by ``holoradar detect -o``.

    Parameters
    ----------
    path : path
        ``.csv`` (the table), ``.json`` (``{"metadata": ..., "objects": [rows]}``)
        or ``.geojson`` (features whose properties are the rows; an area's
        ``Polygon`` is its outline).

    Returns
    -------
    pandas.DataFrame
        The rows, ``attrs["outlines"]`` the areas' outlines (metres) by row position.

    Raises
    ------
    ValueError
        Another suffix, a file that is not such a table, or one without the
        columns ``kind``, ``x``, ``y``, ``range``; the message names the file.
    """
    import pandas as pd

    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in _SUFFIXES:
        raise ValueError(f"{p.name}: expected an objects table from holoradar detect -o "
                         f"(.csv, .json or .geojson), got the suffix {p.suffix!r}")
    outlines: dict[int, list[list[float]]] = {}
    try:
        if suffix == ".csv":
            df = pd.read_csv(p)
        else:
            doc = json.loads(p.read_text(encoding="utf-8"))
            if suffix == ".json":
                rows = doc["objects"] if isinstance(doc, dict) else None
            else:
                feats = doc["features"] if isinstance(doc, dict) else None
                rows = None if not isinstance(feats, list) else \
                    [{k: v for k, v in f["properties"].items() if k != "outline_xy"}
                     for f in feats]
                for n, f in enumerate(feats or []):
                    # The outline in the table's metres (the geometry is longitude and
                    # latitude); a file of older versions has it in the geometry.
                    props = f["properties"] or {}
                    g = f.get("geometry") or {}
                    ring = props.get("outline_xy") if "crs_of_properties" in doc \
                        else (g["coordinates"][0] if g.get("type") == "Polygon" else None)
                    if ring and props.get("kind") == "area":
                        outlines[n] = [[float(u), float(v)] for u, v in ring]
            if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
                raise ValueError("no list of objects")
            df = pd.DataFrame(rows)
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{p.name}: cannot read it ({exc})") from None
    except (ValueError, KeyError, TypeError, IndexError, pd.errors.ParserError) as exc:
        raise ValueError(f"{p.name}: not an objects table from holoradar detect -o "
                         f"({type(exc).__name__}: {exc})") from None
    missing = [c for c in _NEEDED if c not in df.columns] if len(df) else []
    if missing:
        raise ValueError(f"{p.name}: not an objects table from holoradar detect -o: no "
                         f"column {', '.join(missing)}")
    for c in df.columns:
        if c not in ("kind", "frame"):
            df[c] = pd.to_numeric(df[c], errors="coerce")
    df.attrs["outlines"] = outlines
    return df


def outline_of(row: Any, outline: Any = None) -> list[tuple[float, float]]:
    """An area's outline (metres): the one found, or the rectangle of its length, width
    and azimuth about its centre (as ``holoradar detect``'s GeoJSON draws it)."""
    if outline:
        return [(float(u), float(v)) for u, v in outline]
    length, width = _num(row.get("length"), 0.0), _num(row.get("width"), 0.0)
    az = math.radians(_num(row.get("azimuth_deg"), 0.0))
    u = (math.cos(az) * length / 2, math.sin(az) * length / 2)
    v = (-math.sin(az) * width / 2, math.cos(az) * width / 2)
    x, y = float(row["x"]), float(row["y"])
    return [(x + a * u[0] + b * v[0], y + a * u[1] + b * v[1])
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))]


def _num(v: Any, default: float = math.nan) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return default
    return f if math.isfinite(f) else default


def _records(df: Any) -> list[dict[str, Any]]:
    return [] if df is None else df.to_dict("records")


def overlay(df: Any) -> dict[str, dict[str, list[Any]]]:
    """The plan view's glyph data (cm): ``points`` (circles), ``lines`` (segments between
    a line's ends), ``areas`` (outlines, as patches) and ``labels`` (every object's
    number at its position); each carries the object's number ``n``."""
    outlines = (df.attrs.get("outlines") or {}) if df is not None else {}
    pts: dict[str, list[Any]] = {"x": [], "y": [], "n": []}
    lines: dict[str, list[Any]] = {"x0": [], "y0": [], "x1": [], "y1": [], "n": []}
    areas: dict[str, list[Any]] = {"xs": [], "ys": [], "n": []}
    labels: dict[str, list[Any]] = {"x": [], "y": [], "text": [], "n": []}
    for i, r in enumerate(_records(df)):
        n = i + 1
        x, y = _num(r.get("x")) * CM, _num(r.get("y")) * CM
        kind = r.get("kind")
        ends = [_num(r.get(k)) for k in ("x_start", "y_start", "x_end", "y_end")]
        if kind == "line" and all(map(math.isfinite, ends)):
            for key, v in zip(("x0", "y0", "x1", "y1"), ends, strict=True):
                lines[key].append(v * CM)
            lines["n"].append(n)
        elif kind == "area":
            ring = outline_of(r, outlines.get(i, outlines.get(str(i))))
            areas["xs"].append([u * CM for u, _ in ring])
            areas["ys"].append([v * CM for _, v in ring])
            areas["n"].append(n)
        else:
            pts["x"].append(x)
            pts["y"].append(y)
            pts["n"].append(n)
        labels["x"].append(x)
        labels["y"].append(y)
        labels["text"].append(str(n))
        labels["n"].append(n)
    return {"points": pts, "lines": lines, "areas": areas, "labels": labels}


def shown_depth(row: Any, surface: float) -> float:
    """An object's place on the page's depth axis, metres: its range less the surface's
    (the page's depth with a ground, its range without)."""
    return _num(row.get("range")) - surface


def section_marks(df: Any, surface: float, at: tuple[float, float],
                  near: float) -> tuple[dict[str, list[Any]], dict[str, list[Any]]]:
    """Markers on the x-z and y-z sections (cm): the objects within ``near`` metres of the
    section's plane (``y = at[1]``, ``x = at[0]``), by their centre (a line: its point
    nearest the plane), at their range less ``surface``."""
    xz: dict[str, list[Any]] = {"x": [], "z": [], "text": [], "n": []}
    yz: dict[str, list[Any]] = {"x": [], "z": [], "text": [], "n": []}
    for i, r in enumerate(_records(df)):
        z = shown_depth(r, surface)
        if not math.isfinite(z):
            continue
        x, y = _num(r.get("x")), _num(r.get("y"))
        ends = [_num(r.get(k)) for k in ("x_start", "y_start", "x_end", "y_end")]
        for out, across, along, axis in ((xz, 1, 0, at[1]), (yz, 0, 1, at[0])):
            pos, off = (x, y)[along], abs((x, y)[across] - axis)
            if r.get("kind") == "line" and all(map(math.isfinite, ends)):
                a, b = np.array(ends[:2]), np.array(ends[2:])
                d = b - a
                # where it crosses the section's plane (its middle if it lies along it)
                t = 0.5 if d[across] == 0 else float(np.clip((axis - a[across]) / d[across],
                                                             0.0, 1.0))
                p = a + t * d
                pos, off = float(p[along]), abs(float(p[across]) - axis)
            if off <= near:
                out["x"].append(pos * CM)
                out["z"].append(z * CM)
                out["text"].append(str(i + 1))
                out["n"].append(i + 1)
    return xz, yz


def _cm(v: float) -> str:
    return "-" if not math.isfinite(v) else f"{round(v * CM, 1) + 0.0:.1f}"


def table_rows(df: Any, surface: float) -> dict[str, list[Any]]:
    """The page's list of objects as text columns (:data:`TABLE_FIELDS`), plus ``at``: the
    depth (cm, the page's axis) the slider moves to when a row is chosen, and ``x``/``y``
    in metres as ``x_m``/``y_m`` for the sections."""
    out: dict[str, list[Any]] = {k: [] for k, _ in TABLE_FIELDS}
    out.update({"at": [], "x_m": [], "y_m": []})
    for i, r in enumerate(_records(df)):
        kind = str(r.get("kind"))
        depth = _num(r.get("depth"))
        lo, hi = _num(r.get("depth_low")), _num(r.get("depth_high"))
        z = shown_depth(r, surface)
        if not math.isfinite(depth):  # no ground in the table: the page's axis
            depth = z
        interval = f" [{_cm(lo)}, {_cm(hi)}]" if math.isfinite(lo) and math.isfinite(hi) \
            else ""
        length, width = _num(r.get("length"), 0.0), _num(r.get("width"), 0.0)
        if kind == "line":
            size = f"{_cm(length)} long"
        elif kind == "area":
            size = f"{_cm(length)} x {_cm(width)}"
        else:
            size = "-"
        snr = _num(r.get("snr_db"))
        out["n"].append(i + 1)
        out["kind"].append(kind)
        out["x"].append(_cm(_num(r.get("x"))))
        out["y"].append(_cm(_num(r.get("y"))))
        out["depth"].append(_cm(depth) + interval)
        out["size"].append(size)
        out["snr"].append("-" if not math.isfinite(snr) else f"{snr:.1f}")
        out["at"].append(z * CM if math.isfinite(z) else math.nan)
        out["x_m"].append(_num(r.get("x")))
        out["y_m"].append(_num(r.get("y")))
    return out
