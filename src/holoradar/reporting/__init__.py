"""The inspection report: one self-contained HTML file of what a survey found.

:func:`report` reads images, holograms or survey stores, finds their objects with
:func:`holoradar.detect` (or takes the tables given) and writes one HTML file:
plan views and sections at the objects' depths with the objects outlined and
numbered as in the table, the table itself, the ground and how it was found, the
device and settings, the processing history and the warnings raised on the way.
The pictures are embedded PNGs; the page loads nothing from anywhere.

The parts, one idea each: :mod:`.model` (what a section of the report holds),
:mod:`.sources` (a file or object turned into a section), :mod:`.metadata` (a
file's device, settings and history), :mod:`.figures` (the pictures),
:mod:`.table` (the objects' table), :mod:`.html` (the page), :mod:`.api`
(:func:`report`). See docs/report.md.
"""

from .api import report

__all__ = ["report"]
