"""The ground's permittivity from the glare: :func:`estimate_permittivity`."""

from __future__ import annotations

from typing import Any

from ...data.hologram import Hologram
from ...physics.dipole import Dipole
from ...physics.medium import Medium
from ...physics.sources import GaussianBeam, PointSource
from ._common import _require_direct_wave, direct_wave, recorded_polarization
from .suppress import suppress_surface

__all__ = ["estimate_permittivity"]


def estimate_permittivity(hologram: Hologram, medium: Medium, source: Any = None, *,
                          direct: bool = True) -> tuple[complex, tuple[float, float]]:
    """Permittivity of the ground's top layer from the glare, with its 1-sigma uncertainty.

    Fits the exact reflected field of the radiator (``method="image_source"``).
    The glare's strength against the radiator's fixes |V| and hence eps: the
    radiator's amplitude is the direct wave's, fitted jointly (``direct=True``,
    the direct-path reference; it must be in the data), or ``source.amplitude``
    (``direct=False``, a calibration). ``medium`` supplies the geometry and the
    starting value. When the hologram records a ``polarization`` and the source
    has one (a :class:`~holoradar.Dipole`, a polarised horn or beam), the glare
    and the direct wave are the vector fields, TE and TM waves each reflected
    with their own law; otherwise the scalar (TE) model. The 1-sigma covers
    receiver noise and diffuse clutter (a sandwich estimate) plus, through
    ``b/1.96``, the largest shift ``b`` that the residual's smooth part (model
    error: a scalar model of a vector source, a layered ground seen as a
    half-space, a buried object under the glare) could cause; a white residual
    adds nothing. The noise-only sigma and ``b`` are in the
    ``suppress_surface(..., "image_source")`` report's ``parameters``.

    Examples
    --------
    >>> import holoradar as hr
    >>> m = hr.Medium.half_space(0.3, 4.0)
    >>> h = hr.simulate(hr.Scene(m, hr.PointSource((0.0, 0.0, -0.05))),
    ...                 hr.Aperture.grid(24, 0.015), 9.9e9, include_direct=True)
    >>> eps, std = estimate_permittivity(h, hr.Medium.half_space(0.3, 3.0))
    >>> round(eps.real, 2)
    4.0
    """
    src = source if source is not None else getattr(hologram, "source", None)
    if direct and isinstance(src, PointSource | GaussianBeam | Dipole):
        _require_direct_wave(direct_wave(src, hologram.k, hologram.points,
                                          recorded_polarization(hologram, src)), hologram.data)
    _, rep = suppress_surface(hologram, medium, source, "image_source", direct=direct)
    return rep.eps, rep.eps_std
