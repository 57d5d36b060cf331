"""The viewer's page: Bokeh widgets and plots bound to a :class:`ViewSession`.

Every picture comes from the session (holoradar's imaging in this process);
the page only draws the arrays it is sent over the Bokeh websocket. A setting
that changes the data (ground, glare, views, frequency, sweep) redoes the depth
sweep behind the sections and the colour scale; the depth slider re-images one
plane. Slider events that arrive while a plane is being imaged are merged:
the next picture is for the latest depth, never a queue of stale ones.
"""

from __future__ import annotations

import html
import math
import traceback
from pathlib import Path
from typing import Any

import numpy as np

from .display import CM, db, distance, peak_of, scaled, sections
from .session import ViewSession
from .settings import GLARE_METHODS, MODES, ViewSettings

__all__ = ["ViewerPage"]

_GLARE_LABELS = {"off": "off", "gaussian": "Gaussian beam fit", "image_source": "image source",
                 "cut": "mirror-plane cut"}

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


def _edges(c: np.ndarray, unit: float = CM) -> tuple[float, float]:
    """Left edge and width of pixels centred on ``c``, times ``unit`` (default: in cm)."""
    step = float(c[1] - c[0]) if c.size > 1 else 1e-3
    return float((c[0] - step / 2) * unit), float(step * c.size * unit)


def _cm(v: float, digits: int = 2) -> str:
    """``v`` metres in cm, rounded, never "-0.00"."""
    return f"{round(v * CM, digits) + 0.0:.{digits}f}"


def _fmt_eps(e: complex | None, std: tuple[float, float] | None) -> str:
    if e is None:
        return "-"
    if std is None:
        return f"{e.real:.3g}{e.imag:+.2g}j (no σ from this method)"
    return f"{e.real:.3g} ± {std[0]:.2g}, {e.imag:+.2g} ± {std[1]:.2g}j"


class ViewerPage:
    """One browser tab: the widgets, the figures and the callbacks that join them.

    Parameters
    ----------
    doc : bokeh.document.Document
        The tab's document.
    session : ViewSession
        The data (shared between tabs; its caches too).
    settings : ViewSettings
        The first look.
    export_dir : Path
        Where the export buttons write (never replacing a file).
    ground_file : Mapping, optional
        A layered ground offered as a choice; default the layered ground of
        ``settings`` (from a medium file, ``--layers`` or a saved look).
    objects : pandas.DataFrame, optional
        Objects to overlay and list from the start (a table of
        :func:`holoradar.detect`, e.g. read by :func:`.objects.read_objects`).
    find : bool
        Find the objects in the first plane shown (as the *Find objects* button).
    """

    def __init__(self, doc: Any, session: ViewSession, settings: ViewSettings,
                 export_dir: Path, ground_file: dict[str, Any] | None = None,
                 objects: Any = None, find: bool = False) -> None:
        self.doc = doc
        self.session = session
        self.s = settings
        self.export_dir = export_dir
        layered = settings.ground is not None and "layer" in settings.ground
        self.ground_file = ground_file or (dict(settings.ground) if layered else None)
        self.ref = 1.0
        self.volume = None
        self.points: list[tuple[float, float, float]] = []
        self.pending_plane = False
        self.pending_full = False
        self._syncing = False  # True while the page itself moves its widgets
        self._full_ok = True  # the last sweep (sections, colour scale) succeeded
        self.objects = objects
        self.section_at: tuple[float, float] | None = None  # x, y (m) of the sections
        self._build()
        self._full()
        if objects is not None:
            self.objects_note.text = f"{len(objects)} object(s) from the file"
        self._draw_objects()
        if find:
            self._schedule_find()

    # ------------------------------------------------------------------ layout
    def _build(self) -> None:
        from bokeh.layouts import column, row
        from bokeh.models import (
            Button,
            CheckboxGroup,
            ColorBar,
            ColumnDataSource,
            CustomJS,
            Div,
            HoverTool,
            Label,
            LinearColorMapper,
            RadioButtonGroup,
            Select,
            Slider,
            Span,
            Spinner,
        )
        from bokeh.plotting import figure

        s, S = self.s, self.session
        holo = S.kind == "holograms"
        self.status = Div(text="", name="status", width=CONTROLS_WIDTH - 10)
        self.info = Div(text=self._info_text(), name="info", width=CONTROLS_WIDTH - 10)
        a, b = s.sweep if s.sweep is not None else (0.0, 0.25)
        label = "depth below the surface (cm)" if s.ground is not None else "range z (cm)"
        step = max((b - a) / 500, 1e-4)
        self.depth = Slider(title=label, start=a * CM, end=b * CM, step=step * CM,
                            value=min(max(s.depth, a), b) * CM, name="depth",
                            width=CONTROLS_WIDTH - 20)
        self.depth.on_change("value", lambda _a, _o, _n: self._syncing or self._schedule_plane())
        self.sweep_a = Spinner(title="sweep from (cm)", value=round(a * CM, 3), step=0.5,
                               width=100, format="0[.]00",
                               name="sweep_a")
        self.sweep_b = Spinner(title="to (cm)", value=round(b * CM, 3), step=0.5, width=100,
                               format="0[.]00",
                               name="sweep_b")
        for w in (self.sweep_a, self.sweep_b):
            w.on_change("value", lambda _a, _o, _n: self._syncing or self._set_sweep())
        # ground
        g = dict(s.ground) if s.ground is not None else {}
        opts = ["air (no ground)", "half-space"] + (["layers from file"] if self.ground_file
                                                     else [])
        kind = "air (no ground)" if s.ground is None else (
            "layers from file" if "layer" in g else "half-space")
        self.ground_kind = Select(title="ground", options=opts, value=kind, name="ground",
                                  width=150)
        # The spinners show the ground's eps at the views' frequency (a conductivity or a
        # loss tangent given on the command line is in its imaginary part).
        m = S.medium(s) if s.ground is not None and "layer" not in g else None
        eps = complex(m.eps[1]) if m is not None and m.n_regions == 2 else 2.5 + 0j
        self.surface = Spinner(title="surface range (cm)", value=float(g.get("surface", 0.3)) * CM,
                               step=0.5, low=0.1, width=110, name="surface")
        self.eps_re = Spinner(title="eps'", value=eps.real, step=0.1, low=1.0, width=80,
                              name="eps_re")
        self.eps_im = Spinner(title="eps''", value=eps.imag, step=0.01, low=0.0, width=80,
                              format="0[.]0000",
                              name="eps_im")
        for w in (self.ground_kind, self.surface, self.eps_re, self.eps_im):
            w.on_change("value", lambda _a, _o, _n: self._set_ground())
        # display
        self.scale = RadioButtonGroup(labels=["dB", "linear"], active=0 if s.scale == "db" else 1,
                                      name="scale")
        self.scale.on_change("active", lambda _a, _o, _n: self._set(
            scale="db" if self.scale.active == 0 else "linear"))
        self.db_range = Spinner(title="dB range", value=s.db_range, step=5, low=1, high=200,
                                width=90, name="db_range")
        self.db_range.on_change("value", lambda _a, _o, n: self._set_db_range(n))
        self.which = RadioButtonGroup(labels=["image plane", "mirror-source plane"],
                                      active=0 if s.plane == "image" else 1, name="plane")
        self.which.on_change("active", lambda _a, _o, n: self._set(
            plane="image" if n == 0 else "mirror"))
        # glare
        self.glare = Select(title="glare suppression", value=s.glare, name="glare",
                            options=[(m, _GLARE_LABELS[m]) for m in GLARE_METHODS], width=170)
        self.glare.on_change("value", lambda _a, _o, n: self._set(glare=n))
        self.direct = CheckboxGroup(labels=["remove the direct wave too"],
                                    active=[0] if s.direct else [], name="direct")
        self.direct.on_change("active", lambda _a, _o, n: self._set(direct=bool(n)))
        self.glare_report = Div(text="", name="glare_report", width=CONTROLS_WIDTH - 10)
        # views and frequencies
        names = S.names if holo else []
        use = list(range(len(names))) if s.views is None else list(s.views)
        self.views = CheckboxGroup(labels=names, active=use, name="views")
        self.views.on_change("active", lambda _a, _o, n: self._set_views(n))
        self.mode = Select(title="synthesis", options=list(MODES), value=s.mode, name="mode",
                           width=140)
        self.mode.on_change("value", lambda _a, _o, n: self._set(mode=n))
        fopts = [("coherent", "all, coherent sum"), ("incoherent", "all, incoherent sum")]
        fopts += [(str(i), f"{f / 1e9:.4g} GHz") for i, f in enumerate(S.frequencies)]
        self.freq = Select(title="frequencies", options=fopts, value=str(s.frequency),
                           name="frequency", width=140)
        self.freq.on_change("value", lambda _a, _o, n: self._set(
            frequency=n if n in ("coherent", "incoherent") else int(n)))
        self.frame = Select(title="planes", value=s.frame, name="frame", width=150,
                            options=[("aperture", "parallel to the array"),
                                     ("ground", "level (ground frame)")])
        self.frame.on_change("value", lambda _a, _o, n: self._set(frame=n))
        # clicks
        self.click = RadioButtonGroup(labels=["click measures", "click places sections"],
                                      active=0, name="click")
        self.readout = Div(text="cursor: -", name="readout", sizing_mode="stretch_width")
        # Drawn on the plot's canvas: a Div's new text would re-lay out the whole page on
        # every slider step (about 8 ms in Chromium).
        self.peak = Label(x=6, y=6, x_units="screen", y_units="screen", text="", name="peak",
                          text_color="white", text_font_size="10pt",
                          background_fill_color="black", background_fill_alpha=0.6)
        self.ruler = Div(text="distance: click two points", name="distance",
                         sizing_mode="stretch_width")
        clear = Button(label="clear points", width=100, name="clear")
        clear.on_click(lambda: self._clear_points())
        # objects: found in the plane shown, or read from a file (--objects)
        self.find = Button(label="Find objects", width=120, name="find_objects",
                           button_type="primary")
        self.find.on_click(lambda _e=None: self._schedule_find())
        self.objects_note = Div(text="", name="objects_note", width=CONTROLS_WIDTH - 140)
        # export
        self.exported = Div(text="", name="exported", width=CONTROLS_WIDTH - 10)
        buttons = []
        for what in ("PNG", "NetCDF", "settings"):
            bt = Button(label=f"export {what}", width=105, name=f"export_{what.lower()}")
            bt.on_click(lambda _e=None, w=what: self._export(w))
            buttons.append(bt)
        # figures
        self.mapper = LinearColorMapper(palette="Inferno256", low=-s.db_range, high=0.0)
        # dB is drawn straight from the readout's "db" column (the mapper floors it at
        # -db_range): one array per picture over the websocket; linear adds "lin".
        self.src = ColumnDataSource(data={"db": [np.zeros((2, 2), np.float32)],
                                          "x": [0.0], "y": [0.0], "dw": [1.0], "dh": [1.0]},
                                    name="image_source")
        tools = "pan,wheel_zoom,box_zoom,reset,save,tap"
        self.fig = figure(title="plan view", height=460, tools=tools, sizing_mode="stretch_width",
                          min_width=PLAN_MIN_WIDTH, max_width=PLAN_MAX_WIDTH, match_aspect=True,
                          x_axis_label="x (cm)", y_axis_label="y (cm)", name="plan")
        self.plan = self.fig.image(image="db", x="x", y="y", dw="dw", dh="dh",
                                   source=self.src, color_mapper=self.mapper)
        self.bar = ColorBar(color_mapper=self.mapper, title="|E| (dB re sweep peak)",
                            width=12)
        self.fig.add_layout(self.bar, "right")
        self.fig.add_layout(self.peak)
        self.fig.add_tools(HoverTool(tooltips=[("x, y", "$x{0.0}, $y{0.0} cm"),
                                               ("|E|", "@db{0.0} dB")]))
        self.marks = ColumnDataSource(data={"x": [], "y": []}, name="marks")
        self.fig.scatter("x", "y", source=self.marks, size=9, marker="x", color="cyan",
                         line_width=2)
        self.fig.line("x", "y", source=self.marks, color="cyan", line_dash="dashed")
        self.vline = Span(location=0, dimension="height", line_color="white",
                          line_dash="dotted", line_alpha=0.6)
        self.hline = Span(location=0, dimension="width", line_color="white",
                          line_dash="dotted", line_alpha=0.6)
        self.fig.add_layout(self.vline)
        self.fig.add_layout(self.hline)
        self.fig.on_event("tap", self._tap)
        self.xz_src = ColumnDataSource(data={"image": [np.zeros((2, 2), np.float32)],
                                             "x": [0.0], "y": [0.0], "dw": [1], "dh": [1]})
        self.yz_src = ColumnDataSource(data=dict(self.xz_src.data))
        ylabel = "depth (cm)" if s.ground is not None else "range z (cm)"
        self.xz = figure(title="x-z section", width=SECTION_WIDTH, height=215,
                         x_axis_label="x (cm)", y_axis_label=ylabel,
                         tools="pan,wheel_zoom,reset,save", name="xz")
        self.yz = figure(title="y-z section", width=SECTION_WIDTH, height=215,
                         x_axis_label="y (cm)", y_axis_label=ylabel,
                         tools="pan,wheel_zoom,reset,save", name="yz")
        self.depth_marks = []
        for f, src in ((self.xz, self.xz_src), (self.yz, self.yz_src)):
            f.image(image="image", x="x", y="y", dw="dw", dh="dh", source=src,
                    color_mapper=self.mapper)
            f.y_range.flipped = True
            sp = Span(location=0, dimension="width", line_color="cyan", line_dash="dashed")
            f.add_layout(sp)
            self.depth_marks.append(sp)
        self._build_objects()
        # hologram and spectral window of one view
        self.holo_view = Select(title="hologram of view", options=[(str(i), n) for i, n in
                                                                   enumerate(names)],
                                value="0", name="holo_view", width=200)
        self.holo_view.on_change("value", lambda _a, _o, _n: self._guard(self._holo))
        self.h_amp = ColumnDataSource(data=dict(self.xz_src.data))
        self.h_phase = ColumnDataSource(data=dict(self.xz_src.data))
        self.h_spec = ColumnDataSource(data=dict(self.xz_src.data))
        self.hfigs = []
        for title, src, pal, lab in (
                ("|E|", self.h_amp, "Viridis256", ("x (cm)", "y (cm)")),
                ("phase (rad)", self.h_phase, "Turbo256", ("x (cm)", "y (cm)")),
                ("spectral window (dB)", self.h_spec, "Magma256",
                 ("kx / k", "ky / k"))):
            f = figure(title=title, height=250, tools="pan,wheel_zoom,reset,save",
                       sizing_mode="stretch_width", min_width=200, max_width=320,
                       match_aspect=True, x_axis_label=lab[0], y_axis_label=lab[1])
            m = LinearColorMapper(palette=pal)
            f.image(image="image", x="x", y="y", dw="dw", dh="dh", source=src, color_mapper=m)
            f.add_layout(ColorBar(color_mapper=m, width=8), "right")
            self.hfigs.append(f)
        # The waves that travel: |k_t| <= k, or 2k for a monostatic (transceiver) record,
        # whose phase is that of the path there and back.
        t = np.linspace(0, 2 * np.pi, 181)
        kmax = 2.0 if holo and S.views[0].monostatic else 1.0
        self.hfigs[2].line(kmax * np.cos(t), kmax * np.sin(t), color="white",
                           line_dash="dashed")
        self.hfigs[2].add_layout(Label(x=0.55 * kmax, y=0.8 * kmax, text_color="white",
                                       text="|k_t| = 2k" if kmax == 2 else "|k_t| = k",
                                       text_font_size="9pt"))
        # the cursor readout: x, y from the pointer, the value from the shown plane
        self.fig.js_on_event("mousemove", CustomJS(args={"src": self.src, "div": self.readout,
                                                         "depth": self.depth,
                                                         "which": self.which}, code="""
            const d = src.data; const w = d.dw[0], h = d.dh[0];
            const shape = d.db[0].shape || [0, 0];
            const i = Math.floor((cb_obj.y - d.y[0]) / h * shape[0]);
            const j = Math.floor((cb_obj.x - d.x[0]) / w * shape[1]);
            let v = '-';
            if (i >= 0 && j >= 0 && i < shape[0] && j < shape[1]) {
                v = Number(d.db[0][i * shape[1] + j]).toFixed(1) + ' dB';
            }
            // the slider reads depth below the surface, or range without a ground; the
            // mirror-source plane has its own range (in the plot's corner)
            const word = depth.title.startsWith('depth') ? 'depth' : 'range';
            const z = which.active == 1 ? '' : `${word} = ${depth.value.toFixed(1)} cm, `;
            div.text = `cursor: x = ${cb_obj.x.toFixed(1)} cm, y = ${cb_obj.y.toFixed(1)} cm, `
                     + `${z}|E| = ${v}`;
        """))
        controls = column(
            self.info, self.status, self.depth, row(self.sweep_a, self.sweep_b),
            row(self.ground_kind, self.surface), row(self.eps_re, self.eps_im),
            self.glare, self.direct, self.glare_report, self.which,
            Div(text="<b>views</b>"), self.views, row(self.mode, self.freq), self.frame,
            row(self.scale, self.db_range), self.click, clear,
            row(self.find, self.objects_note), row(*buttons[:2]),
            buttons[2], self.exported, width=CONTROLS_WIDTH)
        readouts = column(self.readout, self.ruler, self.obj_table,
                          sizing_mode="stretch_width")
        # The hologram row only where holograms were opened (an image has none).
        holo_row = row(column(self.holo_view, self.hfigs[0], sizing_mode="stretch_width",
                              max_width=320),
                       self.hfigs[1], self.hfigs[2], visible=holo, sizing_mode="stretch_width",
                       max_width=PLAN_MAX_WIDTH + SECTION_WIDTH)
        # A survey's mosaic is one plane at a time: no sections.
        plots = [column(self.fig, readouts, sizing_mode="stretch_width",
                        max_width=PLAN_MAX_WIDTH)] + (
            [column(self.xz, self.yz, width=SECTION_WIDTH)] if S.kind != "survey" else [])
        # Fixed controls, the rest stretched to the window (see CONTROLS_WIDTH).
        layout = row(controls, column(row(*plots, sizing_mode="stretch_width"), holo_row,
                                      sizing_mode="stretch_width"),
                     sizing_mode="stretch_width", name="layout")
        if not holo:
            for w in (self.ground_kind, self.surface, self.eps_re, self.eps_im, self.glare,
                      self.direct, self.which, self.mode, self.freq, self.frame,
                      self.holo_view):
                w.disabled = True
        self.doc.add_root(layout)
        self.doc.template = PAGE_TEMPLATE
        self.doc.js_on_event("document_ready", CustomJS(code=_DROP_LOADING))
        self.doc.title = f"holoradar view: {', '.join(p.name for p in S.paths)}"

    def _info_text(self) -> str:
        S = self.session
        if S.kind == "survey":
            what = f"survey store, {len(S.names)} frames"
        elif S.kind == "image":
            v = S.volume
            what = (f"image, {v.z.size} plane(s) {v.z.min() * CM:.1f} to {v.z.max() * CM:.1f} "
                    "cm")
        else:
            h = S.views[0]
            f = S.frequencies
            fs = f"{f[0] / 1e9:.4g} GHz" if f.size == 1 else \
                f"{f.size} frequencies {f[0] / 1e9:.4g} to {f[-1] / 1e9:.4g} GHz"
            what = (f"{len(S.views)} view(s), {h.x.size} x {h.y.size} elements, pitch "
                    f"{h.pitch[0] * CM:.3g} cm, {fs}"
                    + (", tilted array" if S.tilted else ""))
        return f"<b>{html.escape(', '.join(p.name for p in S.paths))}</b><br>{what}"

    # ------------------------------------------------------------- settings
    def _set(self, **changes: Any) -> None:
        try:
            self.s = self.s.replace(**changes)
        except ValueError as exc:
            self._error(str(exc))
            return
        light = set(changes) <= {"scale", "db_range"}
        if light:
            self._recolour()
        else:
            self._schedule_full()

    def _set_db_range(self, value: float | None) -> None:
        if value is None:
            self._error("dB range: give a number of dB (1 to 200)")
            return
        self._set(db_range=float(value))

    def _set_views(self, active: list[int]) -> None:
        if not active:
            self._error("views: keep at least one view")
            return
        self._set(views=tuple(sorted(active)))

    def _set_sweep(self) -> None:
        a, b = self.sweep_a.value, self.sweep_b.value
        if a is None or b is None or not b > a:
            self._error("sweep: 'to' must be deeper than 'from'")
            return
        self.depth.start, self.depth.end = a, b
        self.depth.step = max((b - a) / 500, 0.01)
        self.depth.value = min(max(self.depth.value, a), b)
        self._set(sweep=(a / CM, b / CM))

    def _set_ground(self) -> None:
        kind = self.ground_kind.value
        if kind == "air (no ground)":
            ground = None
        elif kind == "layers from file":
            ground = self.ground_file
        else:
            try:
                ground = {"surface": float(self.surface.value) / CM,
                          "eps": f"{float(self.eps_re.value)}+{float(self.eps_im.value)}j"}
            except (TypeError, ValueError):
                self._error("ground: give the surface range and eps', eps''")
                return
        try:
            new = self.s.replace(ground=ground)
            # With a ground the slider reads depth below the surface, without one range
            # from the array: the same planes stay in view when the ground comes or goes.
            shift = self.session.surface(self.s) - self.session.surface(new) \
                if (ground is None) != (self.s.ground is None) else 0.0
        except ValueError as exc:
            self._error(str(exc))
            return
        self.depth.title = "depth below the surface (cm)" if ground is not None \
            else "range z (cm)"
        for f in (self.xz, self.yz):
            f.yaxis.axis_label = "depth (cm)" if ground is not None else "range z (cm)"
        if shift:
            a, b = (v + shift for v in (new.sweep or (0.0, 0.25)))
            self._syncing = True
            try:
                self.sweep_a.value, self.sweep_b.value = round(a * CM, 3), round(b * CM, 3)
                self.depth.start, self.depth.end = a * CM, b * CM
                self.depth.value = (new.depth + shift) * CM
            finally:
                self._syncing = False
            self._set(ground=ground, sweep=(a, b), depth=new.depth + shift)
        else:
            self._set(ground=ground)

    def _error(self, text: str) -> None:
        self.status.text = f'<span style="color:#b00">{html.escape(text)}</span>'

    # ------------------------------------------------------------- scheduling
    def _schedule_full(self) -> None:
        if not self.pending_full:
            self.pending_full = True
            self.status.text = "imaging the sweep ..."
            self.doc.add_next_tick_callback(self._full)

    def _schedule_plane(self) -> None:
        if not self.pending_plane:
            self.pending_plane = True
            self.doc.add_next_tick_callback(self._plane)

    def _guard(self, work: Any, what: str = "") -> bool:
        """Run ``work()``; an error is shown on the page (prefixed by ``what``), never lost
        in a callback."""
        try:
            work()
        except (ValueError, OSError) as exc:
            self._error(f"{what}{exc}")
            return False
        except Exception as exc:  # a bug must show, not freeze the page
            traceback.print_exc()
            self._error(f"{what}internal error: {type(exc).__name__}: {exc}")
            return False
        return True

    # ------------------------------------------------------------- pictures
    def _full(self) -> None:
        self.pending_full = False
        self._full_ok = self._guard(self._compute_full)
        if self._full_ok:
            self.status.text = "".join(f'<div style="color:#a60">note: {html.escape(w)}</div>'
                                       for w in self.session.notes(self.s))
        self._plane()

    def _compute_full(self) -> None:
        S, s = self.session, self.s
        self.volume = S.sweep(s)
        self.fig.title.text = ("mirror-source plane (the glare's focus)" if s.plane == "mirror"
                               else "plan view at the slider's depth")
        self.ref = float(np.abs(self.volume.data).max()) or 1.0
        if s.plane == "mirror":
            raw = S.mirror_plane(s.replace(glare="off"))
            self.ref = float(np.abs(raw.data).max()) or 1.0
        self._glare()
        self._holo()
        self._sections()

    def _plane(self) -> None:
        self.pending_plane = False
        self.s = self.s.replace(depth=float(self.depth.value) / CM)
        # A good plane clears its own earlier error, never the sweep's.
        if self._guard(self._compute_plane) and self._full_ok and \
                self.status.text.startswith('<span style="color:#b00">'):
            self.status.text = ""

    def _compute_plane(self) -> None:
        S, s = self.session, self.s
        img = S.image(s)
        amp = np.abs(img.data)
        x0, w = _edges(img.x)
        y0, h = _edges(img.y)
        surf = S.surface(s)
        pk = peak_of(img, self.ref)
        where = "depth" if s.ground is not None and s.plane != "mirror" else "range"
        at = float(img.z[0]) - (surf if where == "depth" else 0.0)
        pz = pk.z - (surf if where == "depth" else 0.0)
        # The readouts go out before the picture: each change is its own message, and
        # whoever waits for the picture (a user, a test) then finds them current.
        self.peak.text = (f"{where} {_cm(at)} cm\n"
                          f"peak: x = {_cm(pk.x)} cm, y = {_cm(pk.y)} cm,\n"
                          f"{where} = {_cm(pz)} cm, |E| = {pk.level_db:.1f} dB")
        for sp in self.depth_marks:
            sp.location = self.depth.value
        self._recolour_mapper()
        data = {"db": [db(amp, self.ref).astype(np.float32)], "x": [x0], "y": [y0],
                "dw": [w], "dh": [h]}
        if s.scale == "linear":
            data["lin"] = [scaled(amp, self.ref, "linear", s.db_range).astype(np.float32)]
        else:
            self.plan.glyph.image = "db"  # before the data that may lack "lin"
        self.src.data = data
        if s.scale == "linear":
            self.plan.glyph.image = "lin"  # after the data that has it

    def _recolour_mapper(self) -> None:
        s = self.s
        if s.scale == "db":
            self.mapper.low, self.mapper.high = -s.db_range, 0.0
            self.bar.title = ("|E| (dB re the unsuppressed glare)" if s.plane == "mirror"
                              else "|E| (dB re sweep peak)")
        else:
            self.mapper.low, self.mapper.high = 0.0, 1.0
            self.bar.title = "|E| / sweep peak"

    def _recolour(self) -> None:
        self._guard(self._sections)
        self._plane()

    def _sections(self) -> None:
        S, s, vol = self.session, self.s, self.volume
        if vol is None:
            return
        if S.kind == "survey":  # not in the page (see _build)
            return
        if s.section is not None:
            x, y = s.section
        else:
            from ...analysis.metrics import peak_position

            x, y, _ = peak_position(vol)
        xz, yz = sections(vol, x, y)
        z = vol.z - S.surface(s)
        steps = np.diff(z)
        if steps.size > 1 and not np.allclose(steps, steps[0], rtol=1e-6):
            # An image file's planes may be unevenly spaced; the page draws a regular
            # grid: each row shows the nearest plane.
            even = np.linspace(z[0], z[-1], max(64, 2 * z.size))
            near = np.abs(even[:, None] - z[None, :]).argmin(axis=1)
            xz, yz, z = xz[near], yz[near], even
        z0, dz = _edges(z)
        for src, a, c in ((self.xz_src, xz, vol.x), (self.yz_src, yz, vol.y)):
            c0, w = _edges(c)
            src.data = {"image": [scaled(a, self.ref, s.scale, s.db_range).astype(np.float32)],
                        "x": [c0], "y": [z0], "dw": [w], "dh": [dz]}
        self.xz.title.text = f"x-z section at y = {_cm(y, 1)} cm"
        self.yz.title.text = f"y-z section at x = {_cm(x, 1)} cm"
        self.vline.location, self.hline.location = x * CM, y * CM
        self.section_at = (float(x), float(y))
        self._draw_objects()

    def _holo(self) -> None:
        S, s = self.session, self.s
        if S.kind != "holograms":
            return
        i = int(self.holo_view.value)
        h = S.hologram(s, i)
        x0, w = _edges(h.x)
        y0, hh = _edges(h.y)
        d = h.data
        self.h_amp.data = {"image": [np.abs(d).astype(np.float32)], "x": [x0], "y": [y0],
                           "dw": [w], "dh": [hh]}
        self.h_phase.data = {"image": [np.angle(d).astype(np.float32)], "x": [x0],
                             "y": [y0], "dw": [w], "dh": [hh]}
        kx, ky, spec = S.spectrum(s, i)
        sdb = scaled(spec, float(spec.max()), "db", 40.0).astype(np.float32)
        kx0, kw = _edges(kx, 1.0)
        ky0, kh = _edges(ky, 1.0)
        self.h_spec.data = {"image": [sdb], "x": [kx0], "y": [ky0], "dw": [kw], "dh": [kh]}
        state = "glare removed" if s.glare != "off" else "as recorded"
        self.hfigs[0].title.text = f"|E|, {state}"

    def _glare(self) -> None:
        S, s = self.session, self.s
        if S.kind != "holograms" or s.glare == "off":
            self.glare_report.text = ""
            return
        _, notes = S.cleaned(s)

        def db_cell(v: float | None) -> str:
            return "-" if v is None else f"{v:.1f}"

        rows = []
        for n in notes:
            view = html.escape(n.view)
            if n.error is not None:
                rows.append(f"<tr><td>{view}</td><td colspan=4 style='color:#b00'>"
                            f"{html.escape(n.error)}</td></tr>")
                continue
            rows.append(f"<tr><td>{view}</td><td>{db_cell(n.removed_db)}</td>"
                        f"<td>{db_cell(n.direct_db)}</td><td>{db_cell(n.suppression_db)}</td>"
                        f"<td>{_fmt_eps(n.eps, n.eps_std)}</td></tr>")
            if n.warning:
                rows.append(f"<tr><td></td><td colspan=4 style='color:#a60'>"
                            f"{html.escape(n.warning)}</td></tr>")
        self.glare_report.text = (
            "<table><tr><th>view</th><th>glare removed (dB)</th><th>direct removed (dB)</th>"
            "<th>spot drop (dB)</th><th>eps from glare</th></tr>" + "".join(rows)
            + "</table>")

    # ------------------------------------------------------------- clicks
    def _tap(self, event: Any) -> None:
        x, y = float(event.x) / CM, float(event.y) / CM
        if not (math.isfinite(x) and math.isfinite(y)):
            return
        if self.click.active == 1:
            self._set(section=(x, y))
            return
        self.points = [*self.points[-1:], (x, y, float(self.depth.value) / CM)]
        self.marks.data = {"x": [p[0] * CM for p in self.points],
                           "y": [p[1] * CM for p in self.points]}
        if len(self.points) == 2:
            p, q = self.points
            d = distance(p, q)
            self.ruler.text = (f"distance: {d * CM:.2f} cm (dx {abs(q[0] - p[0]) * CM:.2f}, "
                               f"dy {abs(q[1] - p[1]) * CM:.2f}, d(depth) "
                               f"{abs(q[2] - p[2]) * CM:.2f} cm)")
        else:
            self.ruler.text = "distance: click a second point"

    def _clear_points(self) -> None:
        self.points = []
        self.marks.data = {"x": [], "y": []}
        self.ruler.text = "distance: click two points"

    # ------------------------------------------------------------- objects
    def _build_objects(self) -> None:
        """The objects' glyphs on the plan view and the sections, and their list."""
        from bokeh.models import ColumnDataSource, DataTable, TableColumn

        from .objects import TABLE_FIELDS, overlay, section_marks, table_rows

        empty = overlay(None)
        self.obj_src = {k: ColumnDataSource(data=v, name=f"objects_{k}")
                        for k, v in empty.items()}
        colour = "#39ff14"
        f = self.fig
        f.patches("xs", "ys", source=self.obj_src["areas"], fill_color=colour,
                  fill_alpha=0.12, line_color=colour, line_width=2)
        f.segment("x0", "y0", "x1", "y1", source=self.obj_src["lines"], line_color=colour,
                  line_width=3)
        f.scatter("x", "y", source=self.obj_src["points"], marker="circle", size=16,
                  fill_alpha=0.0, line_color=colour, line_width=2)
        f.text("x", "y", text="text", source=self.obj_src["labels"], text_color=colour,
               text_font_size="11pt", text_font_style="bold", x_offset=8, y_offset=-8)
        xz, yz = section_marks(None, 0.0, (0.0, 0.0), 0.0)
        self.obj_sections = []
        for fig, data in ((self.xz, xz), (self.yz, yz)):
            src = ColumnDataSource(data=data, name=f"objects_{fig.name}")
            fig.scatter("x", "z", source=src, marker="circle", size=12, fill_alpha=0.0,
                        line_color=colour, line_width=2)
            fig.text("x", "z", text="text", source=src, text_color=colour,
                     text_font_size="10pt", text_font_style="bold", x_offset=7, y_offset=-7)
            self.obj_sections.append(src)
        self.obj_table_src = ColumnDataSource(data=table_rows(None, 0.0),
                                              name="objects_source")
        widths = {"n": 30, "kind": 50, "depth": 150, "size": 90}
        # Shown once there are objects (an empty list would only take room).
        self.obj_table = DataTable(
            source=self.obj_table_src, name="objects", height=160, index_position=None,
            sizing_mode="stretch_width", selectable=True, sortable=False, visible=False,
            columns=[TableColumn(field=k, title=t, width=widths.get(k, 60))
                     for k, t in TABLE_FIELDS])
        self.obj_table_src.selected.on_change("indices", lambda _a, _o, n: self._goto(n))

    def _draw_objects(self) -> None:
        """Fill the objects' sources from ``self.objects`` for the look shown."""
        from .objects import overlay, section_marks, table_rows

        df = self.objects
        surface = self.session.surface(self.s) if self.session.kind == "holograms" else 0.0
        for k, v in overlay(df).items():
            self.obj_src[k].data = v
        if self.section_at is not None:
            near = self._near()
            for src, data in zip(self.obj_sections,
                                 section_marks(df, surface, self.section_at, near),
                                 strict=True):
                src.data = data
        rows = table_rows(df, surface)
        self.obj_table_src.data = rows
        n = len(rows["n"])
        self.obj_table.visible = n > 0
        self.obj_table.height = min(160, 30 + 26 * n)

    def _near(self) -> float:
        """How far from a section an object is marked on it: half a resolution cell
        of the detection (a table from a file: the plan view's 2 pixels, or 1 cm)."""
        cell = (self.objects.attrs.get("resolution_cell") if self.objects is not None
                else None)
        if cell is not None and len(cell) >= 2 and all(map(math.isfinite, cell[:2])):
            return 0.5 * max(float(cell[0]), float(cell[1]))
        vol = self.volume
        if vol is not None and vol.x.size > 1:
            return max(2 * abs(float(vol.x[1] - vol.x[0])), 0.01)
        return 0.01

    def _schedule_find(self) -> None:
        self.objects_note.text = "finding objects ..."
        self.doc.add_next_tick_callback(self._find)

    def _find(self) -> None:
        def work() -> None:
            # the plane at the slider, even while its picture is still on its way
            self.s = self.s.replace(depth=float(self.depth.value) / CM)
            df = self.session.objects(self.s)
            self.objects = df
            self._draw_objects()
            where = "depth" if self.s.ground is not None else "range"
            self.objects_note.text = (f"{len(df)} object(s) in the plane at {where} "
                                      f"{float(self.depth.value):.1f} cm")

        if not self._guard(work, "find objects: "):
            self.objects_note.text = ""

    def _goto(self, indices: list[int]) -> None:
        """A chosen row: the slider to its object's depth, the sections through it."""
        if not indices:
            return
        data = self.obj_table_src.data
        i = int(indices[0])
        at, x, y = data["at"][i], data["x_m"][i], data["y_m"][i]
        if at is None or not math.isfinite(at):
            return
        if not self.depth.start <= at <= self.depth.end:
            # beyond the sweep: widen it (the spinners redo the sweep)
            self.sweep_a.value = round(min(self.depth.start, at), 3)
            self.sweep_b.value = round(max(self.depth.end, at), 3)
        self.depth.value = at
        if math.isfinite(x) and math.isfinite(y):
            self._set(section=(float(x), float(y)))

    # ------------------------------------------------------------- export
    def _export(self, what: str) -> None:
        from .export import export_netcdf, export_png, export_settings

        def work() -> None:
            if what == "PNG":
                p = export_png(self.session, self.s, self.export_dir)
            elif what == "NetCDF":
                p = export_netcdf(self.session, self.s, self.export_dir)
            else:
                p = export_settings(self.s, self.export_dir)
            self.exported.text = f"wrote {html.escape(str(p))}"

        self._guard(work, f"export {what}: ")
