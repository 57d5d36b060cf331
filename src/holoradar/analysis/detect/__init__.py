"""Detection: the objects in an image with position, depth, size and confidence.

:func:`detect` finds objects by CLEAN (:mod:`.clean`) above a threshold set by the
image's own noise (:mod:`.noise`), fits each with its point response (:mod:`.model`
from the hologram, :mod:`.window` from the image alone), joins elongated ones into
lines (:mod:`.lines`) and returns a table (:mod:`.table`); a wideband volume without
its hologram is searched plane by plane (:mod:`.stack`), and :func:`rebar_layers`
sums a rebar mat's lines up per direction. See docs/detect.md.
"""

from .api import detect
from .peak import PeakPosition, unbiased_peak
from .rebar import rebar_layers
from .table import COLUMNS

__all__ = ["COLUMNS", "PeakPosition", "detect", "rebar_layers", "unbiased_peak"]
