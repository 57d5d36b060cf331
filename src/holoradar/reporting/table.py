"""The objects' table as HTML: one row per object, numbered as ``holoradar detect``
numbers them (row ``i`` of ``hr.detect``'s table is object ``i + 1``).

Each cell shows the value in the column's unit (cm, cm^2, deg, dB) rounded to the
digits shown in :data:`COLUMNS`, and carries the exact value in ``hr.detect``'s unit
(metres, m^2, degrees, dB) as ``data-value`` (Python's ``repr`` of the float, which
reads back to the same double; ``nan`` for a missing value), so that a program can
read the table back exactly.
"""

from __future__ import annotations

import html
import math
from typing import Any

__all__ = ["COLUMNS", "MISSING", "objects_table"]

MISSING = "–"
"""What a cell shows for a value ``hr.detect`` leaves out (NaN): an en dash."""

COLUMNS: list[tuple[str, str, float, int]] = [
    ("x", "x (cm)", 100.0, 1),
    ("y", "y (cm)", 100.0, 1),
    ("range", "range (cm)", 100.0, 1),
    ("depth", "depth (cm)", 100.0, 1),
    ("depth_low", "depth 95 % low (cm)", 100.0, 1),
    ("depth_high", "depth 95 % high (cm)", 100.0, 1),
    ("length", "length (cm)", 100.0, 1),
    ("width", "width (cm)", 100.0, 1),
    ("azimuth_deg", "azimuth (deg)", 1.0, 0),
    ("area", "area (cm²)", 1e4, 0),
    ("amplitude_db", "amplitude (dB)", 1.0, 1),
    ("snr_db", "SNR (dB)", 1.0, 1),
]
"""(column of ``hr.detect``'s table, header, factor to the shown unit, decimals shown)."""


def _number(v: Any) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _cell(col: str, value: Any, factor: float, digits: int, blank: bool = False) -> str:
    """One cell; ``blank``: the value is not defined for the object (shown as
    :data:`MISSING`, kept exact in ``data-value``)."""
    v = _number(value)
    shown = math.nan if blank else v * factor
    if col == "azimuth_deg" and math.isfinite(shown):
        shown = round(shown, digits) % 180.0    # an axis: 180 deg is 0 deg
    # + 0.0 turns the -0.0 of a small negative value's rounding into 0.0
    shown = MISSING if not math.isfinite(shown) else \
        f"{round(shown, digits) + 0.0:.{digits}f}"
    return f'<td data-col="{col}" data-value="{html.escape(repr(v))}">{shown}</td>'


def objects_table(table: Any, source: str, key: str = "s1",
                  min_cover: float | None = None) -> str:
    """The table's HTML (``<table class="objects">``), or a sentence when it is empty.

    ``source`` names the source (``data-source``); ``key`` prefixes the rows' ids
    (``{key}-object-{n}``); with ``min_cover`` (m) a column checks each bar's cover
    against it (:func:`~.rebar.cover_status`). A point's length and width, and the
    azimuth of a point, are not defined and show as blank; an azimuth is shown in
    [0, 180) degrees; no value shows as ``-0``.

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame([{"kind": "point", "x": 0.1, "y": -0.02, "range": 0.42}])
    >>> text = objects_table(df, "a.nc")
    >>> '<td data-col="x" data-value="0.1">10.0</td>' in text
    True
    """
    if len(table) == 0:
        return '<p class="none">No object above the threshold.</p>'
    from .rebar import cover_status

    cols = [c for c in COLUMNS if c[0] in table.columns]
    frame = "frames" if "frames" in table.columns else "frame" if "frame" in table.columns \
        else None
    check = min_cover is not None
    head = "".join(f"<th>{html.escape(h)}</th>" for _, h, _, _ in cols)
    rows = []
    for i, rec in enumerate(table.to_dict("records")):
        point = rec.get("kind") == "point"
        cells = "".join(_cell(c, rec.get(c), f, d, point and c in ("length", "width"))
                        for c, _, f, d in cols)
        extra = f'<td data-col="frame">{html.escape(str(rec[frame]).replace(";", ", "))}' \
            "</td>" if frame else ""
        status = cover_status(rec, min_cover) if check else ""
        if check:
            extra += f'<td data-col="cover_check">{status or MISSING}</td>'
        cls = ' class="below"' if status == "below" else ""
        rows.append(f'<tr id="{key}-object-{i + 1}"{cls}><td data-col="number">'
                    f'{i + 1}</td><td data-col="kind">{html.escape(str(rec["kind"]))}</td>'
                    f"{cells}{extra}</tr>")
    more = ("<th>frames seen in</th>" if frame == "frames" else "<th>frame</th>" if frame
            else "") + (f"<th>cover ≥ {min_cover * 100:.1f} cm?</th>" if check else "")
    return (f'<table class="objects" data-source="{html.escape(source)}"><thead><tr>'
            f'<th>#</th><th>kind</th>{head}{more}</tr></thead>'
            f'<tbody>{"".join(rows)}</tbody></table>{_notes(table)}')


def _notes(table: Any) -> str:
    """What the blanks mean, where there are any."""
    notes = []
    if {"depth", "depth_low"} <= set(table.columns):
        plane = [i + 1 for i, (d, lo) in enumerate(zip(table["depth"], table["depth_low"],
                                                      strict=True))
                 if math.isfinite(_number(d)) and not math.isfinite(_number(lo))]
        if plane:
            notes.append(f"Object(s) {', '.join(map(str, plane))}: no depth interval, the "
                         "range's uncertainty not being known (an object found from the "
                         "image alone on one plane takes that plane's range; give the "
                         "hologram for a fitted range with its 95 % interval).")
    if "depth" in table.columns and not any(math.isfinite(_number(d)) for d in table["depth"]):
        notes.append("No depths: no ground with a surface was given or found; ranges are "
                     "from the array.")
    notes.append(f"{MISSING}: not defined for this kind of object (a point's length, width, "
                 "azimuth or area) or not measured.")
    return "".join(f'<p class="note">{html.escape(n)}</p>' for n in notes)
