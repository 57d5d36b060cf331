"""The page's objects: their markers on the plan view and the sections, and their list.

The objects are a table of :func:`holoradar.detect` (found in the plane shown, or read
from a file); :mod:`holoradar.app.view.objects` turns it into the glyphs' data, in cm.
Choosing a row of the list takes the slider to its object's depth and the sections
through it.
"""

from __future__ import annotations

import math

from ..display import CM

__all__ = ["ObjectList"]

_COLOUR = "#39ff14"


class ObjectList:
    """The objects of a :class:`~holoradar.app.view.page.ViewerPage`: found, drawn, listed.

    A part of the page: it draws on the page's figures (``fig``, ``xz``, ``yz``), moves
    its depth slider and sweep, and finds objects in the plane of its look ``s``.
    """

    # ------------------------------------------------------------ building
    def _build_objects(self) -> None:
        """The objects' glyphs on the plan view and the sections, and their list."""
        self._build_object_marks()
        self._build_object_section_marks()
        self._build_object_table()

    def _build_object_marks(self) -> None:
        """Areas, lines, points and labels on the plan view."""
        from bokeh.models import ColumnDataSource

        from ..objects import overlay

        empty = overlay(None)
        self.obj_src = {k: ColumnDataSource(data=v, name=f"objects_{k}")
                        for k, v in empty.items()}
        f = self.fig
        f.patches("xs", "ys", source=self.obj_src["areas"], fill_color=_COLOUR,
                  fill_alpha=0.12, line_color=_COLOUR, line_width=2)
        f.segment("x0", "y0", "x1", "y1", source=self.obj_src["lines"], line_color=_COLOUR,
                  line_width=3)
        f.scatter("x", "y", source=self.obj_src["points"], marker="circle", size=16,
                  fill_alpha=0.0, line_color=_COLOUR, line_width=2)
        f.text("x", "y", text="text", source=self.obj_src["labels"], text_color=_COLOUR,
               text_font_size="11pt", text_font_style="bold", x_offset=8, y_offset=-8)

    def _build_object_section_marks(self) -> None:
        """The objects near each section, marked on it."""
        from bokeh.models import ColumnDataSource

        from ..objects import section_marks

        xz, yz = section_marks(None, 0.0, (0.0, 0.0), 0.0)
        self.obj_sections = []
        for fig, data in ((self.xz, xz), (self.yz, yz)):
            src = ColumnDataSource(data=data, name=f"objects_{fig.name}")
            fig.scatter("x", "z", source=src, marker="circle", size=12, fill_alpha=0.0,
                        line_color=_COLOUR, line_width=2)
            fig.text("x", "z", text="text", source=src, text_color=_COLOUR,
                     text_font_size="10pt", text_font_style="bold", x_offset=7, y_offset=-7)
            self.obj_sections.append(src)

    def _build_object_table(self) -> None:
        """The list of the objects; a chosen row is gone to (:meth:`_goto`)."""
        from bokeh.models import ColumnDataSource, DataTable, TableColumn

        from ..objects import TABLE_FIELDS, table_rows

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

    # ------------------------------------------------------------ drawing
    def _draw_objects(self) -> None:
        """Fill the objects' sources from ``self.objects`` for the look shown."""
        from ..objects import overlay, section_marks, table_rows

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

    # ------------------------------------------------------------ finding
    def _schedule_find(self) -> None:
        self.objects_note.text = "finding objects ..."
        self.doc.add_next_tick_callback(self._find)

    def _find(self) -> None:
        """Find the objects in the plane at the slider (an error shows on the page)."""
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
