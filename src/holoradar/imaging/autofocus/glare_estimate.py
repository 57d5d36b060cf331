"""The glare's own estimate of eps', and its combination with the focus's.

The surface glare (the source's reflection from the ground) carries the top of the
ground's eps' (:func:`~holoradar.estimate_permittivity`). :func:`autofocus
<holoradar.autofocus>` measures it (``glare=True``: fitted, then removed from the
hologram) or takes one made elsewhere (``glare=(eps', sigma)``), and combines it
with the focus's estimate by inverse variance; where the focus gives no handle the
glare's estimate is the answer alone.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ...data.hologram import Hologram
from ...physics.medium import Medium
from .checks import check_glare
from .interval import quantile

__all__ = ["combine", "glare_alone", "glare_input"]


def glare_input(glare: Any, hologram: Hologram, medium_model: Any,
                make: Callable[[float], Medium], lo: float,
                hi: float) -> tuple[Hologram, tuple[float, float] | None]:
    """The hologram to focus and the glare's (eps', sigma), if any.

    Parameters
    ----------
    glare : bool or (float, float) or None
        ``autofocus``'s argument: ``True`` measures the glare (and removes it from the
        hologram), a pair is an estimate made elsewhere, ``None`` or ``False`` none.
    hologram : Hologram
    medium_model : Medium or callable
        ``autofocus``'s argument; a half-space Medium is the glare fit's start.
    make : callable
        eps' -> Medium (:func:`~.checks.medium_factory`), for the start otherwise (at
        the geometric middle of ``lo .. hi``).
    lo, hi : float
        The eps' range searched.

    Returns
    -------
    Hologram
        The hologram, without its glare for ``glare=True``.
    (float, float) or None
        The glare's eps' and its 1-sigma.
    """
    if glare is True:
        start = medium_model if isinstance(medium_model, Medium) else make(float(np.sqrt(lo * hi)))
        return _measure(hologram, start)
    if glare not in (None, False):
        return hologram, check_glare(glare)
    return hologram, None


def _measure(hologram: Hologram, medium: Medium) -> tuple[Hologram, tuple[float, float]]:
    from ..glare import suppress_surface

    if hologram.monostatic or hologram.source is None or hologram.is_wideband:
        raise ValueError("glare=True needs a single-frequency receiver-array hologram with its "
                         "source (the glare is the source's reflection); remove the glare "
                         "yourself and pass glare=(eps', sigma), or glare=None")
    clean, rep = suppress_surface(hologram, medium, None, "image_source")
    return clean, (float(rep.eps.real), float(rep.eps_std[0]))


def combine(e_f: float, interval: tuple[float, float], glare: tuple[float, float],
            q: float) -> tuple[float, tuple[float, float], str]:
    """The focus's and the glare's estimates combined by their inverse variances.

    Parameters
    ----------
    e_f : float
        The focus's eps'.
    interval : (float, float)
        Its interval; its 1-sigma is the half-width over ``q``.
    glare : (float, float)
        The glare's eps' and 1-sigma.
    q : float
        The normal quantile of the interval's confidence.

    Returns
    -------
    float
        The combined eps'.
    (float, float)
        Its interval (``+- q`` sigma).
    str
        How it was made; it says when the two disagree by 3 sigma or more.

    Examples
    --------
    >>> est, interval, note = combine(4.0, (3.8, 4.2), (4.1, 0.1), 2.0)
    >>> round(est, 3), note
    (4.05, 'focus and glare combined by inverse variance')
    """
    s_f = (interval[1] - interval[0]) / (2 * q)
    e_g, s_g = glare
    w_f, w_g = 1 / s_f**2, 1 / s_g**2
    est = (w_f * e_f + w_g * e_g) / (w_f + w_g)
    s = 1 / np.sqrt(w_f + w_g)
    gap = abs(e_f - e_g) / np.hypot(s_f, s_g)
    note = ("focus and glare combined by inverse variance" if gap < 3 else
            f"focus and glare combined, but they disagree by {gap:.1f} sigma: the glare sees the "
            "top of the ground, the focus the path down to the object (layered ground?)")
    return float(est), (float(est - q * s), float(est + q * s)), note


def glare_alone(glare: tuple[float, float], confidence: float,
                make: Callable[[float], Medium], reason: str) -> dict[str, Any]:
    """The result's fields when the focus gave no handle (``reason``): the glare's estimate.

    Examples
    --------
    >>> fields = glare_alone((3.8, 0.2), 0.95, lambda e: None, "no object")
    >>> fields["eps"], fields["reason"]
    (3.8, 'from the glare alone (the focus gave no handle: no object)')
    """
    g, s = glare
    q = quantile(confidence)
    return dict(eps=g, eps_interval=(g - q * s, g + q * s), determinable=True,
                reason=f"from the glare alone (the focus gave no handle: {reason})",
                medium=make(g))
