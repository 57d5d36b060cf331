"""Planar shapes for test objects: boolean masks on a grid of (x, y) in metres.

Each function takes coordinate arrays ``X, Y`` (broadcastable, metres, relative
to the shape's centre) and returns a boolean mask that is True on the object.
"""

from __future__ import annotations

import numpy as np

__all__ = ["disk", "letter_r", "rectangle", "ring"]


def disk(X: np.ndarray, Y: np.ndarray, diameter: float) -> np.ndarray:
    """A disk of the given diameter (metres)."""
    return X**2 + Y**2 <= (diameter / 2) ** 2


def ring(X: np.ndarray, Y: np.ndarray, outer_diameter: float, width: float) -> np.ndarray:
    """An annulus: outer diameter and radial width, metres."""
    r2 = X**2 + Y**2
    ro = outer_diameter / 2
    return (r2 <= ro**2) & (r2 >= (ro - width) ** 2)


def rectangle(X: np.ndarray, Y: np.ndarray, width: float, height: float) -> np.ndarray:
    """An axis-aligned rectangle, full width (x) and height (y), metres."""
    return (np.abs(X) <= width / 2) & (np.abs(Y) <= height / 2)


def letter_r(X: np.ndarray, Y: np.ndarray, width: float = 0.10, height: float = 0.15,
             stroke: float | None = None) -> np.ndarray:
    """The letter R (the paper's stencil, 10 x 15 cm), upright for y increasing upwards.

    Parameters
    ----------
    width, height : float
        Size of the letter's bounding box, metres.
    stroke : float, optional
        Stroke width, metres (default ``width/4``).
    """
    t = width / 4 if stroke is None else stroke
    # Work in the letter's own frame: origin at the lower-left corner.
    x = X + width / 2
    y = Y + height / 2
    yb = 0.45 * height            # bottom of the bowl
    ro = (height - yb) / 2        # outer radius of the bowl's round part
    xc, yc = width - ro, yb + ro  # centre of the round part
    stem = (x >= 0) & (x <= t) & (y >= 0) & (y <= height)
    outer = (((x >= 0) & (x <= xc) & (y >= yb) & (y <= height))
             | ((x >= xc) & ((x - xc) ** 2 + (y - yc) ** 2 <= ro**2)))
    ri = ro - t
    inner = (((x >= t) & (x <= xc) & (y >= yb + t) & (y <= height - t))
             | ((x >= xc) & ((x - xc) ** 2 + (y - yc) ** 2 <= ri**2)))
    bowl = outer & ~inner
    # Leg: a stroke from the bowl's lower middle to the bottom-right corner.
    ax, ay, bx, by = 0.45 * width, yb, width - t / 2, 0.0
    dx, dy = bx - ax, by - ay
    s = np.clip(((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy), 0, 1)
    leg = (x - ax - s * dx) ** 2 + (y - ay - s * dy) ** 2 <= (t / 2) ** 2
    return stem | bowl | leg
