"""Lines: points of CLEAN strung along an elongated reflector, joined into one."""

from __future__ import annotations

from typing import Any

__all__ = ["group_lines"]


def group_lines(rows: list[dict[str, Any]], cell: tuple[float, float, float]
                ) -> list[dict[str, Any]]:
    """Points unchanged (lines not yet joined)."""
    return rows
