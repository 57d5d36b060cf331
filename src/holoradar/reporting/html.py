"""The report's page: one HTML document holding everything, pictures as base64 PNG.

No script, no external style sheet, font or picture: the page is the same offline,
archived or mailed. Every text from a file (names, history, warnings) is escaped.
"""

from __future__ import annotations

import base64
import html
import json
import math
from collections.abc import Sequence
from typing import Any

from .figures import Picture
from .model import Ground, Section
from .rebar import rebar_html
from .table import objects_table

__all__ = ["page"]

_CM = 100.0
_STYLE = """
body { font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
       margin: 0 auto; max-width: 1180px; padding: 0 24px 48px; color: #1b1f24; }
h1 { font-size: 26px; margin: 24px 0 4px; }
h2 { font-size: 21px; border-bottom: 2px solid #d0d7de; padding-bottom: 4px; margin-top: 36px; }
h3 { font-size: 16px; margin: 22px 0 8px; }
.meta { color: #57606a; margin: 0 0 8px; }
table { border-collapse: collapse; margin: 6px 0 12px; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #d0d7de; padding: 3px 8px; }
th { background: #f3f5f7; font-weight: 600; font-size: 13px; }
table.objects td { text-align: right; }
table.objects td[data-col="kind"], table.objects td[data-col="frame"] { text-align: left; }
table.facts th { text-align: left; width: 210px; vertical-align: top; }
figure { margin: 12px 0 20px; }
figure img { max-width: 100%; height: auto; border: 1px solid #d0d7de; }
figcaption { color: #57606a; font-size: 13px; }
ol.history li { margin-bottom: 6px; }
pre { background: #f6f8fa; padding: 8px; overflow-x: auto; font-size: 12px;
      white-space: pre-wrap; }
ul.warnings li { color: #9a6700; }
tr.below td { background: #ffebe9; }
table.rebar td { text-align: right; }
.none { color: #57606a; font-style: italic; }
p.note { color: #57606a; font-size: 13px; margin: 2px 0; }
"""


def _e(text: Any) -> str:
    return html.escape(str(text))


def _facts(rows: Sequence[tuple[str, str]]) -> str:
    body = "".join(f"<tr><th>{_e(k)}</th><td>{_e(v)}</td></tr>" for k, v in rows)
    return f'<table class="facts">{body}</table>'


def _eps(e: complex) -> str:
    e = complex(e)
    return f"{e.real:.4g}" + (f" + {e.imag:.3g}j" if e.imag else "")


def ground_rows(g: Ground, intervals: bool = True) -> list[tuple[str, str]]:
    """The ground as (label, value) rows: its layers' permittivities and ranges, how it was
    found, and the permittivity interval (``intervals``: whether any depth has an
    interval it could widen).

    Examples
    --------
    >>> import holoradar as hr
    >>> rows = dict(ground_rows(Ground(hr.Medium.half_space(0.3, 2.5 + 0.01j), "given")))
    >>> rows["surface"], rows["eps below"]
    ('at range 30.0 cm from the array', '2.5 + 0.01j')
    """
    m = g.medium
    rows: list[tuple[str, str]] = []
    if m is None or not m.z_interfaces:
        rows.append(("ground", "free space (no surface): positions are ranges from the array"))
    else:
        zi = [float(v) for v in m.z_interfaces]
        rows.append(("surface", f"at range {zi[0] * _CM:.1f} cm from the array"))
        if len(zi) == 1:
            rows.append(("eps above", _eps(m.eps[0])))
            rows.append(("eps below", _eps(m.eps[1])))
        else:
            rows.append(("eps above", _eps(m.eps[0])))
            for k, top in enumerate(zi):
                rows.append((f"layer {k + 1} (from {top * _CM:.1f} cm)",
                             "eps " + _eps(m.eps[k + 1])))
    rows.append(("how it was found", g.how))
    if g.eps_interval is not None:
        lo, hi = g.eps_interval
        rows.append(("eps' interval", f"{lo:.4g} to {hi:.4g}"
                     + (f", {g.interval_how}" if g.interval_how else "")
                     + (": widens the depths' 95 % intervals" if intervals else
                        ": no depth here has an interval to widen (each found on one plane "
                        "from the image alone, at the plane's depth)")))
    else:
        rows.append(("eps' interval", "none given: the depth intervals are the range's "
                                      "uncertainty only"))
    return rows


def _cm(v: Any) -> str:
    return "n/a" if v is None or not math.isfinite(float(v)) else f"{float(v) * _CM:.2f} cm"


def detection_rows(d: dict[str, Any], table: Any) -> list[tuple[str, str]]:
    """The detection's settings and outcome as (label, value) rows."""
    kinds = ", ".join(d.get("kinds") or [])
    counts = ", ".join(f"{int((table['kind'] == k).sum())} {k}(s)" for k in
                       ("point", "line", "area") if len(table) and (table["kind"] == k).any())
    rows = [("objects", f"{len(table)}" + (f" ({counts})" if counts else "")),
            ("false alarm", f"{d.get('false_alarm'):g} expected false objects per resolution "
                            "cell on noise"),
            ("kinds reported", kinds)]
    model = d.get("model")
    if model:
        rows.append(("model", {"hologram": "each object's exact response fitted to its "
                                           "hologram", "window": "the image's analytic point "
                                                                 "response (the image alone)",
                               "aperture": "the aperture's point response (the image alone)"}
                     .get(str(model), str(model))))
    if d.get("threshold") is not None:
        rows.append(("threshold", f"{float(d['threshold']):.3g} (|R|² over the local noise)"))
    if d.get("n_cells") is not None:
        rows.append(("resolution cells searched", f"{float(d['n_cells']):.0f}"))
    cell = d.get("resolution_cell")
    if cell:
        rows.append(("resolution cell", " x ".join(_cm(c) for c in cell[:2])
                     + (f", {_cm(cell[2])} in range" if len(cell) > 2 and cell[2] is not None
                        else ", none in range (one frequency)" if len(cell) > 2 else "")))
    if d.get("frames") is not None:
        rows.append(("frames searched", str(d["frames"])))
    return rows


def _history(steps: Sequence[dict[str, Any]]) -> str:
    if not steps:
        return '<p class="none">No processing history stored with this source.</p>'
    items = []
    for s in steps:
        head = f"<b>{_e(s.get('step', '?'))}</b>"
        bits = [f"input {_e(s['input'])}" for _ in [0] if s.get("input")]
        if s.get("time"):
            bits.append(f"at {_e(s['time'])}")
        if s.get("holoradar"):
            bits.append(f"holoradar {_e(s['holoradar'])}")
        params = s.get("parameters")
        detail = ""
        if params:
            text = json.dumps(params, indent=1, default=str)
            detail = f"<details><summary>parameters</summary><pre>{_e(text)}</pre></details>"
        items.append(f"<li>{head}{': ' + ', '.join(bits) if bits else ''}{detail}</li>")
    return f'<ol class="history">{"".join(items)}</ol>'


def _warnings(texts: Sequence[str]) -> str:
    if not texts:
        return '<p class="none">None.</p>'
    return '<ul class="warnings">' + "".join(f"<li>{_e(t)}</li>" for t in texts) + "</ul>"


def _figure(p: Picture) -> str:
    data = base64.b64encode(p.png).decode("ascii")
    return (f'<figure class="{p.kind}"><img alt="{_e(p.caption)}" width="{p.width}" '
            f'height="{p.height}" src="data:image/png;base64,{data}">'
            f"<figcaption>{_e(p.caption)}. {_LEGEND[p.kind]}</figcaption></figure>")


_LEGEND = {
    "rebar": "Every object numbered as in the table, coloured by its cover (depth below the "
             "surface; the scale bar in cm); bars below the specified minimum cover dashed "
             "over red, uncertain ones over dotted red; a point as a dot.",
    "plan": "|E| in dB re the brightest pixel. Objects outlined and numbered as in the "
            "table: a point as a circle one resolution cell across, a line from end to end, "
            "an area by its outline; each object on the plane nearest its range.",
    "section": "|E| in dB re the section's brightest pixel; the objects within one "
               "resolution cell of the section (and the lines crossing it) circled at their "
               "range and numbered as in the table.",
}


def _has_intervals(table: Any) -> bool:
    if "depth_low" not in getattr(table, "columns", ()) or not len(table):
        return True    # nothing to contradict
    return any(math.isfinite(float(v)) for v in table["depth_low"]
               if v is not None)


def section_html(k: int, s: Section, pics: Sequence[Picture]) -> str:
    """One source's part of the page (``<section id="s{k}">``)."""
    key = f"s{k}"
    plans = "".join(_figure(p) for p in pics if p.kind == "plan")
    rebar = rebar_html(s.table, s.min_cover, key)
    if rebar:
        rebar = ("<h3>Reinforcement: layers, spacing and cover</h3>" + rebar
                 + "".join(_figure(p) for p in pics if p.kind == "rebar"))
    secs = "".join(_figure(p) for p in pics if p.kind == "section")
    frame = "the survey frame (the frames’ world positions)" if s.kind == "survey" \
        else "the image’s axes"
    what = {"image": "an image", "hologram": "a hologram (imaged for the report)",
            "survey": "a survey store (objects in survey coordinates)"}[s.kind]
    return (f'<section id="{key}" data-source="{_e(s.name)}"><h2>{k}. {_e(s.name)}</h2>'
            f'<p class="meta">{what}; {len(s.table)} object(s); positions in cm on '
            f"{frame}; numbers as in <code>holoradar detect</code>.</p>"
            f"<h3>Objects</h3>{objects_table(s.table, s.name, key, s.min_cover)}{rebar}"
            f"<h3>Plan views at the objects' depths</h3>{plans}"
            + (f"<h3>Vertical sections</h3>{secs}" if secs else "")
            + f"<h3>Ground</h3>{_facts(ground_rows(s.ground, _has_intervals(s.table)))}"
            f"<h3>Detection</h3>{_facts(detection_rows(s.detection, s.table))}"
            f"<h3>Device and settings</h3>{_facts(s.device)}"
            f"<h3>Processing history</h3>{_history(s.history)}"
            f"<h3>Warnings</h3>{_warnings(s.warnings)}</section>")


def page(title: str, sections: Sequence[Section], pictures: Sequence[Sequence[Picture]],
         created: str, version: str, meta: Sequence[tuple[str, str]] = ()) -> str:
    """The whole document; ``meta`` the inspection's fields (site, element, operator,
    scan...) shown first."""
    toc = "".join(f'<li><a href="#s{k}">{_e(s.name)}</a>: {len(s.table)} object(s)</li>'
                  for k, s in enumerate(sections, 1))
    total = sum(len(s.table) for s in sections)
    body = "".join(section_html(k, s, p) for k, (s, p) in
                   enumerate(zip(sections, pictures, strict=True), 1))
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<meta name=\"generator\" content=\"holoradar {_e(version)}\">"
            f"<title>{_e(title)}</title><style>{_STYLE}</style></head><body>"
            f"<h1>{_e(title)}</h1><p class=\"meta\">{len(sections)} source(s), {total} "
            f"object(s); made by holoradar {_e(version)} at {_e(created)} (UTC). Depths are "
            "below the ground surface, ranges from the array; intervals are 95 %.</p>"
            + (f"<h3>Inspection</h3>{_facts(meta)}" if meta else "")
            + f"<ol class=\"toc\">{toc}</ol>{body}</body></html>\n")
