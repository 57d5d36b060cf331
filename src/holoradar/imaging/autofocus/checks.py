"""The checks of :func:`~holoradar.autofocus`'s arguments: each refused by name."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ...data.hologram import Hologram
from ...physics.medium import Medium

__all__ = ["check_confidence", "check_fit", "check_glare", "check_hologram",
           "check_line_radius", "check_range", "check_target", "medium_factory"]


def check_hologram(hologram: Any) -> None:
    """One frame of a :class:`~holoradar.Hologram`, not all zero."""
    if not isinstance(hologram, Hologram):
        raise ValueError(f"hologram must be a holoradar.Hologram, got {type(hologram).__name__}")
    if hologram.data.ndim != (3 if hologram.is_wideband else 2):
        raise ValueError("hologram: autofocus takes one frame (data (ny, nx) or (nf, ny, nx)), "
                         f"got data of shape {hologram.data.shape}; pass one frame at a time")
    if not np.any(hologram.data):
        raise ValueError("hologram: every sample is zero; there is nothing to focus")


def check_range(eps_range: Any) -> tuple[float, float]:
    """``eps_range`` as (min, max) floats with ``1 <= min < max``."""
    try:
        lo, hi = (float(v) for v in eps_range)
    except (TypeError, ValueError):
        raise ValueError(f"eps_range must be (min, max) real permittivities, got "
                         f"{eps_range!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 1 <= lo < hi):
        raise ValueError(f"eps_range must satisfy 1 <= min < max (real eps'), got {eps_range!r}")
    return lo, hi


def medium_factory(model: Any, lo: float, hi: float) -> Callable[[float], Medium]:
    """``medium_model`` as a checked function eps' -> Medium.

    A half-space Medium keeps its surface range and its loss tangent ``eps''/eps'``; a
    function must return a Medium with a ground, its surface at one range for ``lo``
    and ``hi`` alike.
    """
    if isinstance(model, Medium):
        if model.n_regions != 2:
            raise ValueError("medium_model: a Medium must be a half-space (its ground's eps' is "
                             f"what autofocus finds); this one has {model.n_regions - 1} ground "
                             "layers: pass a function eps' -> Medium that says which one varies")
        z0, e = model.z_interfaces[0], complex(model.eps[1])
        tan = e.imag / e.real if e.real > 0 else 0.0

        def make(eps: float) -> Medium:
            return Medium((z0,), (1.0, complex(eps, eps * tan)), model.polarization)

        return make
    if not callable(model):
        raise ValueError("medium_model must be a half-space Medium or a function eps' -> Medium, "
                         f"got {type(model).__name__}")

    def checked(eps: float) -> Medium:
        m = model(eps)
        if not isinstance(m, Medium) or m.is_free_space:
            raise ValueError(f"medium_model({eps:g}) must return a Medium with a ground, got "
                             f"{m!r}")
        return m

    surfaces = {checked(lo).z_interfaces[0], checked(hi).z_interfaces[0]}
    if len(surfaces) != 1:
        raise ValueError("medium_model must keep the ground surface at one range for every eps' "
                         f"(got {sorted(surfaces)} m)")
    return checked


def check_glare(glare: Any) -> tuple[float, float]:
    """An estimate made elsewhere, ``glare = (eps', sigma)``, as floats."""
    try:
        g, s = (float(v) for v in glare)
    except (TypeError, ValueError):
        raise ValueError("glare must be True, None, or (eps', sigma) of an independent "
                         f"estimate, got {glare!r}") from None
    if not (np.isfinite(g) and g >= 1 and np.isfinite(s) and s > 0):
        raise ValueError(f"glare = (eps', sigma) needs eps' >= 1 and sigma > 0, got {glare!r}")
    return g, s


def check_confidence(confidence: Any) -> float:
    """``confidence`` as a float strictly between 0 and 1."""
    confidence = float(confidence)
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must lie between 0 and 1 (e.g. 0.95), got {confidence}")
    return confidence


def check_fit(fit: Any) -> None:
    """``fit`` is ``"phase"`` or ``"field"``."""
    if fit not in ("phase", "field"):
        raise ValueError(f"fit must be 'phase' or 'field', got {fit!r}")


def check_target(target: Any) -> None:
    """``target`` is ``"point"``, ``"line"`` or ``"sphere"``."""
    if target not in ("point", "line", "sphere"):
        raise ValueError(f"target must be 'point' (a compact object), 'line' (rebar, pipe) or "
                         f"'sphere' (a conducting ball), got {target!r}")


def check_line_radius(line_radius: Any) -> float:
    """A line's radius in metres, > 0."""
    try:
        r = float(line_radius) if np.isscalar(line_radius) else np.nan
    except (TypeError, ValueError):
        r = np.nan
    if not (np.isfinite(r) and r > 0):
        raise ValueError(f"line_radius must be the bar's radius in metres (> 0), got "
                         f"{line_radius!r}")
    return r
