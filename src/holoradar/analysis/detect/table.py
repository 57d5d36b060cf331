"""The objects' table: columns, depths and their intervals."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["COLUMNS", "as_eps_interval", "cramer_rao_factor", "depth_interval", "depth_of",
           "detection_row"]

COLUMNS = ["kind", "x", "y", "range", "depth", "depth_low", "depth_high", "length", "width",
           "azimuth_deg", "amplitude_db", "snr_db", "x_std", "y_std", "range_std",
           "x_start", "y_start", "x_end", "y_end", "spacing", "model_error_db", "area"]
"""Columns of :func:`holoradar.detect`'s table, in order."""

Z95 = 1.959963984540054  # two-sided 95 % of a normal distribution


def as_eps_interval(eps_interval: Any) -> tuple[float, float] | None:
    """``(low, high)`` real permittivities from a pair or an ``AutofocusResult``.

    Raises
    ------
    ValueError
        Not two finite numbers >= 1 with low <= high.

    Examples
    --------
    >>> as_eps_interval((4.5, 3.5))
    Traceback (most recent call last):
    ...
    ValueError: eps_interval must be (low, high) with low <= high, got (4.5, 3.5)
    """
    if eps_interval is None:
        return None
    if hasattr(eps_interval, "eps_interval") and not isinstance(eps_interval, tuple | list):
        value = eps_interval.eps_interval
        if value is None:
            raise ValueError("eps_interval: the AutofocusResult has no interval "
                             f"({getattr(eps_interval, 'reason', 'not determinable')})")
        eps_interval = value
    try:
        lo, hi = (float(np.real(complex(v))) for v in eps_interval)
    except (TypeError, ValueError):
        raise ValueError("eps_interval must be (low, high): two real relative permittivities "
                         f">= 1 (or an AutofocusResult), got {eps_interval!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi)) or lo < 1:
        raise ValueError("eps_interval must be (low, high): two finite relative permittivities "
                         f">= 1, got {eps_interval!r}")
    if lo > hi:
        raise ValueError("eps_interval must be (low, high) with low <= high, got "
                         f"{eps_interval!r}")
    return lo, hi


def depth_interval(depth: float, range_std: float, eps: float,
                   eps_interval: tuple[float, float] | None, wideband: bool
                   ) -> tuple[float, float]:
    """Depth bounds: the range's 95 % interval, widened by the permittivity's.

    An image focused through a ground of real permittivity ``eps`` puts a point at
    depth ``d``. With another ``eps'`` the same data put it elsewhere: at one
    frequency the wave front's curvature fixes the apparent depth ``d/n``
    (paraxial), so ``d' = d sqrt(eps'/eps)``; across a band the two-way delay
    fixes ``n d``, so ``d' = d sqrt(eps/eps')``. The bounds are the extremes over
    the interval's ends, each widened by ``1.96`` range standard deviations. A range
    that was not fitted (``range_std`` NaN: an object found on one plane without the
    hologram) gives NaN bounds: the depth is then unknown within the focus's length.

    Examples
    --------
    >>> [round(v, 4) for v in depth_interval(0.10, 0.0, 4.0, (3.0, 5.0), False)]
    [0.0866, 0.1118]
    >>> [round(v, 4) for v in depth_interval(0.10, 0.0, 4.0, (3.0, 5.0), True)]
    [0.0894, 0.1155]
    >>> depth_interval(0.10, float("nan"), 4.0, None, False)
    (nan, nan)
    """
    if not np.isfinite(range_std):
        # The range was not fitted (an object found on one plane of the image alone):
        # one frequency's focus is tens of centimetres long, so the depth is unknown
        # within it, not exact. Say so rather than state a zero-width interval.
        return float("nan"), float("nan")
    s = Z95 * range_std
    ends = [depth]
    if eps_interval is not None and eps > 0:
        for e in eps_interval:
            f = np.sqrt(eps / e) if wideband else np.sqrt(e / eps)
            ends.append(depth * f)
    return float(min(ends) - s), float(max(ends) + s)


def detection_row(kind: str, x: float, y: float, range_m: float, **columns: Any
                  ) -> dict[str, Any]:
    """One object's row: every column of :data:`COLUMNS` (NaN where not given), the
    one place a row is made.

    ``columns`` may also hold the extras some kinds carry (``outline``: an area's
    polygon; ``components``: how many pieces were joined).

    Examples
    --------
    >>> row = detection_row("point", 0.0, 0.1, 0.4, amplitude_db=-3.0)
    >>> row["kind"], row["amplitude_db"], bool(np.isnan(row["snr_db"])), len(row)
    ('point', -3.0, True, 22)
    """
    unknown = set(columns) - set(COLUMNS) - {"outline", "components"}
    if unknown:
        raise ValueError(f"not a column of the objects' table: {sorted(unknown)}")
    row: dict[str, Any] = dict.fromkeys(COLUMNS, np.nan)
    row.update(kind=kind, x=x, y=y, range=range_m, **columns)
    return row


def depth_of(range_m: float, range_std: float, medium: Any,
             interval: tuple[float, float] | None, wideband: bool
             ) -> tuple[float, float, float]:
    """``(depth, low, high)``: the depth below the ground's surface of an object at
    ``range_m`` and its bounds (:func:`depth_interval`, with the permittivity of the
    layer it lies in); NaN without a ground.

    Examples
    --------
    >>> import holoradar as hr
    >>> [round(v, 4) for v in depth_of(0.5, 0.0, hr.Medium.half_space(0.4, 4.0),
    ...                                (3.0, 5.0), False)]
    [0.1, 0.0866, 0.1118]
    """
    if medium is None or not medium.z_interfaces:
        return np.nan, np.nan, np.nan
    depth = range_m - float(medium.z_interfaces[0])
    eps = float(np.real(medium.eps[int(medium.region_of(range_m))]))
    lo, hi = depth_interval(depth, range_std, eps, interval, wideband)
    return depth, lo, hi


def cramer_rao_factor(snr: float) -> float:
    """``sqrt(3 / (2 SNR))``: a peak's position standard deviation in units of its
    response's width over pi (Cramer-Rao for a peak of mean-square spectral width
    ``beta^2 = mu^2 / 3``: ``1 / sqrt(2 SNR beta^2)``); infinite at SNR 0.

    Examples
    --------
    >>> round(cramer_rao_factor(150.0), 4)
    0.1
    """
    return math.sqrt(3 / (2 * snr)) if snr > 0 else math.inf
