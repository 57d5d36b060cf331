"""When the page computes: the depth sweep, the plane at the slider, and their errors.

A setting that changes the data redoes the depth sweep behind the sections and the colour
scale (:meth:`Scheduling._full`); the depth slider re-images one plane
(:meth:`Scheduling._plane`). Both run on Bokeh's next tick, at most one of each pending:
slider events that arrive while a plane is being imaged are merged, and the next picture
is for the latest depth. An error in either is shown on the page, never lost in a
callback.
"""

from __future__ import annotations

import html
import traceback
from typing import Any

import numpy as np

from ..display import CM

__all__ = ["Scheduling"]


class Scheduling:
    """The computing of a :class:`~holoradar.app.view.page.ViewerPage`: what is imaged
    when, and its errors on the page.

    A part of the page: it images the page's ``session`` for its look ``s`` and hands the
    results to its figures (``_glare``, ``_holo``, ``_sections``, ``_compute_plane``).
    """

    # ------------------------------------------------------------ scheduling
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

    def _error(self, text: str) -> None:
        self.status.text = f'<span style="color:#b00">{html.escape(text)}</span>'

    # ------------------------------------------------------------ computing
    def _full(self) -> None:
        """The depth sweep (sections, colour scale, holograms), then the plane."""
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
                               else "reflectivity (inverted) at the slider's depth"
                               if s.plane == "reflectivity"
                               else "plan view at the slider's depth")
        self.ref = float(np.abs(self.volume.data).max()) or 1.0
        if s.plane == "mirror":
            raw = S.mirror_plane(s.replace(glare="off"))
            self.ref = float(np.abs(raw.data).max()) or 1.0
        self._glare()
        self._holo()
        self._sections()

    def _plane(self) -> None:
        """The plane at the slider's depth."""
        self.pending_plane = False
        self.s = self.s.replace(depth=float(self.depth.value) / CM)
        # A good plane clears its own earlier error, never the sweep's.
        if self._guard(self._compute_plane) and self._full_ok and \
                self.status.text.startswith('<span style="color:#b00">'):
            self.status.text = ""

    def _recolour(self) -> None:
        """The sections and the plane again, in new colours (no new sweep)."""
        self._guard(self._sections)
        self._plane()
