"""One row per object of a survey: the frames' rows of one object joined.

Overlapping frames see the same object, each the part under its array. Rows of one
kind from different frames are one object when

* points: they lie within a lateral resolution cell of each other;
* areas: within a cell, or half the narrower's width;
* lines: they are parallel (azimuths within twice the angle a cell subtends over
  the shorter), within a cell of each other across, and their extents along the
  axis overlap or leave a gap shorter than two cells (each frame loses up to a cell
  at its edge);
* a point and a line: the point lies within a cell across the line's axis and
  within two cells beyond its ends (a frame that holds only a few cells of a bar,
  or its end, sees it as points).

Rows whose depths cannot be one object (95 % intervals apart, or ranges more than
a cell apart without intervals) are never joined: a bar over another is two. The
groups are closed under that relation (a pipe crossing seven frames is one chain),
but two rows one frame told apart are never put in one group (only a point on a
line may join a group its frame is in: a piece of that bar). A group is kept as the
row of the frame it lies nearest the centre of (its
fit there is the best: the whole aperture around it; a line's if the group has
one), except that a line's extent becomes the group's: its ends are the extreme
ends of all its rows projected on the axis of the longest line (a point counting
as both ends), its position their midpoint, across the axis the lines'
length-weighted mean offset. A point on a joined line (within a cell across its
axis and of its extent) is a piece of that line seen at a frame's edge and is
dropped. Each row names the frames its object was seen in (``frames``, separated by
``;``) and lines get their spacing again (to the nearest parallel line across the
whole survey).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["merge"]

_HELPERS = ["_off", "_cell"]


def merge(df: Any) -> Any:
    """The frames' rows of each object joined into one (module notes).

    Parameters
    ----------
    df : pandas.DataFrame
        The frames' tables concatenated: ``hr.detect``'s columns in survey
        coordinates, ``frame`` (its name), ``_off`` (the row's distance from its frame's
        centre, m) and ``_cell`` (its frame's lateral resolution cell, m).

    Returns
    -------
    pandas.DataFrame
        One row per object, strongest first, with ``frames``; the helper columns
        dropped.

    Examples
    --------
    >>> import pandas as pd
    >>> def line(frame, x0, x1, off):
    ...     return {"kind": "line", "x": (x0 + x1) / 2, "y": 0.0, "x_start": x0,
    ...             "y_start": 0.0, "x_end": x1, "y_end": 0.0, "length": x1 - x0,
    ...             "azimuth_deg": 0.0, "amplitude_db": -10.0, "snr_db": 30.0,
    ...             "frame": frame, "_off": off, "_cell": 0.02}
    >>> t = merge(pd.DataFrame([line("a", -0.3, -0.05, 0.1), line("b", -0.1, 0.15, 0.0),
    ...                         line("c", 0.1, 0.3, 0.1)]))
    >>> len(t), round(float(t.length[0]), 3), t.frames[0]
    (1, 0.6, 'a;b;c')
    """
    import pandas as pd

    if df.empty:
        out = df.drop(columns=[c for c in _HELPERS if c in df])
        if "spacing" not in out:
            out["spacing"] = pd.Series(dtype=float)
        out["frames"] = pd.Series(dtype=object)
        return out
    rows = df.reset_index(drop=True)
    groups = _groups(rows)
    order = {f: i for i, f in enumerate(dict.fromkeys(rows["frame"]))}
    kept = []
    for members in groups:
        sub = rows.loc[members]
        lines = sub[sub["kind"] == "line"]
        best = (lines if len(lines) else sub).sort_values("_off", kind="stable").iloc[0]
        best = best.to_dict()
        if len(lines) and len(members) > 1:
            best.update(_joined_line(lines, sub[sub["kind"] == "point"]))
        best["amplitude_db"] = float(sub["amplitude_db"].max())
        best["snr_db"] = float(sub["snr_db"].max())
        best["frames"] = ";".join(sorted(set(sub["frame"]), key=order.__getitem__))
        kept.append(best)
    kept = _without_pieces(kept)
    _spacing(kept)
    cols = [*rows.columns, *(["spacing"] if "spacing" not in rows else []), "frames"]
    out = pd.DataFrame(kept, columns=cols)
    out = out.sort_values("amplitude_db", ascending=False, kind="stable")
    return out.drop(columns=_HELPERS).reset_index(drop=True)


def _groups(rows: Any) -> list[list[int]]:
    """The rows joined into objects: a union of every pair that :func:`_same` joins."""
    parent = list(range(len(rows)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    recs = rows.to_dict("records")
    frames = [{r["frame"]} for r in recs]     # the frames in each root's group
    for i in range(len(recs)):
        for j in range(i + 1, len(recs)):
            if recs[i]["frame"] == recs[j]["frame"] or not _same(recs[i], recs[j]):
                continue
            a, b = find(i), find(j)
            # Two objects one frame told apart stay apart, whatever joins them: only a
            # point on a line may join a group its frame is in (a piece of that bar).
            piece = {recs[i]["kind"], recs[j]["kind"]} == {"point", "line"}
            if a != b and (piece or not frames[a] & frames[b]):
                parent[a] = b
                frames[b] |= frames[a]
    out: dict[int, list[int]] = {}
    for i in range(len(recs)):
        out.setdefault(find(i), []).append(i)
    return list(out.values())


def _same(a: dict[str, Any], b: dict[str, Any]) -> bool:
    if not _same_depth(a, b):
        return False
    cell = max(float(a["_cell"]), float(b["_cell"]))
    if {a["kind"], b["kind"]} == {"point", "line"}:
        p, ln = (a, b) if a["kind"] == "point" else (b, a)
        return _on_line(p, ln, reach=2 * cell)
    if a["kind"] != b["kind"]:
        return False
    d = math.hypot(a["x"] - b["x"], a["y"] - b["y"])
    if a["kind"] == "point":
        return d < cell
    if a["kind"] == "area":
        return d < max(cell, 0.5 * min(_num(a.get("width")), _num(b.get("width"))))
    shorter = max(min(a["length"], b["length"]), cell)
    daz = abs((a["azimuth_deg"] - b["azimuth_deg"] + 90.0) % 180.0 - 90.0)
    if not daz < 2 * math.degrees(math.atan2(cell, shorter)):
        return False
    u = math.radians(a["azimuth_deg"])
    dx, dy = b["x"] - a["x"], b["y"] - a["y"]
    across = abs(-dx * math.sin(u) + dy * math.cos(u))
    along = abs(dx * math.cos(u) + dy * math.sin(u))
    return across < cell and along - 0.5 * (a["length"] + b["length"]) < 2 * cell


def _same_depth(a: dict[str, Any], b: dict[str, Any]) -> bool:
    """Whether two rows can be one object in depth: their 95 % depth intervals overlap
    where both have one; else their ranges lie within a lateral cell (a plane's rows,
    a one-frequency fit)."""
    lo = (_num(a.get("depth_low"), math.nan), _num(b.get("depth_low"), math.nan))
    hi = (_num(a.get("depth_high"), math.nan), _num(b.get("depth_high"), math.nan))
    if all(math.isfinite(v) for v in (*lo, *hi)):
        return lo[0] <= hi[1] and lo[1] <= hi[0]
    ra, rb = _num(a.get("range"), math.nan), _num(b.get("range"), math.nan)
    if math.isfinite(ra) and math.isfinite(rb):
        return abs(ra - rb) <= max(float(a["_cell"]), float(b["_cell"]))
    return True


def _num(v: Any, default: float = 0.0) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return default
    return f if math.isfinite(f) else default


def _joined_line(sub: Any, points: Any) -> dict[str, float]:
    """A group of lines (and the points on them) as one line: its axis the longest
    line's, its ends the extreme ends of all rows along it (a point's position counts
    as both its ends), across the axis the lines' length-weighted mean offset."""
    longest = sub.loc[sub["length"].idxmax()]
    az = float(longest["azimuth_deg"])
    u = np.array([math.cos(math.radians(az)), math.sin(math.radians(az))])
    n = np.array([-u[1], u[0]])
    p0 = np.array([float(longest["x"]), float(longest["y"])])
    ends = np.concatenate([sub[["x_start", "y_start"]].to_numpy(float),
                           sub[["x_end", "y_end"]].to_numpy(float),
                           points[["x", "y"]].to_numpy(float)]) - p0
    t = ends @ u
    centres = sub[["x", "y"]].to_numpy(float) - p0
    w = np.maximum(sub["length"].to_numpy(float), 1e-9)
    s = float(np.sum(w * (centres @ n)) / np.sum(w))
    a = p0 + s * n + float(t.min()) * u
    b = p0 + s * n + float(t.max()) * u
    mid = 0.5 * (a + b)
    return {"x": float(mid[0]), "y": float(mid[1]), "x_start": float(a[0]),
            "y_start": float(a[1]), "x_end": float(b[0]), "y_end": float(b[1]),
            "length": float(t.max() - t.min()), "azimuth_deg": az % 180.0}


def _without_pieces(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The points that lie on a line seen in several frames dropped (module notes)."""
    lines = [r for r in rows if r["kind"] == "line" and ";" in r["frames"]]
    out = []
    for r in rows:
        if r["kind"] == "point" and any(_on_line(r, ln) and _same_depth(r, ln)
                                        for ln in lines):
            continue
        out.append(r)
    return out


def _on_line(p: dict[str, Any], line: dict[str, Any], reach: float | None = None) -> bool:
    """Whether a point lies within a cell across a line's axis and within ``reach``
    (default a cell) beyond its ends."""
    cell = max(float(p["_cell"]), float(line["_cell"]))
    u = math.radians(line["azimuth_deg"])
    dx, dy = p["x"] - line["x"], p["y"] - line["y"]
    across = abs(-dx * math.sin(u) + dy * math.cos(u))
    along = abs(dx * math.cos(u) + dy * math.sin(u))
    return across < cell and along < 0.5 * line["length"] + (cell if reach is None else reach)


def _spacing(rows: list[dict[str, Any]]) -> None:
    """Each line's distance across it to the nearest parallel line (within 15 degrees)
    beside it (their extents overlapping along the axis: bars end to end have none)."""
    lines = [r for r in rows if r["kind"] == "line"]
    for a in lines:
        t = math.radians(a["azimuth_deg"])
        gaps = []
        for b in lines:
            if b is a or abs((a["azimuth_deg"] - b["azimuth_deg"] + 90.0) % 180.0
                             - 90.0) > 15.0:
                continue
            dx, dy = b["x"] - a["x"], b["y"] - a["y"]
            if abs(dx * math.cos(t) + dy * math.sin(t)) > 0.5 * (a["length"] + b["length"]):
                continue
            gaps.append(abs(-dx * math.sin(t) + dy * math.cos(t)))
        a["spacing"] = min(gaps) if gaps else np.nan
