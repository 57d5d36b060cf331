"""The profile-likelihood interval of eps': its level, and where the focus falls to it.

The interval holds the eps' whose residual exceeds the best one's by at most
``(q s sqrt(phi) + sqrt(E_err))^2`` (the package's notes): in focus-fraction units a
drop of that over ``||h||^2`` from the best focus fraction. Its ends are where the
best focus fraction at each eps' crosses that level, on either side of the best.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..._lazy import lazy_module

if TYPE_CHECKING:
    from .search import Search

# The quantile comes from scipy.special, not scipy.stats, whose import alone (0.4 s)
# would double a first single-frequency search.
_opt = lazy_module("scipy.optimize")
_special = lazy_module("scipy.special")

__all__ = ["crossing", "focus_drop", "quantile"]


def quantile(confidence: float) -> float:
    """The normal quantile of a two-sided ``confidence`` (1.96 for 0.95).

    Examples
    --------
    >>> round(quantile(0.95), 4)
    1.96
    """
    return float(_special.ndtri(0.5 + confidence / 2))


def focus_drop(stats: dict[str, float], q: float, energy: float) -> float:
    """The interval's depth below the best focus fraction (dimensionless).

    Parameters
    ----------
    stats : dict
        :func:`~.fit_statistics.fit_statistics` at the optimum: ``s2``, ``phi``,
        ``model_error``, ``unmodelled`` and ``residual_scale``.
    q : float
        The normal quantile of the confidence (:func:`quantile`).
    energy : float
        The hologram's energy ``||h||^2``.

    Returns
    -------
    float
        ``(q s sqrt(phi) + sqrt(E_err) + sqrt(E_out))^2 / (residual_scale ||h||^2)``.
    """
    # The statistical part (noise, q s sqrt(phi)) and a bound on the bias a smooth model
    # error of energy E_err can cause, were it aligned with the change of eps' (profile
    # residual rises as ||d||^2 delta^2, the bias is at most sqrt(E_err)/||d||): the
    # deviations add, so their square roots do. E_out: what the model knowingly leaves
    # out, bounded the same way; the residual does not show the part of a model error
    # that lies along the change of eps' (the fit absorbs it), so it is added here.
    return (q * np.sqrt(stats["s2"] * stats["phi"]) + np.sqrt(stats["model_error"])
            + np.sqrt(stats.get("unmodelled", 0.0))) ** 2 / (stats["residual_scale"] * energy)


def crossing(search: Search, e_hat: float, level: float, side: int) -> float | None:
    """eps' on ``side`` of ``e_hat`` where the best focus fraction falls to ``level``.

    Parameters
    ----------
    search : Search
        The search, with the trials made so far (more are made here).
    e_hat : float
        The best eps'.
    level : float
        The focus fraction at the interval's end.
    side : {-1, 1}
        Below (-1) or above (1) ``e_hat``.

    Returns
    -------
    float or None
        The crossing (relative tolerance 1e-3), or ``None`` when the focus fraction at
        the edge of the eps' range searched is still above ``level``.
    """
    inside = e_hat
    for e in sorted(search.best, reverse=side < 0):
        if (e - e_hat) * side > 0 and search.best[e][0] < level:
            outside = e
            break
        if (e - e_hat) * side > 0:
            inside = e
    else:
        edge = search.lo if side < 0 else search.hi
        if search.evaluate(edge)[0] >= level:
            return None
        outside = edge

    def f(e: float) -> float:
        return search.evaluate(float(e))[0] - level

    return float(_opt.brentq(f, inside, outside, rtol=1e-3))
