"""Off-screen figures shared by the report and the applications' plots: a figure as PNG
bytes (no pyplot, no display) and the cell edges ``pcolormesh`` takes."""

from __future__ import annotations

import io

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

__all__ = ["edges", "to_png"]


def to_png(fig: Figure, dpi: int = 110) -> bytes:
    """Render a figure to PNG bytes."""
    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def edges(c: np.ndarray) -> np.ndarray:
    """The edges of the cells centred on ``c`` (``c.size + 1`` values; one centre: a cell
    of width 1), for ``pcolormesh(..., shading="flat")``.

    Examples
    --------
    >>> edges(np.array([0.0, 1.0, 3.0])).tolist()
    [-0.5, 0.5, 2.0, 4.0]
    """
    c = np.asarray(c, float)
    if c.size == 1:
        return np.array([c[0] - 0.5, c[0] + 0.5])
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])
