"""Numbers for a person: lengths in centimetres without a "-0.0"."""

from __future__ import annotations

__all__ = ["cm"]


def cm(metres: float, digits: int = 1) -> str:
    """``metres`` in centimetres to ``digits`` decimals, never ``"-0.0"``.

    Examples
    --------
    >>> cm(-0.0004), cm(0.0312), cm(-0.0312, 0)
    ('0.0', '3.1', '-3')
    """
    return f"{round(100 * float(metres), digits) + 0.0:.{digits}f}"
