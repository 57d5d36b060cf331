"""Surface multiples: an object's echo that bounced once more between it and the surface.

A wave reflected by a buried object at depth ``d`` reaches the ground's surface from
below, part of it is reflected back down (the surface's reflection coefficient from
the ground side), meets the object again and returns: its path in the ground is
``4 d`` instead of ``2 d``, so the image shows it at depth ``2 d`` under the object,
with the object's shape and orientation and weaker by the surface's reflection and
the object's second scattering. A flat face (a disk, a bar's top) makes a strong one.

An object is taken as such a multiple of a stronger one when

* its depth lies within half a range cell ``c / (2 B n)`` of twice the stronger
  object's depth (one range cell wide: the depths are each read to a fraction of
  it), and
* it lies under it laterally: within a lateral resolution cell of its position
  (points and areas), or, for lines, parallel to it (azimuths within 10 degrees) and
  within a cell of its axis.

A real object at twice another's depth, under it and parallel to it, cannot be told
from its multiple by the image: it is listed among the multiples, with the object
whose multiple it would be, not dropped silently.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["AZIMUTH_DEG", "line_offset", "split_multiples"]

AZIMUTH_DEG = 10.0   # lines this parallel (degrees) can be one's multiple


def split_multiples(rows: list[dict[str, Any]], cell: float, range_cell: float
                    ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The rows that are objects, and those that are surface multiples (each with
    ``"multiple_of"``, the index in the first list of the object it repeats).

    Parameters
    ----------
    rows : list of dict
        Detection rows, strongest first, with ``depth`` below the surface (metres).
    cell, range_cell : float
        The lateral and range resolution cells, metres (``range_cell`` 0 or not finite:
        one frequency, no depth to compare, nothing is split).

    Examples
    --------
    >>> bar = {"kind": "line", "x": 0.0, "y": 0.0, "depth": 0.03, "azimuth_deg": 90.0}
    >>> echo = {**bar, "x": 0.002, "depth": 0.062}
    >>> kept, multiples = split_multiples([bar, echo], cell=0.013, range_cell=0.034)
    >>> len(kept), multiples[0]["multiple_of"]
    (1, 0)
    """
    if not (range_cell > 0 and math.isfinite(range_cell)):
        return list(rows), []
    kept: list[dict[str, Any]] = []
    multiples: list[dict[str, Any]] = []
    for row in rows:
        host = next((i for i, a in enumerate(kept) if _repeats(row, a, cell, range_cell)),
                    None)
        if host is None:
            kept.append(row)
        else:
            multiples.append({**row, "multiple_of": host})
    return kept, multiples


def _repeats(b: dict[str, Any], a: dict[str, Any], cell: float, range_cell: float) -> bool:
    """Whether ``b`` (weaker) lies where ``a``'s surface multiple would."""
    da, db = float(a.get("depth", math.nan)), float(b.get("depth", math.nan))
    if not (da > 0 and abs(db - 2 * da) <= range_cell / 2):
        return False
    if a["kind"] == "line" and b["kind"] == "line":
        d_az, across = line_offset(a, b)
        return d_az <= AZIMUTH_DEG and across <= cell
    if a["kind"] == "line" or b["kind"] == "line":
        return False
    return math.hypot(b["x"] - a["x"], b["y"] - a["y"]) <= cell


def line_offset(a: dict[str, Any], b: dict[str, Any]) -> tuple[float, float]:
    """The angle between two lines' azimuths (degrees, 0-90) and ``b``'s centre's
    distance from ``a``'s axis (metres).

    Examples
    --------
    >>> line_offset({"x": 0.0, "y": 0.0, "azimuth_deg": 90.0},
    ...             {"x": 0.07, "y": 0.02, "azimuth_deg": 268.0})
    (2.0, 0.07)
    """
    d_az = abs(a["azimuth_deg"] - b["azimuth_deg"]) % 180.0
    t = math.radians(a["azimuth_deg"])
    across = abs(-(b["x"] - a["x"]) * math.sin(t) + (b["y"] - a["y"]) * math.cos(t))
    return min(d_az, 180.0 - d_az), across
