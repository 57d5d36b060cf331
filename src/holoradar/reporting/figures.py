"""The report's pictures: plan views at the objects' depths and vertical sections through
them, the objects outlined and numbered as in the table.

Each picture is ``|E|`` in dB re the brightest pixel of what it shows, over
``DB_RANGE`` dB (inferno). Objects: a point is a circle of one resolution cell
across, a line its segment from end to end, an area its outline polygon; each
carries its number (the table's row + 1) in white on a dark halo, legible on
any colour of the map. Positions are in cm on the image's axes (a survey's: world
metres of the frames' positions, in cm).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import patheffects
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from .._figures import edges as _edges
from .._figures import to_png
from .model import Section

__all__ = ["DB_RANGE", "MAX_PLANES", "Picture", "pictures"]

DB_RANGE = 30.0
"""dB shown below the brightest pixel."""
MAX_PLANES = 4
"""At most this many plan views (and sections) per source: the planes holding most objects."""
_CM = 100.0
_COLOUR = "#35e0ff"
_HALO = [patheffects.withStroke(linewidth=3, foreground="black")]


@dataclass
class Picture:
    """One embedded figure: its PNG bytes, caption and size in pixels."""

    kind: str
    caption: str
    png: bytes
    width: int
    height: int


def _db(a: np.ndarray) -> np.ndarray:
    ref = float(np.max(a)) if a.size and np.max(a) > 0 else 1.0
    return 20 * np.log10(np.maximum(a / ref, 10 ** (-DB_RANGE / 20)))


def _cell(section: Section) -> float:
    cell = section.detection.get("resolution_cell") or []
    vals = [c for c in cell[:2] if c is not None and math.isfinite(c)]
    return max(vals) if vals else 0.0


def _plane_choice(ranges: np.ndarray, amps: np.ndarray, planes: np.ndarray) -> list[int]:
    """The planes to draw: those nearest the objects' ranges, most objects first (then the
    strongest), at most MAX_PLANES, in range order; the brightest plane without objects."""
    if ranges.size == 0:
        return []
    near = [int(np.argmin(np.abs(planes - r))) for r in ranges]
    score: dict[int, tuple[int, float]] = {}
    for i, a in zip(near, amps, strict=True):
        c, best = score.get(i, (0, -np.inf))
        score[i] = (c + 1, max(best, float(a)))
    chosen = sorted(score, key=lambda i: score[i], reverse=True)[:MAX_PLANES]
    return sorted(chosen)


def _label(ax: Any, x: float, y: float, n: int, dx: float, *, left: bool = False) -> None:
    """The number beside an object: up and to the right, or to the left near the right
    edge of the view (``left``), clipped to the axes."""
    sx = -dx if left else dx
    ax.annotate(str(n), (x * _CM, y * _CM), xytext=(x * _CM + sx, y * _CM + dx),
                color="white", fontsize=11, fontweight="bold",
                ha="right" if left else "left", va="bottom", path_effects=_HALO, zorder=5,
                annotation_clip=True, clip_on=True)


def draw_objects(ax: Any, table: Any, rows: Sequence[int], cell: float, *,
                 span: float, right: float = math.inf) -> None:
    """Outline and number the rows ``rows`` of ``table`` on a plan view in cm.

    ``cell`` is the lateral resolution cell (m; a point's circle), ``span`` the
    view's width (m; sets the labels' offset), ``right`` its right edge (m): an
    object's number goes to its left within a tenth of the view from it.
    """
    outlines = table.attrs.get("outlines") or {}
    radius = (cell / 2 if cell > 0 else span / 60) * _CM
    dx = max(radius * 0.8, span * _CM / 120)
    for i in rows:
        r = table.iloc[i]
        kind = str(r["kind"])
        if kind == "area" and outlines.get(i):
            ring = np.asarray(outlines[i], dtype=float) * _CM
            ax.add_patch(Polygon(ring, closed=True, fill=False, ec=_COLOUR, lw=1.8, zorder=4))
        elif kind == "line" and all(np.isfinite(float(r.get(k, np.nan)))
                                    for k in ("x_start", "y_start", "x_end", "y_end")):
            ax.plot([r["x_start"] * _CM, r["x_end"] * _CM], [r["y_start"] * _CM,
                    r["y_end"] * _CM], color=_COLOUR, lw=2.2, solid_capstyle="round", zorder=4)
        else:
            ax.add_patch(Circle((r["x"] * _CM, r["y"] * _CM), radius, fill=False, ec=_COLOUR,
                                lw=1.8, zorder=4))
        _label(ax, float(r["x"]), float(r["y"]), i + 1, dx,
               left=float(r["x"]) > right - span / 10)


def _plan(x: np.ndarray, y: np.ndarray, amp: np.ndarray, title: str, table: Any,
          rows: Sequence[int], cell: float) -> Figure:
    """A plan view; a long strip (a survey) is cut into pieces stacked one above the other.

    The axes are placed by hand (inches), not by a layout engine: a survey's dozen
    panels would otherwise cost seconds of layout.
    """
    wx, wy = float(np.ptp(x)) or 1e-3, float(np.ptp(y)) or 1e-3
    pieces = max(1, min(12, math.ceil(wx / wy / 5)))
    edges = np.linspace(float(x[0]), float(x[-1]), pieces + 1)
    ye = _edges(y) * _CM
    dx = float(x[1] - x[0]) if x.size > 1 else wx
    span = (wx / pieces + dx) * _CM                  # one piece with its edge pixels, cm
    left, right, top, gap, bottom = 0.85, 1.45, 0.5, 0.5, 0.55  # inches
    pw = 6.8
    ph = pw * float(ye[-1] - ye[0]) / span
    if ph > 6.4:
        pw, ph = pw * 6.4 / ph, 6.4
    width = left + pw + right
    height = top + pieces * ph + (pieces - 1) * gap + bottom
    fig = Figure(figsize=(width, height))
    a = _db(amp)
    m = None
    # each object in exactly one piece: the one its x falls in
    piece = {i: min(max(int((float(table.iloc[i]["x"]) - edges[0]) / (wx / pieces)), 0),
                    pieces - 1) for i in rows}
    for k in range(pieces):
        y0 = bottom + (pieces - 1 - k) * (ph + gap)
        ax = fig.add_axes((left / width, y0 / height, pw / width, ph / height))
        sel = np.nonzero((x >= edges[k] - 1e-12) & (x <= edges[k + 1] + 1e-12))[0]
        sel = np.arange(max(sel[0] - 1, 0), min(sel[-1] + 2, x.size)) if sel.size else sel
        xe = _edges(x[sel]) * _CM
        m = ax.imshow(a[:, sel], extent=(xe[0], xe[-1], ye[0], ye[-1]), origin="lower",
                      interpolation="nearest", cmap="inferno", vmin=-DB_RANGE, vmax=0.0,
                      aspect="auto")
        inside = [i for i in rows if piece[i] == k]
        draw_objects(ax, table, inside, cell, span=span / _CM, right=(xe[0] + span) / _CM)
        ax.set_xlim(xe[0], xe[0] + span)
        ax.set_ylim(ye[0], ye[-1])
        ax.set_ylabel("y (cm)")
        if k == pieces - 1:
            ax.set_xlabel("x (cm)")
    bar_h = min(ph * pieces + gap * (pieces - 1), 4.5)
    cax = fig.add_axes(((left + pw + 0.25) / width, (height - top - bar_h) / height,
                        0.18 / width, bar_h / height))
    fig.colorbar(m, cax=cax, label=f"|E| (dB re the brightest pixel; {DB_RANGE:.0f} dB "
                                   "shown)")
    fig.suptitle(title, fontsize=11, y=1 - 0.15 / height, va="top")
    return fig


def _where(z: float, medium: Any) -> str:
    if medium is not None and medium.z_interfaces:
        return f"range {z * _CM:.1f} cm, depth {(z - medium.z_interfaces[0]) * _CM:.1f} cm " \
               "below the surface"
    return f"range {z * _CM:.1f} cm from the array"


def _section_view(img: Any, vol: np.ndarray, table: Any, rows: Sequence[int], at_y: float,
                  cell: float, medium: Any, name: str) -> Figure:
    """An x-range section of |E| at ``y = at_y``, the objects within one cell of it marked."""
    j = int(np.argmin(np.abs(img.y - at_y)))
    sec = vol[:, j, :]
    fig = Figure(figsize=(9.0, 4.2), layout="constrained")
    ax = fig.subplots()
    m = ax.pcolormesh(_edges(img.x) * _CM, _edges(img.z) * _CM, _db(sec), cmap="inferno",
                      vmin=-DB_RANGE, vmax=0.0, shading="flat")
    ax.invert_yaxis()
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("range from the array (cm)")
    if medium is not None and medium.z_interfaces:
        zs = float(medium.z_interfaces[0]) * _CM
        if img.z[0] * _CM <= zs <= img.z[-1] * _CM:
            ax.axhline(zs, color="c", lw=1, ls="--", label="ground surface")
            ax.legend(loc="lower right", fontsize=8)
        sec_ax = ax.secondary_yaxis("right", functions=(lambda v: v - zs, lambda v: v + zs))
        sec_ax.set_ylabel("depth below the surface (cm)")
    yj = float(img.y[j])
    near = [i for i in rows if abs(float(table.iloc[i]["y"]) - yj) <= max(cell, 1e-9)
            or (str(table.iloc[i]["kind"]) != "point" and _crosses(table.iloc[i], yj))]
    dx = float(np.ptp(img.x)) * _CM / 100
    for i in near:
        r = table.iloc[i]
        ax.plot(r["x"] * _CM, r["range"] * _CM, marker="o", ms=12, mfc="none", mec=_COLOUR,
                mew=1.8, zorder=4)
        ax.annotate(str(i + 1), (r["x"] * _CM, r["range"] * _CM),
                    xytext=(r["x"] * _CM + dx, r["range"] * _CM - dx), color="white",
                    fontsize=11, fontweight="bold", path_effects=_HALO, zorder=5)
    fig.colorbar(m, ax=ax, label="|E| (dB re the section's brightest pixel)")
    fig.suptitle(f"{name}: section at y = {img.y[j] * _CM:.1f} cm", fontsize=11)
    return fig


def _crosses(r: Any, y: float) -> bool:
    ys = [float(r.get(k, np.nan)) for k in ("y_start", "y_end")]
    if all(np.isfinite(ys)):
        return min(ys) <= y <= max(ys)
    return False


def _picture(kind: str, caption: str, fig: Figure) -> Picture:
    w, h = fig.get_size_inches()
    dpi = 100
    return Picture(kind, caption, to_png(fig, dpi=dpi), round(w * dpi), round(h * dpi))


def pictures(section: Section) -> list[Picture]:
    """The plan views (and, for a volume, the sections) of one source; where it holds
    bars with depths, first the rebar plan (:func:`~.rebar.rebar_plan`)."""
    from .rebar import rebar_plan

    out = []
    if len(section.table) and (section.table["kind"] == "line").any():
        fig = rebar_plan(section.table, section.min_cover, f"{section.name}: bars by cover")
        if fig is not None:
            out.append(_picture("rebar", f"{section.name}: plan of the bars coloured by "
                                         "cover", fig))
    return out + _views(section)


def _views(section: Section) -> list[Picture]:
    table = section.table
    cell = _cell(section)
    medium = section.ground.medium
    if section.kind == "survey":
        return _survey_pictures(section, cell)
    img = section.image
    planes = np.atleast_1d(np.asarray(img.z, dtype=float))
    vol = np.abs(np.asarray(img.data)).reshape((-1, planes.size, img.y.size, img.x.size))[0]
    ranges = np.asarray(table["range"], dtype=float) if len(table) else np.zeros(0)
    amps = np.asarray(table["amplitude_db"], dtype=float) if len(table) else np.zeros(0)
    chosen = _plane_choice(ranges, amps, planes) or \
        [int(np.argmax(vol.reshape(planes.size, -1).max(axis=1)))]
    # every object on the drawn plane nearest its range
    home = {i: chosen[int(np.argmin([abs(planes[c] - ranges[i]) for c in chosen]))]
            for i in range(len(table))}
    out = []
    for c in chosen:
        rows = [i for i, h in home.items() if h == c]
        title = f"{section.name}: plan view at {_where(float(planes[c]), medium)}"
        if not rows:
            title += " (no object)"
        out.append(_picture("plan", title, _plan(img.x, img.y, vol[c], title, table, rows,
                                                 cell)))
    if planes.size > 1:
        for c in chosen:
            rows = [i for i, h in home.items() if h == c]
            if not rows:
                continue
            best = max(rows, key=lambda i: float(table.iloc[i]["amplitude_db"]))
            fig = _section_view(img, vol, table, list(range(len(table))),
                                float(table.iloc[best]["y"]), cell, medium, section.name)
            out.append(_picture("section", f"{section.name}: vertical section through object "
                                           f"{best + 1}", fig))
    return out


def _survey_pictures(section: Section, cell: float) -> list[Picture]:
    from ..survey.mosaic import mosaic
    from ..survey.store import read_index

    table = section.table
    planes = np.asarray(read_index(Path(section.store))["z"], dtype=float)
    ranges = np.asarray(table["range"], dtype=float) if len(table) else np.zeros(0)
    amps = np.asarray(table["amplitude_db"], dtype=float) if len(table) else np.zeros(0)
    chosen = _plane_choice(ranges, amps, planes) or [0]
    home = {i: chosen[int(np.argmin([abs(planes[c] - ranges[i]) for c in chosen]))]
            for i in range(len(table))}
    out = []
    for c in chosen:
        m = mosaic(section.store, float(planes[c]))
        rows = [i for i, h in home.items() if h == c]
        title = f"{section.name}: mosaic at {float(planes[c]) * _CM:.1f} cm from the arrays " \
                "(survey coordinates)"
        out.append(_picture("plan", title, _plan(np.asarray(m.x), np.asarray(m.y),
                                                 np.abs(np.asarray(m.data)), title, table,
                                                 rows, cell)))
    return out
