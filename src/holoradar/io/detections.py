"""The objects' table written out: one line per object for the terminal, CSV, JSON
(records and metadata) or GeoJSON (a FeatureCollection in local metres, for GIS).

The table is :func:`holoradar.detect`'s (a survey's also has ``frame``); what
``holoradar detect`` prints and writes with ``-o``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from .plain import plain

__all__ = ["SUFFIXES", "geojson", "medium_dict", "records", "table_lines", "write"]

SUFFIXES = [".csv", ".json", ".geojson"]
"""The files :func:`write` writes, by suffix."""


def records(df: Any) -> list[dict[str, Any]]:
    """The table's rows as plain JSON values (NaN and infinities as null)."""
    return [{str(k): plain(v) for k, v in row.items()} for row in df.to_dict("records")]


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
    for n, row in enumerate(records(df)):
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


def write(out: Path, df: Any, metadata: dict[str, Any], frame: str) -> None:
    """Write the table to ``out`` in the format its suffix names (:data:`SUFFIXES`;
    anything else is JSON), atomically: ``metadata`` goes with JSON and GeoJSON,
    ``frame`` (the coordinates' frame, in words) with GeoJSON."""
    from .output import write_atomic

    suffix = out.suffix.lower()
    if suffix == ".csv":
        payload = df.to_csv(index=False).encode()
    elif suffix == ".geojson":
        payload = json.dumps(geojson(df, metadata, frame), indent=1, allow_nan=False).encode()
    else:
        payload = json.dumps({"metadata": metadata, "objects": records(df)}, indent=1,
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


def medium_dict(medium: Any) -> Any:
    """A ground as plain JSON: its interfaces (m) and permittivities (``re``, ``im``);
    None for free space."""
    if medium is None:
        return None
    return {"z_interfaces_m": [float(v) for v in medium.z_interfaces],
            "eps": [{"re": float(complex(e).real), "im": float(complex(e).imag)}
                    for e in medium.eps]}
