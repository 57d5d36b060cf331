"""The page's controls: its widgets and the callbacks that turn them into a new look.

A widget's change becomes a new :class:`~holoradar.app.view.settings.ViewSettings`
(:meth:`Controls._set`); one that changes the data is imaged again by the page's
scheduling, one that changes only the colours (scale, dB range) is redrawn. Lengths on
the widgets are in cm, in the settings in metres.
"""

from __future__ import annotations

import html
import math
from typing import Any

from ..display import CM, distance
from ..settings import GLARE_METHODS, MODES, PLANES
from .layout import CONTROLS_WIDTH

__all__ = ["Controls"]

_GLARE_LABELS = {"off": "off", "gaussian": "Gaussian beam fit", "image_source": "image source",
                 "cut": "mirror-plane cut"}


class Controls:
    """The widgets of a :class:`~holoradar.app.view.page.ViewerPage` and their callbacks.

    A part of the page: it reads and sets the page's ``s`` (the look), ``session``,
    ``doc`` and figures, and calls its scheduling (``_schedule_full``, ``_recolour``,
    ``_guard``, ``_error``).
    """

    # ------------------------------------------------------------ widgets
    def _build_controls(self) -> None:
        """Every control, from the first look ``self.s``."""
        self._build_status()
        self._build_depth()
        self._build_ground()
        self._build_display()
        self._build_glare()
        self._build_views()
        self._build_clicks()
        self._build_find()
        self._build_export()

    def _build_status(self) -> None:
        from bokeh.models import Div

        self.status = Div(text="", name="status", width=CONTROLS_WIDTH - 10)
        self.info = Div(text=self._info_text(), name="info", width=CONTROLS_WIDTH - 10)

    def _build_depth(self) -> None:
        """The depth slider and the sweep it moves in (cm)."""
        from bokeh.models import Slider, Spinner

        s = self.s
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

    def _build_ground(self) -> None:
        """The ground: none, a half-space (surface range, eps) or the layers of a file."""
        from bokeh.models import Select, Spinner

        s, S = self.s, self.session
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

    def _build_display(self) -> None:
        """The colour scale (dB or linear), its dB range, and which plane is shown."""
        from bokeh.models import RadioButtonGroup, Spinner

        s = self.s
        self.scale = RadioButtonGroup(labels=["dB", "linear"], active=0 if s.scale == "db" else 1,
                                      name="scale")
        self.scale.on_change("active", lambda _a, _o, _n: self._set(
            scale="db" if self.scale.active == 0 else "linear"))
        self.db_range = Spinner(title="dB range", value=s.db_range, step=5, low=1, high=200,
                                width=90, name="db_range")
        self.db_range.on_change("value", lambda _a, _o, n: self._set_db_range(n))
        self.which = RadioButtonGroup(
            labels=["image plane", "mirror-source plane", "reflectivity"],
            active=PLANES.index(s.plane), name="plane")
        self.which.on_change("active", lambda _a, _o, n: self._set(plane=PLANES[n]))

    def _build_glare(self) -> None:
        """The glare suppression, the direct wave's, and the report of what they removed."""
        from bokeh.models import CheckboxGroup, Div, Select

        s = self.s
        self.glare = Select(title="glare suppression", value=s.glare, name="glare",
                            options=[(m, _GLARE_LABELS[m]) for m in GLARE_METHODS], width=170)
        self.glare.on_change("value", lambda _a, _o, n: self._set(glare=n))
        self.direct = CheckboxGroup(labels=["remove the direct wave too"],
                                    active=[0] if s.direct else [], name="direct")
        self.direct.on_change("active", lambda _a, _o, n: self._set(direct=bool(n)))
        self.glare_report = Div(text="", name="glare_report", width=CONTROLS_WIDTH - 10)

    def _build_views(self) -> None:
        """The views used, their synthesis, the frequencies and the planes' frame."""
        from bokeh.models import CheckboxGroup, Select

        s, S = self.s, self.session
        names = S.names if S.kind == "holograms" else []
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

    def _build_clicks(self) -> None:
        """What a click on the plan view does, and the distance it measures."""
        from bokeh.models import Button, Div, RadioButtonGroup

        self.click = RadioButtonGroup(labels=["click measures", "click places sections"],
                                      active=0, name="click")
        self.ruler = Div(text="distance: click two points", name="distance",
                         sizing_mode="stretch_width")
        self._clear_button = Button(label="clear points", width=100, name="clear")
        self._clear_button.on_click(lambda: self._clear_points())

    def _build_find(self) -> None:
        """Objects: found in the plane shown, or read from a file (``--objects``)."""
        from bokeh.models import Button, Div

        self.find = Button(label="Find objects", width=120, name="find_objects",
                           button_type="primary")
        self.find.on_click(lambda _e=None: self._schedule_find())
        self.objects_note = Div(text="", name="objects_note", width=CONTROLS_WIDTH - 140)

    def _build_export(self) -> None:
        """The export buttons (PNG, NetCDF, settings) and what they wrote."""
        from bokeh.models import Button, Div

        self.exported = Div(text="", name="exported", width=CONTROLS_WIDTH - 10)
        self._export_buttons = []
        for what in ("PNG", "NetCDF", "settings"):
            bt = Button(label=f"export {what}", width=105, name=f"export_{what.lower()}")
            bt.on_click(lambda _e=None, w=what: self._export(w))
            self._export_buttons.append(bt)

    def _info_text(self) -> str:
        """What was opened (HTML): its files, and its views, image or survey in brief."""
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

    # ------------------------------------------------------------ settings
    def _set(self, **changes: Any) -> None:
        """A new look: redrawn if only its colours changed, else imaged again."""
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
        """The sweep from its spinners (cm); the slider follows it."""
        a, b = self.sweep_a.value, self.sweep_b.value
        if a is None or b is None or not b > a:
            self._error("sweep: 'to' must be deeper than 'from'")
            return
        self.depth.start, self.depth.end = a, b
        self.depth.step = max((b - a) / 500, 0.01)
        self.depth.value = min(max(self.depth.value, a), b)
        self._set(sweep=(a / CM, b / CM))

    def _set_ground(self) -> None:
        """The ground from its widgets; the planes shown stay where they were."""
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

    # ------------------------------------------------------------ clicks
    def _tap(self, event: Any) -> None:
        """A click on the plan view (cm): a point measured, or where the sections go."""
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

    # ------------------------------------------------------------ export
    def _export(self, what: str) -> None:
        """Write the look shown as ``what`` ("PNG", "NetCDF" or "settings")."""
        from ..export import export_netcdf, export_png, export_settings

        def work() -> None:
            if what == "PNG":
                p = export_png(self.session, self.s, self.export_dir)
            elif what == "NetCDF":
                p = export_netcdf(self.session, self.s, self.export_dir)
            else:
                p = export_settings(self.s, self.export_dir)
            self.exported.text = f"wrote {html.escape(str(p))}"

        self._guard(work, f"export {what}: ")
