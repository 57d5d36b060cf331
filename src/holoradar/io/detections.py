"""The objects' table written out: one line per object for the terminal, CSV, JSON
(records and metadata) or GeoJSON (RFC 7946: WGS 84 longitude and latitude, for GIS;
needs the positions' coordinate reference system).

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

__all__ = ["SUFFIXES", "geojson", "geojson_files", "medium_dict", "records", "table_lines",
           "write"]

SUFFIXES = [".csv", ".json", ".geojson"]
"""The files :func:`write` writes, by suffix."""


def records(df: Any) -> list[dict[str, Any]]:
    """The table's rows as plain JSON values (NaN and infinities as null)."""
    return [{str(k): plain(v) for k, v in row.items()} for row in df.to_dict("records")]


def geojson(df: Any, metadata: dict[str, Any], frame: str, crs: Any = None,
            points_only: bool = False) -> dict[str, Any]:
    """The objects as a GeoJSON FeatureCollection (RFC 7946: WGS 84 longitude, latitude).

    Points are ``Point``, lines ``LineString`` (their ends), areas ``Polygon``: the
    outline ``hr.detect`` found (``df.attrs["outlines"]``, keyed by row position, a
    closed ring), or without one the rectangle of their length, width and azimuth
    about the centre; with ``points_only`` every object is the ``Point`` of its
    position (one geometry type for a table of several kinds). The table's ``x``, ``y``
    are easting and northing in metres in ``crs``; the geometry is transformed to
    longitude and latitude (pyproj), the properties are the table's row (positions in
    ``crs`` metres; an area's outline there as ``outline_xy``), and the top-level
    ``crs_of_properties`` member names ``crs``.

    Parameters
    ----------
    df : pandas.DataFrame
        ``hr.detect``'s table, positions in ``crs``.
    metadata : dict
        Carried as the collection's ``metadata`` member.
    frame : str
        The positions' frame in words (a survey's, an image's axes).
    crs : str or pyproj.CRS
        The positions' projected coordinate reference system (metres).
    points_only : bool
        Every object as its position's ``Point``.

    Raises
    ------
    ValueError
        No ``crs`` (GeoJSON has no other coordinate system than longitude and
        latitude), or one that is not a projected CRS in metres.

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame([{"kind": "point", "x": 500000.0, "y": 0.0}])
    >>> g = geojson(df, {}, "survey", "EPSG:32633")["features"][0]["geometry"]
    >>> g["type"], [round(v, 9) for v in g["coordinates"]]
    ('Point', [15.0, 0.0])
    """
    from .crs import as_crs, check_area_of_use, crs_name, to_lonlat

    if crs is None:
        raise ValueError("GeoJSON (RFC 7946) holds WGS 84 longitude and latitude, and the "
                         "positions' coordinate reference system is not known: give it "
                         "(--crs EPSG:..., the projected CRS of the frames' positions), or "
                         "write .csv or .json (metres on the image's axes)")
    crs = as_crs(crs)
    if len(df):
        check_area_of_use(df["x"].to_numpy(float), df["y"].to_numpy(float), crs,
                          "the objects' positions")
    features = []
    outlines = df.attrs.get("outlines") or {}
    for n, row in enumerate(records(df)):
        kind = row.get("kind")
        ends = [row.get(k) for k in ("x_start", "y_start", "x_end", "y_end")]
        ring = None
        if kind == "area" and outlines.get(n):
            ring = [[float(u), float(v)] for u, v in outlines[n]]
            if ring[0] != ring[-1]:
                ring.append(list(ring[0]))
        elif kind == "area":
            length, width = row.get("length") or 0.0, row.get("width") or 0.0
            az = math.radians(row.get("azimuth_deg") or 0.0)
            u = (math.cos(az) * length / 2, math.sin(az) * length / 2)
            v = (-math.sin(az) * width / 2, math.cos(az) * width / 2)
            ring = [[row["x"] + a * u[0] + b * v[0], row["y"] + a * u[1] + b * v[1]]
                    for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))]
        if ring is not None:
            row["outline_xy"] = ring
        if points_only:
            kind_of, xy = "Point", [[row["x"], row["y"]]]
        elif kind == "line" and all(v is not None for v in ends):
            kind_of, xy = "LineString", [ends[:2], ends[2:]]
        elif ring is not None:
            kind_of, xy = "Polygon", ring
        else:
            kind_of, xy = "Point", [[row["x"], row["y"]]]
        lon, lat = to_lonlat([p[0] for p in xy], [p[1] for p in xy], crs)
        coords = [[float(a), float(b)] for a, b in zip(lon, lat, strict=True)]
        geom = {"type": kind_of, "coordinates": coords[0] if kind_of == "Point" else
                coords if kind_of == "LineString" else [coords]}
        features.append({"type": "Feature", "id": n + 1, "geometry": geom, "properties": row})
    return {"type": "FeatureCollection", "crs_of_properties": {
                "crs": crs_name(crs), "frame": frame, "units": "m",
                "note": "the geometry is WGS 84 longitude and latitude (RFC 7946); the "
                        "properties' x, y (and line ends, outlines) are easting and northing "
                        "in this CRS; depths and ranges are in the properties"},
            "metadata": metadata, "features": features}


def geojson_files(out: Path, df: Any) -> dict[Path, Any]:
    """The GeoJSON files ``-o OUT.geojson`` writes, one geometry type each: ``OUT`` alone
    for a table of one kind; for several, ``OUT`` with every object as the point of its
    position, and ``OUT_points``, ``OUT_lines``, ``OUT_areas`` (each kind's own
    geometry). Values: the rows each holds (None: every row, as points)."""
    kinds = [k for k in ("point", "line", "area") if len(df) and (df["kind"] == k).any()]
    if len(kinds) <= 1:
        return {out: df.index}
    files: dict[Path, Any] = {out: None}
    for k in kinds:
        files[out.with_name(f"{out.stem}_{k}s{out.suffix}")] = df.index[df["kind"] == k]
    return files


def write(out: Path, df: Any, metadata: dict[str, Any], frame: str, crs: Any = None,
          overwrite: bool = True) -> list[Path]:
    """Write the table to ``out`` in the format its suffix names (:data:`SUFFIXES`;
    anything else is JSON), atomically: ``metadata`` goes with JSON and GeoJSON,
    ``frame`` (the coordinates' frame, in words) and ``crs`` with GeoJSON, whose
    table of several kinds is several files (:func:`geojson_files`; refused before
    any is written where one exists and ``overwrite`` is False). Returns the files
    written."""
    from .output import check_output, write_atomic

    suffix = out.suffix.lower()
    if suffix == ".csv":
        write_atomic(out, df.to_csv(index=False).encode())
        return [out]
    if suffix != ".geojson":
        write_atomic(out, json.dumps({"metadata": metadata, "objects": records(df)},
                                     indent=1, allow_nan=False).encode())
        return [out]
    files = geojson_files(out, df)
    payloads = {}
    for path, rows in files.items():
        if path != out:
            check_output(path, suffixes=[".geojson"], overwrite=overwrite, name="--out")
        part = df if rows is None else df.loc[rows]
        if rows is not None and part is not df:
            outlines = df.attrs.get("outlines") or {}
            pos = [df.index.get_loc(i) for i in rows]
            part = part.reset_index(drop=True)
            part.attrs = {**df.attrs, "outlines": {j: outlines[p] for j, p in enumerate(pos)
                                                   if p in outlines}}
        payloads[path] = json.dumps(geojson(part, metadata, frame, crs,
                                            points_only=rows is None),
                                    indent=1, allow_nan=False).encode()
    for path, payload in payloads.items():
        write_atomic(path, payload)
    return list(payloads)


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
                size += f" at {round(r['azimuth_deg']) % 180:.0f} deg"   # an axis: 180 is 0
        frame = f"  ({r['frames'].replace(';', ', ')})" if isinstance(r.get("frames"), str) \
            else f"  ({r['frame']})" if "frame" in r else ""
        # + 0.0: a small negative value rounds to 0.0, not -0.0
        x, y = (round(r[k] * 100, 1) + 0.0 for k in ("x", "y"))
        lines.append(f"{n + 1:>3}  {r['kind']:<6} {x:>7.1f} {y:>7.1f}  "
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
