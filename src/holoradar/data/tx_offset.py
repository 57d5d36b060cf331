"""The transmitter's offset from the receiver of a scanned pair, checked.

A scanner that carries a transmitting and a receiving antenna side by side records,
at each position ``p`` of the receiver, the field of a transmitter at ``p + d``: a
fixed offset ``d = (dx, dy, dz)`` in the aperture's own axes (``dz`` along its normal,
towards the scene). ``d = 0`` is a transceiver.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["as_tx_offset", "refuse_tx_offset"]


def as_tx_offset(value: Any, x: np.ndarray, y: np.ndarray) -> tuple[float, float, float] | None:
    """``value`` as ``(dx, dy, dz)`` metres, or None for no offset.

    Parameters
    ----------
    value : None or sequence of 2 or 3 float
        The offset, metres (two numbers: ``dz = 0``).
    x, y : ndarray
        The receiver's positions, metres: an offset longer than the aperture's
        diagonal (the span of ``x`` and ``y`` plus one pitch) is refused.

    Raises
    ------
    ValueError
        Not 2 or 3 finite numbers, or longer than the aperture.

    Examples
    --------
    >>> x = np.arange(12) * 0.018
    >>> as_tx_offset((0.12, 0), x, x)
    (0.12, 0.0, 0.0)
    >>> as_tx_offset((0, 0, 0), x, x) is None
    True
    """
    if value is None:
        return None
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape not in ((2,), (3,)) or not np.all(np.isfinite(arr)):
        raise ValueError(f"tx_offset must be (dx, dy) or (dx, dy, dz), finite metres, got "
                         f"{value!r}")
    d = np.zeros(3)
    d[:arr.size] = arr
    if not np.any(d):
        return None
    span = np.hypot(*(_extent(a) for a in (x, y)))
    length = float(np.linalg.norm(d))
    if length > span:
        raise ValueError(f"tx_offset {tuple(d.tolist())} m is {length:.4g} m long, longer "
                         f"than the aperture's diagonal ({span:.4g} m): give metres (not "
                         "millimetres), the transmitter's offset from the receiver")
    return (float(d[0]), float(d[1]), float(d[2]))


def _extent(a: np.ndarray) -> float:
    a = np.asarray(a, dtype=float)
    if a.size < 2:
        return 0.0
    return float(a[-1] - a[0]) * a.size / (a.size - 1)


def refuse_tx_offset(hologram: Any, what: str) -> None:
    """Raise where ``what`` has no model of a transmitter beside the receiver.

    Raises
    ------
    ValueError
        ``hologram.tx_offset`` is set.
    """
    offset = getattr(hologram, "tx_offset", None)
    if offset is not None:
        raise ValueError(f"{what} has no model of a transmitter offset from the receiver "
                         f"(hologram.tx_offset = {offset} m); image it with migrate, "
                         "migration_operator or invert, which model it exactly")
