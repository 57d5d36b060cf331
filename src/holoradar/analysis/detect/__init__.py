"""Detection: the objects in an image with position, depth, size and confidence.

:func:`detect` finds objects by CLEAN (:mod:`.clean`) above a threshold set by the
image's own noise (:mod:`.noise`), fits each with its point response (:mod:`.model`
from the hologram, :mod:`.window` from the image alone), joins elongated ones into
lines (:mod:`.lines`) and returns a table (:mod:`.table`). See docs/detect.md.
"""

from .api import detect
from .table import COLUMNS

__all__ = ["COLUMNS", "detect"]
