"""The report's rebar part, as concrete scanners give it: per layer of parallel bars
the count, spacing and cover; the cover checked against a specified minimum; a plan
of all bars coloured by cover, with a scale bar and the table's numbers.

A layer is a direction of bars, and within it a depth
(:func:`holoradar.rebar_layers`). Cover is a bar's depth below the surface (its
top, where its echo comes from), with the 95 % interval of each bar's depth; a bar
is *below* a specified minimum cover when its depth is, and *uncertain* when its
depth is not but its interval reaches below it (the measurement cannot tell).
"""

from __future__ import annotations

import html
import math
from typing import Any

import numpy as np

__all__ = ["cover_status", "rebar_html", "rebar_plan", "summary_rows"]

_CM = 100.0


def cover_status(row: Any, min_cover: float | None) -> str:
    """``"below"``, ``"uncertain"``, ``"ok"`` (a line with a depth, against
    ``min_cover`` in metres), or ``""`` (no minimum, no depth, not a bar).

    Examples
    --------
    >>> cover_status({"kind": "line", "depth": 0.03, "depth_low": 0.028}, 0.035)
    'below'
    >>> cover_status({"kind": "line", "depth": 0.036, "depth_low": 0.033}, 0.035)
    'uncertain'
    """
    if min_cover is None or row.get("kind") != "line":
        return ""
    d = _num(row.get("depth"))
    if not math.isfinite(d):
        return ""
    lo = _num(row.get("depth_low"))
    if d < min_cover:
        return "below"
    return "uncertain" if math.isfinite(lo) and lo < min_cover else "ok"


def _num(v: Any) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _cm(v: float, digits: int = 1) -> str:
    if not math.isfinite(v):
        return "–"
    r = round(v * _CM, digits)
    return f"{r + 0.0:.{digits}f}"   # + 0.0: no "-0.0"


def _direction(az: float) -> str:
    a = round(az) % 180
    name = "along x" if a in (0, 179, 1) else "along y" if a in (89, 90, 91) else f"{a} deg"
    return f"{name} ({a} deg)"


def summary_rows(table: Any, min_cover: float | None) -> list[dict[str, Any]]:
    """One dict per layer: direction, bars, the bars' numbers in the table, spacing mean,
    min and max, cover min, mean and max with the 95 % interval's extremes, and how many
    bars lie below ``min_cover`` (and how many are uncertain)."""
    from ..analysis.detect.rebar import rebar_layers

    if len(table) == 0 or not (table["kind"] == "line").any():
        return []
    layers = rebar_layers(table)
    pos = {label: i + 1 for i, label in enumerate(table.index)}
    out = []
    for _, ly in layers.iterrows():
        rows = [table.loc[r] for r in ly["rows"]]
        status = [cover_status(r, min_cover) for r in rows]
        out.append({"direction": _direction(float(ly["azimuth_deg"])), "bars": int(ly["bars"]),
                    "numbers": sorted(pos[r] for r in ly["rows"]),
                    "spacing": (ly["spacing_mean"], ly["spacing_min"], ly["spacing_max"]),
                    "cover": (ly["cover_min"], ly["cover_mean"], ly["cover_max"]),
                    "interval": (ly["cover_low"], ly["cover_high"]),
                    "below": status.count("below"), "uncertain": status.count("uncertain")})
    return out


def rebar_html(table: Any, min_cover: float | None, key: str) -> str:
    """The layers' table and the cover check, or '' where the table holds no bar."""
    rows = summary_rows(table, min_cover)
    if not rows:
        return ""
    head = ["layer", "direction", "bars", "bar numbers", "spacing mean (cm)",
            "spacing min (cm)", "spacing max (cm)", "cover min (cm)", "cover mean (cm)",
            "cover max (cm)", "cover 95 % (cm)"]
    if min_cover is not None:
        head += [f"below {_cm(min_cover)} cm", "uncertain"]
    body = []
    for k, r in enumerate(rows, 1):
        cells = [str(k), r["direction"], str(r["bars"]),
                 ", ".join(map(str, r["numbers"])), *(_cm(float(v)) for v in r["spacing"]),
                 *(_cm(float(v)) for v in r["cover"]),
                 f"{_cm(float(r['interval'][0]))} to {_cm(float(r['interval'][1]))}"]
        if min_cover is not None:
            cells += [str(r["below"]), str(r["uncertain"])]
        cls = ' class="below"' if min_cover is not None and r["below"] else ""
        body.append(f"<tr{cls}>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells)
                    + "</tr>")
    note = ("Spacing: between neighbouring bars of a layer, across their direction (a layer "
            "of one bar has none). Cover: the bars' depths below the surface (a bar's top); "
            "the 95 % column spans the bars' depth intervals.")
    if min_cover is not None:
        note += (f" Specified minimum cover {_cm(min_cover)} cm: a bar is below it when its "
                 "depth is; uncertain when its depth is not but its 95 % interval reaches "
                 "below it. Such bars are marked in the objects' table and drawn dashed on "
                 "the plan.")
    return (f'<table class="rebar" id="{key}-rebar"><thead><tr>'
            + "".join(f"<th>{html.escape(h)}</th>" for h in head)
            + f'</tr></thead><tbody>{"".join(body)}</tbody></table>'
            f'<p class="note">{html.escape(note)}</p>')


def rebar_plan(table: Any, min_cover: float | None, title: str) -> Any:
    """A plan of every bar (and point) coloured by its cover, numbered as in the table,
    with a colour bar in cm and a scale bar; the bars below ``min_cover`` dashed in red.
    Returns a matplotlib Figure, or None where the table has no depth."""
    from matplotlib import colormaps, patheffects
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    if len(table) == 0 or "depth" not in table or \
            not np.isfinite(table["depth"].to_numpy(float)).any():
        return None
    recs = table.to_dict("records")
    xs, ys = [], []
    for r in recs:
        for a, b in (("x", "y"), ("x_start", "y_start"), ("x_end", "y_end")):
            if math.isfinite(_num(r.get(a))) and math.isfinite(_num(r.get(b))):
                xs.append(float(r[a]))
                ys.append(float(r[b]))
    span = max(np.ptp(xs), np.ptp(ys), 0.05)
    depths = table["depth"].to_numpy(float)
    depths = depths[np.isfinite(depths)]
    lo, hi = float(depths.min()) * _CM, float(depths.max()) * _CM
    if hi - lo < 0.5:
        lo, hi = lo - 0.5, hi + 0.5
    norm, cmap = Normalize(lo, hi), colormaps["viridis_r"]
    fig = Figure(figsize=(7.5, 6.2), dpi=100)
    ax = fig.add_axes((0.1, 0.1, 0.72, 0.8))
    cax = fig.add_axes((0.85, 0.1, 0.03, 0.8))
    halo = [patheffects.withStroke(linewidth=3, foreground="white")]
    # The deepest first: a shallower bar crossing it is drawn over it, as seen from above.
    order = sorted(range(len(recs)), key=lambda i: -_num(recs[i].get("depth"))
                   if math.isfinite(_num(recs[i].get("depth"))) else 0.0)
    for i in order:
        n, r = i + 1, recs[i]
        d = _num(r.get("depth"))
        colour = cmap(norm(d * _CM)) if math.isfinite(d) else "0.5"
        status = cover_status(r, min_cover)
        if r.get("kind") == "line" and all(math.isfinite(_num(r.get(k))) for k in
                                           ("x_start", "y_start", "x_end", "y_end")):
            xy = np.array([[r["x_start"], r["y_start"]], [r["x_end"], r["y_end"]]]) * _CM
            if status in ("below", "uncertain"):
                ax.plot(xy[:, 0], xy[:, 1], color="red", lw=7, alpha=0.35,
                        solid_capstyle="round", ls="-" if status == "below" else ":")
            ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=3.5, solid_capstyle="round",
                    ls="--" if status == "below" else "-")
            # the number beyond the bar's start: clear of the bars crossing its middle
            u = (xy[0] - xy[1]) / max(float(np.hypot(*(xy[0] - xy[1]))), 1e-9)
            at, off = xy[0], 12 * u
        else:
            ax.plot(r["x"] * _CM, r["y"] * _CM, "o", ms=9, mfc=colour, mec="black")
            at, off = np.array([r["x"], r["y"]]) * _CM, np.array([6.0, 6.0])
        ax.annotate(str(n), tuple(at), xytext=tuple(off), textcoords="offset points",
                    fontsize=10, fontweight="bold", ha="center", va="center",
                    path_effects=halo, zorder=5)
    pad = 0.12 * span * _CM
    ax.set_xlim(min(xs) * _CM - pad, max(xs) * _CM + pad)
    ax.set_ylim(min(ys) * _CM - pad, max(ys) * _CM + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    ax.set_title(title, fontsize=11)
    ax.grid(True, color="0.9", lw=0.6)
    _scale_bar(ax, span)
    cb = fig.colorbar(ScalarMappable(norm, cmap), cax=cax)
    cb.set_label("cover (depth below the surface, cm)")
    cb.ax.invert_yaxis()          # shallow on top, as in the section through a slab
    if min_cover is not None and lo <= min_cover * _CM <= hi:
        cb.ax.axhline(min_cover * _CM, color="red", lw=2)
    return fig


def _scale_bar(ax: Any, span: float) -> None:
    """A bar of a round length (about a fifth of the view) in the lower left corner."""
    target = span * _CM / 5
    length = max(v for v in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000) if v <= max(target, 1))
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    x, y = x0 + 0.05 * (x1 - x0), y0 + 0.05 * (y1 - y0)
    ax.plot([x, x + length], [y, y], color="black", lw=4, solid_capstyle="butt")
    ax.text(x + length / 2, y + 0.015 * (y1 - y0), f"{length} cm", ha="center",
            va="bottom", fontsize=10, fontweight="bold")
