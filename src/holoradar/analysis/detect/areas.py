"""Areas: the points CLEAN spreads over a planar reflector or a void, joined into one.

A plate, a slab's edge or an air pocket wider than the resolution cell
``c = lambda L / A`` images as a filled region (its reflectivity blurred by the
point response); CLEAN explains it by point responses one to two cells apart
over its whole extent. Components are joined into an area when

- they are linked, each within ``LINK_CELLS`` (2.5, as for lines) cells of
  another (single linkage);
- the group has at least ``MIN_COMPONENTS = 4`` members and is at least
  ``MIN_WIDTH_CELLS = 2`` cells wide across its principal axis (``2 sqrt(3)``
  times the RMS offset from it: a bar's components lie on its axis);
- they fill their outline: discs of ``LINK_CELLS / 2`` cells around them cover at
  least ``COVER = pi/4`` of it. A filled region's components are at most
  ``LINK_CELLS`` apart, and discs of half that spacing around a square lattice
  cover ``pi/4`` of the plane; a rebar mat's bars ``S`` apart cover
  ``1 - (1 - LINK_CELLS c / S)^2`` of theirs (0.66 for bars six cells apart).

The outline is the convex hull of the components not more than ``END_DB``
(13.5 dB, as for lines) below the group's median: the weaker ones outside are
the region's edge ringing (Gibbs, -21 dB), which belongs to it without
widening it. A row ``kind="area"`` has the outline's centroid as ``x``, ``y``,
its extent along and across its principal axis as ``length`` and ``width``
(``azimuth_deg`` the axis), its ``area`` (m^2), and the outline itself (a
closed list of ``[x, y]`` vertices, ``outline``) in the table's
``attrs["outlines"]``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .lines import END_DB, LINK_CELLS, point_components

__all__ = ["convex_hull", "group_areas", "polygon_area"]

MIN_COMPONENTS = 4
MIN_WIDTH_CELLS = 2.0
COVER = np.pi / 4


def convex_hull(p: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of points (n, 2) (Qhull, through scipy.spatial),
    starting at the lowest-leftmost vertex; fewer than three distinct points, or points
    on one line, are returned as they are (sorted).

    Examples
    --------
    >>> convex_hull(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]])).tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    """
    from scipy.spatial import ConvexHull, QhullError

    pts = np.array(sorted({(float(a), float(b)) for a, b in np.asarray(p, float)}), float)
    if len(pts) < 3:
        return pts.reshape(-1, 2)
    try:
        v = ConvexHull(pts).vertices          # counter-clockwise in 2-D
    except QhullError:                        # all on one line: no area
        return pts
    v = np.roll(v, -int(np.argmin(v)))        # pts are sorted: the smallest index first
    return pts[v]


def polygon_area(poly: np.ndarray) -> float:
    """Area of a simple polygon (n, 2), m^2 (the shoelace formula).

    Examples
    --------
    >>> polygon_area(np.array([[0, 0], [2, 0], [2, 1], [0, 1]]))
    2.0
    """
    if len(poly) < 3:
        return 0.0
    x, y = poly[:, 0], poly[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2)


def _inside(poly: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Points q (m, 2) inside the convex counter-clockwise polygon."""
    ok = np.ones(len(q), bool)
    for a, b in zip(poly, np.roll(poly, -1, axis=0), strict=True):
        ok &= (b[0] - a[0]) * (q[:, 1] - a[1]) - (b[1] - a[1]) * (q[:, 0] - a[0]) >= 0
    return ok


def _clusters(p: np.ndarray, link: float) -> list[list[int]]:
    """Single-linkage groups of points (n, 2) within ``link`` of each other."""
    n = len(p)
    d = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1])
    seen = np.zeros(n, bool)
    out = []
    for i in range(n):
        if seen[i]:
            continue
        stack, group = [i], []
        seen[i] = True
        while stack:
            j = stack.pop()
            group.append(j)
            for k in np.flatnonzero((d[j] <= link) & ~seen):
                seen[k] = True
                stack.append(int(k))
        out.append(sorted(group))
    return out


def _coverage(poly: np.ndarray, p: np.ndarray, radius: float, step: float) -> float:
    """Share of the polygon within ``radius`` of a point of ``p``."""
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    gx = np.arange(lo[0], hi[0] + step / 2, step)
    gy = np.arange(lo[1], hi[1] + step / 2, step)
    q = np.stack(np.meshgrid(gx, gy), axis=-1).reshape(-1, 2)
    q = q[_inside(poly, q)]
    if not len(q):
        return 0.0
    d = np.min(np.hypot(q[:, None, 0] - p[None, :, 0], q[:, None, 1] - p[None, :, 1]), axis=1)
    return float(np.mean(d <= radius))


def group_areas(rows: list[dict[str, Any]], cell: tuple[float, float, float],
                model: Any = None) -> list[dict[str, Any]]:
    """Join the point rows spread over planar reflectors into area rows (notes).

    Returns the area rows (each with its ``outline``, a closed vertex list) then
    the rows not in any area.

    Examples
    --------
    >>> g = [(x, y) for x in np.arange(0, 0.1, 0.03) for y in np.arange(0, 0.07, 0.03)]
    >>> rows = [{"kind": "point", "x": x, "y": y, "range": 0.4, "amplitude_db": 0.0,
    ...          "snr_db": 20.0} for x, y in g]
    >>> out = group_areas(rows, (0.02, 0.02, np.inf))
    >>> [r["kind"] for r in out], round(out[0]["area"], 4)
    (['area'], 0.0054)
    """
    found = point_components(rows, cell, model, MIN_COMPONENTS)
    if found is None:
        return rows
    idx, p, amp, c = found
    areas, used = [], set()
    for group in _clusters(p, LINK_CELLS * c):
        if len(group) < MIN_COMPONENTS:
            continue
        core = [g for g in group if amp[g] >= np.median(amp[group]) - END_DB]
        q = p[core]
        if len(core) < MIN_COMPONENTS:
            continue
        cen = q.mean(axis=0)
        _, _, vt = np.linalg.svd(q - cen)
        across = (q - cen) @ vt[1]
        if 2 * np.sqrt(3) * np.sqrt(np.mean(across**2)) < MIN_WIDTH_CELLS * c:
            continue
        hull = convex_hull(q)
        if len(hull) < 3 or _coverage(hull, q, LINK_CELLS * c / 2, c / 4) < COVER:
            continue
        areas.append(_area_row([rows[idx[g]] for g in group], hull))
        used.update(group)
    if not areas:
        return rows
    rest = [r for k, r in enumerate(rows) if not (k in idx and idx.index(k) in used)]
    return areas + rest


def _area_row(members: list[dict[str, Any]], hull: np.ndarray) -> dict[str, Any]:
    a = polygon_area(hull)
    x, y = hull[:, 0], hull[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    cx = float(np.sum((x + np.roll(x, -1)) * cross) / (6 * a)) if a > 0 else float(x.mean())
    cy = float(np.sum((y + np.roll(y, -1)) * cross) / (6 * a)) if a > 0 else float(y.mean())
    _, _, vt = np.linalg.svd(hull - hull.mean(axis=0))
    d = vt[0] if (vt[0][1] > 0 or (vt[0][1] == 0 and vt[0][0] > 0)) else -vt[0]
    along = (hull - [cx, cy]) @ d
    across = (hull - [cx, cy]) @ np.array([-d[1], d[0]])

    def col(name: str) -> np.ndarray:
        return np.array([float(m.get(name, np.nan)) for m in members])

    amps = col("amplitude_db")
    row = dict(members[int(np.nanargmax(amps))])
    row.update({
        "kind": "area", "x": cx, "y": cy, "range": float(np.mean(col("range"))),
        "depth": float(np.mean(col("depth"))),
        "depth_low": float(np.min(col("depth_low"))),
        "depth_high": float(np.max(col("depth_high"))),
        "length": float(np.ptp(along)), "width": float(np.ptp(across)),
        "azimuth_deg": float(np.degrees(np.arctan2(d[1], d[0])) % 180.0),
        "area": a, "outline": [[float(u), float(v)] for u, v in np.vstack([hull, hull[:1]])],
        "amplitude_db": float(np.nanmax(amps)), "snr_db": float(np.nanmax(col("snr_db"))),
        "x_std": np.nan, "y_std": np.nan, "range_std": np.nan,
        "x_start": np.nan, "y_start": np.nan, "x_end": np.nan, "y_end": np.nan,
        "spacing": np.nan, "components": len(members),
        "model_error_db": float(np.nanmedian(col("model_error_db")))
        if np.any(np.isfinite(col("model_error_db"))) else np.nan,
    })
    return row
