"""The page's figures: the plan view, the sections, the hologram and its spectral window,
and the glare table, built once and then redrawn from the session's arrays.

The figures' axes are in cm (the arrays' coordinates are in metres); the spectral window's
in units of the wavenumber k. Amplitudes are drawn in dB re the sweep's peak (``ref``), or
linear as a fraction of it.
"""

from __future__ import annotations

import html

import numpy as np

from ...eps_text import eps_text
from ..display import CM, db, peak_of, scaled, sections
from .layout import PLAN_MAX_WIDTH, PLAN_MIN_WIDTH, SECTION_WIDTH

__all__ = ["Figures"]


def _edges(c: np.ndarray, unit: float = CM) -> tuple[float, float]:
    """Left edge and width of pixels centred on ``c``, times ``unit`` (default: in cm)."""
    step = float(c[1] - c[0]) if c.size > 1 else 1e-3
    return float((c[0] - step / 2) * unit), float(step * c.size * unit)


def _cm(v: float, digits: int = 2) -> str:
    """``v`` metres in cm, rounded, never "-0.00"."""
    return f"{round(v * CM, digits) + 0.0:.{digits}f}"


def _fmt_eps(e: complex | None, std: tuple[float, float] | None) -> str:
    """A permittivity from the glare, with its standard deviations where the method has
    them."""
    if e is None:
        return "-"
    if std is None:   # a rough estimate: two digits, no rounding residue as eps''
        imag = f"{e.imag:+.1g}j " if abs(e.imag) > 1e-3 * abs(e.real) else " "
        return f"about {e.real:.2g}{imag}(rough: no σ from this method)"
    return eps_text(e, std).replace("+-", "±")   # digits from sigma; no eps'' residue


# The cursor readout, in the browser: x, y from the pointer, the value from the shown plane.
_CURSOR_JS = """
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
        """


class Figures:
    """The figures of a :class:`~holoradar.app.view.page.ViewerPage`, and their drawing.

    A part of the page: it draws the page's ``session`` for its look ``s``; the depth
    slider and the plane choice are its controls'.
    """

    # ------------------------------------------------------------ building
    def _build_figures(self) -> None:
        """Every figure, empty until the first sweep draws them."""
        self._build_plan()
        self._build_sections()
        self._build_hologram()
        self._build_cursor()

    def _build_plan(self) -> None:
        """The plan view: the plane at the slider, its colour bar, peak and click marks."""
        from bokeh.models import (
            ColorBar,
            ColumnDataSource,
            HoverTool,
            Label,
            LinearColorMapper,
            Span,
        )
        from bokeh.plotting import figure

        self.mapper = LinearColorMapper(palette="Inferno256", low=-self.s.db_range, high=0.0)
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
        # Drawn on the plot's canvas: a Div's new text would re-lay out the whole page on
        # every slider step (about 8 ms in Chromium).
        self.peak = Label(x=6, y=6, x_units="screen", y_units="screen", text="", name="peak",
                          text_color="white", text_font_size="10pt",
                          background_fill_color="black", background_fill_alpha=0.6)
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

    def _build_sections(self) -> None:
        """The x-z and y-z sections, with the slider's depth marked on them."""
        from bokeh.models import ColumnDataSource, Span
        from bokeh.plotting import figure

        self.xz_src = ColumnDataSource(data={"image": [np.zeros((2, 2), np.float32)],
                                             "x": [0.0], "y": [0.0], "dw": [1], "dh": [1]})
        self.yz_src = ColumnDataSource(data=dict(self.xz_src.data))
        ylabel = "depth (cm)" if self.s.ground is not None else "range z (cm)"
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

    def _build_hologram(self) -> None:
        """One view's hologram (|E|, phase) and its spectral window."""
        from bokeh.models import ColorBar, ColumnDataSource, LinearColorMapper, Select
        from bokeh.plotting import figure

        S = self.session
        names = S.names if S.kind == "holograms" else []
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
        self._mark_travelling_waves()

    def _mark_travelling_waves(self) -> None:
        """The circle of the waves that travel on the spectral window."""
        from bokeh.models import Label

        S = self.session
        # The waves that travel: |k_t| <= k, or 2k for a monostatic (transceiver) record,
        # whose phase is that of the path there and back.
        t = np.linspace(0, 2 * np.pi, 181)
        kmax = 2.0 if S.kind == "holograms" and S.views[0].monostatic else 1.0
        self.hfigs[2].line(kmax * np.cos(t), kmax * np.sin(t), color="white",
                           line_dash="dashed")
        self.hfigs[2].add_layout(Label(x=0.55 * kmax, y=0.8 * kmax, text_color="white",
                                       text="|k_t| = 2k" if kmax == 2 else "|k_t| = k",
                                       text_font_size="9pt"))

    def _build_cursor(self) -> None:
        """The cursor readout under the plan view, written in the browser."""
        from bokeh.models import CustomJS, Div

        self.readout = Div(text="cursor: -", name="readout", sizing_mode="stretch_width")
        self.fig.js_on_event("mousemove", CustomJS(args={"src": self.src, "div": self.readout,
                                                         "depth": self.depth,
                                                         "which": self.which},
                                                   code=_CURSOR_JS))

    # ------------------------------------------------------------ drawing
    def _compute_plane(self) -> None:
        """Image the plane at the slider and draw it, with its readouts."""
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
        """The colour scale and its bar's title for the look's scale and plane."""
        s = self.s
        if s.scale == "db":
            self.mapper.low, self.mapper.high = -s.db_range, 0.0
            self.bar.title = ("|E| (dB re the unsuppressed glare)" if s.plane == "mirror"
                              else "|r| (dB re sweep peak)" if s.plane == "reflectivity"
                              else "|E| (dB re sweep peak)")
        else:
            self.mapper.low, self.mapper.high = 0.0, 1.0
            self.bar.title = "|E| / sweep peak"

    def _sections(self) -> None:
        """The sections through the look's point, or through the sweep's peak."""
        S, s, vol = self.session, self.s, self.volume
        if vol is None:
            return
        if S.kind == "survey":  # not in the page (see .layout)
            return
        if s.section is not None:
            x, y = s.section
        else:
            from ....analysis.metrics import peak_position

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
        """The chosen view's hologram, as the look has it (glare removed or not)."""
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
        """The table of what the glare suppression removed from each view (dB)."""
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
