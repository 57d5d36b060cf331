"""Lines: the points CLEAN strings along an elongated reflector, joined into one.

CLEAN explains a bar (rebar, a pipe, a wire) longer than the resolution cell
``c = lambda L / A`` by point responses along it: once one is subtracted, the
bar's image beside it keeps its level while the point's response falls to its
first null one cell away and through its first sidelobe by two, so the next
component lies one to two cells further along. Components are therefore joined
into a line when

- each lies within ``LINK_CELLS = 2.5`` cells (laterally) of the chain's end
  it extends (the first sidelobe's outer edge, two cells, and half a cell for the
  components' scatter) -- parallel bars a few cells apart stay apart;
- each lies within ``AXIS_CELLS = 0.5`` cell of the chain's axis (the least-squares
  line through its members): the components of a straight bar lie on its axis to
  within their position error, a small fraction of a cell above 15 dB, while a
  compact object beside it is a cell or more away;
- the chain has at least ``MIN_COMPONENTS = 3`` members spanning at least
  ``MIN_LENGTH_CELLS = 3`` cells ("well beyond the resolution cell"; two nearby
  compact objects stay two points).

A component where two bars cross (a rebar mat's crossings) may belong to both.
A line's ends are the outermost components' projections on the axis (each is
the bar's last resolved piece: within a cell of its true end), leaving out
outermost components more than ``END_DB = 13.5`` dB below the chain's median:
the image of a bar rings beyond its end at the Gibbs level (9 %, -21 dB, of its
level inside) while its last piece, half covered, stands at about -6 dB;
13.5 dB lies midway. Those components are the line's own ringing: they belong
to it (no further objects) without extending it. Its its azimuth the
axis's direction (degrees from +x towards +y in [0, 180), ``start`` the end at
the lower coordinate along it), ``width`` the spread of the components across
it (``2 sqrt(3)`` times their RMS offset, the width of a uniform strip with that
RMS; 0 for a bar below the resolution). ``spacing`` is the perpendicular
distance to the nearest parallel line that overlaps it along its length
(parallel: azimuths within twice the angle one cell subtends over the shorter
line, the uncertainty of each azimuth); NaN without one.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["group_lines", "lateral_cell", "point_components"]

END_DB = 13.5
LINK_CELLS = 2.5
AXIS_CELLS = 0.5
MIN_COMPONENTS = 3
MIN_LENGTH_CELLS = 3.0


def lateral_cell(model: Any, z: float, fallback: tuple[float, ...]) -> float:
    """The lateral resolution cell ``lambda L / A`` at range ``z`` of a detection model
    (the larger of x and y), metres; ``fallback`` (the noise's cell) without one."""
    for name in ("_cell", "cell"):
        f = getattr(model, name, None)
        if callable(f):
            try:
                c = f(z) if name == "_cell" else f()
                return float(max(c))
            except (TypeError, ValueError, AttributeError):
                pass
    widths = getattr(model, "widths", None)
    if callable(widths):
        mu, nu = widths(z)
        return float(np.pi / min(mu, nu))
    finite = [float(v) for v in fallback[:2] if np.isfinite(v)]
    return max(finite) if finite else np.nan


def point_components(rows: list[dict[str, Any]], cell: tuple[float, ...], model: Any,
                     least: int) -> tuple[list[int], np.ndarray, np.ndarray, float] | None:
    """The point rows CLEAN found, as the grouping rules take them: their indices in
    ``rows``, lateral positions (n, 2), amplitudes (dB) and the lateral cell at their
    median range; None with fewer than ``least`` points or no finite cell."""
    idx = [i for i, r in enumerate(rows) if r.get("kind") == "point"]
    if len(idx) < least:
        return None
    p = np.array([[rows[i]["x"], rows[i]["y"]] for i in idx], float)
    amp = np.array([float(rows[i].get("amplitude_db", 0.0)) for i in idx])
    c = lateral_cell(model, float(np.median([rows[i]["range"] for i in idx])), cell)
    if not np.isfinite(c) or c <= 0:
        return None
    return idx, p, amp, c


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    """z component of the cross product of two 2-D vectors (signed offset)."""
    return float(a[0] * b[1] - a[1] * b[0])


def _axis(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centre and unit direction of the least-squares line through points (n, 2)."""
    c = p.mean(axis=0)
    if len(p) < 2:
        return c, np.array([1.0, 0.0])
    _, _, vt = np.linalg.svd(p - c)
    d = vt[0]
    # Azimuth in [0, 180): y >= 0 (x > 0 on the x axis).
    if d[1] < 0 or (d[1] == 0 and d[0] < 0):
        d = -d
    return c, d


def _grow(seed: int, p: np.ndarray, cell: float) -> list[int]:
    """The chain of components through ``seed`` (module notes)."""
    members = [seed]
    link, tol = LINK_CELLS * cell, AXIS_CELLS * cell
    while True:
        c, d = _axis(p[members])
        t = (p[members] - c) @ d
        ends = [members[int(np.argmin(t))], members[int(np.argmax(t))]]
        best, best_dist = -1, np.inf
        for j in range(len(p)):
            if j in members:
                continue
            dist = min(float(np.hypot(*(p[j] - p[e]))) for e in ends)
            if dist > link:
                continue
            if len(members) >= 2:
                off = float(abs(_cross(d, p[j] - c)))
                tj = float((p[j] - c) @ d)
                if off > tol or t.min() <= tj <= t.max():
                    continue   # off the axis, or inside the chain (not extending it)
            if dist < best_dist:
                best, best_dist = j, dist
        if best < 0:
            return members
        if len(members) == 1:
            members.append(best)
            continue
        # Keep it only if the refitted axis still holds every member.
        trial = [*members, best]
        c2, d2 = _axis(p[trial])
        if max(float(abs(_cross(d2, q - c2))) for q in p[trial]) > tol:
            return members
        members = trial


def group_lines(rows: list[dict[str, Any]], cell: tuple[float, float, float],
                model: Any = None) -> list[dict[str, Any]]:
    """Join the point rows strung along elongated reflectors into line rows.

    Parameters
    ----------
    rows : list of dict
        CLEAN's objects (``kind == "point"``), strongest first.
    cell : tuple of float
        The noise's resolution cell (x, y, range), the fallback of the lateral cell.
    model : optional
        The detection model (its lateral resolution ``lambda L / A``).

    Returns
    -------
    list of dict
        Lines first (strongest first), then the points not in any line.

    Examples
    --------
    >>> pts = [{"kind": "point", "x": 0.0, "y": y, "range": 0.4, "amplitude_db": 0.0,
    ...         "snr_db": 20.0} for y in (-0.06, -0.03, 0.0, 0.03, 0.06)]
    >>> out = group_lines(pts, (0.02, 0.02, np.inf))
    >>> [r["kind"] for r in out], round(out[0]["length"], 3), round(out[0]["azimuth_deg"])
    (['line'], 0.12, 90)
    """
    found = point_components(rows, cell, model, MIN_COMPONENTS)
    if found is None:
        return rows
    idx, p, _, c = found
    used: set[int] = set()
    chains: list[list[int]] = []
    for seed in range(len(idx)):            # strongest first
        if seed in used:
            continue
        members = _grow(seed, p, c)
        if len(members) < MIN_COMPONENTS:
            continue
        cen, d = _axis(p[members])
        t = (p[members] - cen) @ d
        if float(t.max() - t.min()) < MIN_LENGTH_CELLS * c:
            continue
        if len(set(members) - used) < MIN_COMPONENTS:
            continue               # a line found already (only crossings are shared)
        chains.append(members)
        used.update(members)
    lines = []
    for ch in chains:
        ends = _core(ch, p, np.array([float(rows[idx[m]].get("amplitude_db", 0.0))
                                      for m in ch]))
        lines.append(_line_row([rows[idx[m]] for m in ch], p[ch], p[ends]))
    _spacing(lines, c)
    points = [r for k, r in enumerate(rows) if not (k in idx and idx.index(k) in used)]
    return lines + points


def _core(chain: list[int], p: np.ndarray, amp_db: np.ndarray) -> list[int]:
    """The chain less its outermost components more than END_DB below its median."""
    cen, d = _axis(p[chain])
    order = np.argsort((p[chain] - cen) @ d)
    keep = np.abs(amp_db[order] - np.median(amp_db)) <= END_DB
    keep |= amp_db[order] > np.median(amp_db)
    inside = np.flatnonzero(keep)
    if inside.size < 2:
        return list(chain)
    return [chain[i] for i in order[inside[0]:inside[-1] + 1]]


def _line_row(members: list[dict[str, Any]], p: np.ndarray, core: np.ndarray
              ) -> dict[str, Any]:
    cen, d = _axis(core)
    t = (core - cen) @ d
    a, b = cen + t.min() * d, cen + t.max() * d
    off = np.array([float(_cross(d, q - cen)) for q in core])
    n = len(members)

    def col(name: str) -> np.ndarray:
        return np.array([float(m.get(name, np.nan)) for m in members])

    def mean_std(name: str) -> float:
        s = col(name)
        return float(np.sqrt(np.nanmean(s**2) / n)) if np.any(np.isfinite(s)) else np.nan

    amp = col("amplitude_db")
    row = dict(members[int(np.nanargmax(amp))])
    row.update({
        "kind": "line", "x": float(0.5 * (a[0] + b[0])), "y": float(0.5 * (a[1] + b[1])),
        "range": float(np.mean(col("range"))), "depth": float(np.mean(col("depth"))),
        "depth_low": float(np.min(col("depth_low"))), "depth_high": float(np.max(col(
            "depth_high"))),
        "length": float(t.max() - t.min()),
        "width": float(2 * np.sqrt(3) * np.sqrt(np.mean(off**2))),
        "azimuth_deg": float(np.degrees(np.arctan2(d[1], d[0])) % 180.0),
        "x_start": float(a[0]), "y_start": float(a[1]), "x_end": float(b[0]),
        "y_end": float(b[1]),
        "amplitude_db": float(np.nanmax(amp)), "snr_db": float(np.nanmax(col("snr_db"))),
        "x_std": mean_std("x_std"), "y_std": mean_std("y_std"),
        "range_std": mean_std("range_std"),
        "model_error_db": float(np.nanmedian(col("model_error_db")))
        if np.any(np.isfinite(col("model_error_db"))) else np.nan,
        "spacing": np.nan, "components": n,
    })
    return row


def _spacing(lines: list[dict[str, Any]], cell: float) -> None:
    """Each line's perpendicular distance to the nearest parallel, overlapping line."""
    for i, li in enumerate(lines):
        ci = np.array([li["x"], li["y"]])
        di = np.array([np.cos(np.radians(li["azimuth_deg"])),
                       np.sin(np.radians(li["azimuth_deg"]))])
        best = np.nan
        for j, lj in enumerate(lines):
            if i == j:
                continue
            tol = 2 * np.degrees(np.arctan2(cell, min(li["length"], lj["length"])))
            diff = abs((li["azimuth_deg"] - lj["azimuth_deg"] + 90.0) % 180.0 - 90.0)
            if diff > tol:
                continue
            cj = np.array([lj["x"], lj["y"]])
            along = float((cj - ci) @ di)
            if abs(along) > 0.5 * (li["length"] + lj["length"]):
                continue           # parallel but end to end, not side by side
            s = float(abs(_cross(di, cj - ci)))
            if np.isnan(best) or s < best:
                best = s
        li["spacing"] = best
