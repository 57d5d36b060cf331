"""A compact object's ringing: weak components around a strong one are not objects.

A real object is not a point. A sphere a wavelength across (or a short bar, a
cavity) scatters with a pattern of its own across the aperture, so its image
departs from the point response CLEAN subtracts, mostly in the response's
sidelobes; what is left rings around it above the noise. A full-wave metal
sphere (``k a = 5``, 10 cm deep in sand) left components 23, 23.5, 32, 37 and 41
dB below it at 1.3 to 3.6 cells along its E plane, which were joined into a
"line" beside it.

Such ringing lies at the level of the response's sidelobes or below (the first
sidelobe of a rectangular aperture is 13.3 dB down; a truncated bar's Gibbs
ringing 21 dB), while the pieces of an extended object (a bar, a plate) stand
within a few dB of each other, its edges at about -6 dB. So in each group of
components linked within ``LINK_CELLS`` cells (as lines and areas are), the
members within ``END_DB`` (13.5 dB, as for a line's ends) of the strongest are
the objects; when they are fewer than a line's ``MIN_COMPONENTS`` (one compact
object, or two side by side) the group is those objects and their ringing, and
the members more than ``END_DB`` below the strongest belong to them (are not
reported). An extended object keeps all its members (its faint edges included),
to be joined into its line or area.

The price, the detection's dynamic range near a strong compact object: within
``LINK_CELLS`` cells of it, or of its ringing, another object more than 13.5 dB
weaker is not told from that ringing.
"""

from __future__ import annotations

from typing import Any

import numpy as np  # noqa: F401  (the examples use it)

from .areas import _clusters
from .lines import END_DB, LINK_CELLS, MIN_COMPONENTS, point_components

__all__ = ["absorb_ringing"]


def absorb_ringing(rows: list[dict[str, Any]], cell: tuple[float, float, float],
                   model: Any = None) -> list[dict[str, Any]]:
    """Drop the point rows that are a compact object's ringing (module notes).

    Examples
    --------
    >>> def pt(y, db):
    ...     return {"kind": "point", "x": 0.0, "y": y, "range": 0.4, "amplitude_db": db}
    >>> sphere = [pt(0.0, 0.0), pt(0.025, -23.0), pt(-0.022, -23.5), pt(0.043, -32.0)]
    >>> [r["y"] for r in absorb_ringing(sphere, (0.017, 0.017, np.inf))]
    [0.0]
    >>> bar = [pt(y, -3.0 * abs(y) / 0.1) for y in np.arange(-0.1, 0.11, 0.025)]
    >>> len(absorb_ringing(bar, (0.017, 0.017, np.inf)))
    9
    """
    found = point_components(rows, cell, model, 2)
    if found is None:
        return rows
    idx, p, amp, c = found
    ringing: set[int] = set()
    for group in _clusters(p, LINK_CELLS * c):
        top = max(amp[g] for g in group)
        objects = [g for g in group if amp[g] >= top - END_DB]
        if len(objects) < MIN_COMPONENTS:
            ringing.update(idx[g] for g in group if g not in objects)
    return [r for k, r in enumerate(rows) if k not in ringing]
