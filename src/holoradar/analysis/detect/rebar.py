"""A rebar mat's summary: per layer of bars (a direction and a depth), their number,
spacing and cover."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["rebar_layers"]

LAYER_COLUMNS = ["azimuth_deg", "bars", "spacing", "spacing_mean", "spacing_min",
                 "spacing_max", "cover", "cover_mean", "cover_min", "cover_max", "cover_low",
                 "cover_high", "rows"]
"""Columns of :func:`rebar_layers`'s table, in order."""


def rebar_layers(objects: Any, *, angle_tol_deg: float = 10.0) -> Any:
    """Group the lines of a :func:`~holoradar.detect` table into layers: one row per
    layer of parallel bars (a direction, and within it a depth), as a rebar scanner
    reports a mat.

    Parameters
    ----------
    objects : pandas.DataFrame
        ``detect``'s table (rows of other kinds are ignored).
    angle_tol_deg : float
        Lines whose azimuths differ by less than this (degrees, modulo 180) are one
        direction (default 10: a mat's two directions are 90 apart, while one bar's
        azimuth is known to a fraction of a degree).

    Returns
    -------
    pandas.DataFrame
        One row per layer, most bars first (then the shallower): ``azimuth_deg`` (the
        lines' mean, degrees from +x towards +y in [0, 180)); ``bars``; ``spacing``
        (metres, the median distance between neighbouring bars across their
        direction) with ``spacing_mean``, ``spacing_min``, ``spacing_max``; ``cover``
        (metres, the bars' median depth: the depth of a bar's top, where its echo
        comes from) with ``cover_mean``, ``cover_min``, ``cover_max`` and
        ``cover_low``/``cover_high`` (the extremes of the bars' 95 % depth
        intervals); ``rows`` (the lines' row labels in ``objects``). Spacing is NaN
        for one bar, cover NaN without depths. Bars of one direction are one layer
        unless a bar lies more than :data:`LAYER_GAP` below the previous (sorted by
        depth) with its interval wholly below the layer's: it starts the next.

    Raises
    ------
    ValueError
        ``objects`` without detect's columns, or a bad ``angle_tol_deg``.

    Examples
    --------
    >>> import pandas as pd
    >>> rows = [{"kind": "line", "x": x, "y": 0.0, "azimuth_deg": 90.0, "depth": 0.06,
    ...          "depth_low": 0.055, "depth_high": 0.065} for x in (-0.15, 0.0, 0.15)]
    >>> rows += [{"kind": "line", "x": 0.0, "y": y, "azimuth_deg": 0.5, "depth": 0.04,
    ...           "depth_low": 0.036, "depth_high": 0.046} for y in (-0.075, 0.075)]
    >>> t = rebar_layers(pd.DataFrame(rows))
    >>> t.azimuth_deg.round(1).tolist(), t.bars.tolist(), t.spacing.round(3).tolist()
    ([90.0, 0.5], [3, 2], [0.15, 0.15])
    >>> t.cover.tolist(), t.cover_low.tolist(), t.cover_high.tolist()
    ([0.06, 0.04], [0.055, 0.036], [0.065, 0.046])
    """
    import pandas as pd

    need = {"kind", "x", "y", "azimuth_deg"}
    if not hasattr(objects, "columns") or not need <= set(objects.columns):
        raise ValueError("objects must be holoradar.detect's table (a DataFrame with the "
                         f"columns {sorted(need)})")
    tol = float(angle_tol_deg)
    if not 0 < tol < 90:
        raise ValueError(f"angle_tol_deg must be in (0, 90) degrees, got {angle_tol_deg!r}")
    lines = objects[objects["kind"] == "line"]
    groups: list[list[Any]] = []
    for label, az in sorted(zip(lines.index, lines["azimuth_deg"] % 180.0, strict=True),
                            key=lambda t: t[1]):
        for g in groups:
            if _angle_gap(_mean_azimuth(lines.loc[g, "azimuth_deg"]), az) < tol:
                g.append(label)
                break
        else:
            groups.append([label])
    out = [_layer(lines.loc[d]) | {"rows": list(d)} for g in groups
           for d in _by_depth(lines.loc[g])]
    out.sort(key=lambda r: (-r["bars"], r["cover"] if math.isfinite(r["cover"]) else 0.0))
    return pd.DataFrame(out, columns=LAYER_COLUMNS)


LAYER_GAP = 0.025
"""Metres: a second mat of bars in the same direction lies at least this much deeper
(its bars under the crossing bars of the first, two bar diameters of 10-16 mm); bars of
one layer differ by less (a badly placed bar by a centimetre or so, which the cover
check must show rather than call another layer)."""


def _by_depth(rows: Any) -> list[list[Any]]:
    """One direction's bars split into layers: sorted by depth, a new layer where a bar
    lies more than :data:`LAYER_GAP` below the previous one and its 95 % depth interval
    wholly below every interval of the layer so far."""
    if "depth" not in rows or not np.isfinite(rows["depth"].to_numpy(float)).any():
        return [list(rows.index)]
    order = rows.sort_values("depth", kind="stable")
    lo = order["depth_low"] if "depth_low" in order else order["depth"]
    hi = order["depth_high"] if "depth_high" in order else order["depth"]
    layers: list[list[Any]] = []
    top, last = -math.inf, -math.inf
    for label, d, a, b in zip(order.index, order["depth"], lo, hi, strict=True):
        a = d if not math.isfinite(a) else a
        b = d if not math.isfinite(b) else b
        if not layers or (math.isfinite(d) and a > top and d - last > LAYER_GAP):
            layers.append([label])
            top = -math.inf
        else:
            layers[-1].append(label)
        top = max(top, b) if math.isfinite(b) else top
        last = d if math.isfinite(d) else last
    return layers


def _angle_gap(a: float, b: float) -> float:
    return abs((a - b + 90.0) % 180.0 - 90.0)


def _mean_azimuth(az: Any) -> float:
    """Mean of axial directions (degrees modulo 180), by doubling the angles."""
    a = np.radians(2 * np.asarray(az, float))
    return float(np.degrees(np.arctan2(np.sin(a).mean(), np.cos(a).mean())) / 2 % 180.0)


def _layer(rows: Any) -> dict[str, Any]:
    az = _mean_azimuth(rows["azimuth_deg"])
    u = np.radians(az)
    across = np.sort(-rows["x"].to_numpy() * np.sin(u) + rows["y"].to_numpy() * np.cos(u))
    gaps = np.diff(across)
    depth = rows["depth"].to_numpy(float) if "depth" in rows else np.full(len(rows), np.nan)
    lo = rows["depth_low"].to_numpy(float) if "depth_low" in rows else depth
    hi = rows["depth_high"].to_numpy(float) if "depth_high" in rows else depth

    def stat(f: Any, a: np.ndarray) -> float:
        a = a[np.isfinite(a)]
        return float(f(a)) if a.size else float("nan")

    return {"azimuth_deg": az, "bars": len(rows),
            "spacing": stat(np.median, gaps), "spacing_mean": stat(np.mean, gaps),
            "spacing_min": stat(np.min, gaps), "spacing_max": stat(np.max, gaps),
            "cover": stat(np.median, depth), "cover_mean": stat(np.mean, depth),
            "cover_min": stat(np.min, depth), "cover_max": stat(np.max, depth),
            "cover_low": stat(np.min, lo), "cover_high": stat(np.max, hi)}
