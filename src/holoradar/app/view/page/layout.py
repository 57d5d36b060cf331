"""The page's layout: its widths, the loading text, and the rows and columns that hold the
controls and the figures.

:func:`assemble` puts a :class:`~holoradar.app.view.page.ViewerPage`'s widgets and figures
(made by its controls and figures) in the tab's document; the widths here are shared by
the controls and the figures that take them.
"""

from __future__ import annotations

from typing import Any

__all__ = ["CONTROLS_WIDTH", "LOADING_TEXT", "PAGE_TEMPLATE", "PLAN_MAX_WIDTH",
           "PLAN_MIN_WIDTH", "SECTION_WIDTH", "assemble"]

# The page's widths (px). The controls keep theirs; the plan view, its readouts and the
# hologram row share what the window leaves beside them. At the smallest the controls,
# the plan view and the sections take 300 + 360 + 300 px (+ margins): a 1000 px wide
# window shows them all side by side; a wider one gives the plan view up to 700 px.
CONTROLS_WIDTH = 300
PLAN_MIN_WIDTH = 360
PLAN_MAX_WIDTH = 700
SECTION_WIDTH = 300

LOADING_TEXT = "loading the holoradar viewer..."
# The served page itself says it is loading: Bokeh builds the page in the browser from
# the document sent over the websocket, and until then a page without this (a plain
# `chromium --headless --screenshot`, a slow first sweep) is blank. The text goes once
# the document has been drawn (Bokeh's DocumentReady event, below).
PAGE_TEMPLATE = f"""
{{% block contents %}}
<div id="holoradar-loading" style="font: 16px sans-serif; color: #555; padding: 2em;">
  {LOADING_TEXT}
  <noscript>(the viewer needs JavaScript)</noscript>
</div>
{{{{ super() }}}}
{{% endblock %}}
"""
_DROP_LOADING = "const el = document.getElementById('holoradar-loading'); if (el) el.remove();"


def assemble(page: Any) -> None:
    """Lay out ``page``'s controls and figures and make them its document.

    Parameters
    ----------
    page : ViewerPage
        A page whose widgets and figures have been built.
    """
    from bokeh.models import CustomJS

    holo = page.session.kind == "holograms"
    layout = _row_of(page, holo)
    if not holo:
        # Without holograms there is nothing for these to change.
        for w in (page.ground_kind, page.surface, page.eps_re, page.eps_im, page.glare,
                  page.direct, page.which, page.mode, page.freq, page.frame,
                  page.holo_view):
            w.disabled = True
    doc = page.doc
    doc.add_root(layout)
    doc.template = PAGE_TEMPLATE
    doc.js_on_event("document_ready", CustomJS(code=_DROP_LOADING))
    doc.title = f"holoradar view: {', '.join(p.name for p in page.session.paths)}"


def _controls(page: Any) -> Any:
    """The column of controls, at its fixed width (see ``CONTROLS_WIDTH``)."""
    from bokeh.layouts import column, row
    from bokeh.models import Div

    buttons = page._export_buttons
    return column(
        page.info, page.status, page.depth, row(page.sweep_a, page.sweep_b),
        row(page.ground_kind, page.surface), row(page.eps_re, page.eps_im),
        page.glare, page.direct, page.glare_report, page.which,
        Div(text="<b>views</b>"), page.views, row(page.mode, page.freq), page.frame,
        row(page.scale, page.db_range), page.click, page._clear_button,
        row(page.find, page.objects_note), row(*buttons[:2]),
        buttons[2], page.exported, width=CONTROLS_WIDTH)


def _row_of(page: Any, holo: bool) -> Any:
    """The whole page: the controls, then the figures stretched to the window."""
    from bokeh.layouts import column, row

    controls = _controls(page)
    readouts = column(page.readout, page.ruler, page.obj_table,
                      sizing_mode="stretch_width")
    # The hologram row only where holograms were opened (an image has none).
    holo_row = row(column(page.holo_view, page.hfigs[0], sizing_mode="stretch_width",
                          max_width=320),
                   page.hfigs[1], page.hfigs[2], visible=holo, sizing_mode="stretch_width",
                   max_width=PLAN_MAX_WIDTH + SECTION_WIDTH)
    # A survey's mosaic is one plane at a time: no sections.
    plots = [column(page.fig, readouts, sizing_mode="stretch_width",
                    max_width=PLAN_MAX_WIDTH)] + (
        [column(page.xz, page.yz, width=SECTION_WIDTH)] if page.session.kind != "survey"
        else [])
    # Fixed controls, the rest stretched to the window (see CONTROLS_WIDTH).
    return row(controls, column(row(*plots, sizing_mode="stretch_width"), holo_row,
                                sizing_mode="stretch_width"),
               sizing_mode="stretch_width", name="layout")
