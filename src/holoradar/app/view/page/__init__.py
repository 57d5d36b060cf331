"""The viewer's page: Bokeh widgets and plots bound to a :class:`ViewSession`.

Every picture comes from the session (holoradar's imaging in this process);
the page only draws the arrays it is sent over the Bokeh websocket. A setting
that changes the data (ground, glare, views, frequency, sweep) redoes the depth
sweep behind the sections and the colour scale; the depth slider re-images one
plane. Slider events that arrive while a plane is being imaged are merged:
the next picture is for the latest depth, never a queue of stale ones.

The page's parts, each a module here: :mod:`.controls` (the widgets and their
callbacks), :mod:`.figures` (the plots and their drawing), :mod:`.objects` (the
objects' markers and list), :mod:`.schedule` (what is computed when) and
:mod:`.layout` (where they all go); :class:`ViewerPage` ties them together.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..session import ViewSession
from ..settings import ViewSettings
from .controls import Controls
from .figures import Figures
from .layout import assemble
from .objects import ObjectList
from .schedule import Scheduling

__all__ = ["ViewerPage"]


class ViewerPage(Controls, Figures, ObjectList, Scheduling):
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
        :func:`holoradar.detect`, e.g. read by :func:`~holoradar.app.view.objects.read_objects`).
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

    def _build(self) -> None:
        """The widgets, then the figures (some follow widgets), then the page of them."""
        self._build_controls()
        self._build_figures()
        self._build_objects()
        assemble(self)
