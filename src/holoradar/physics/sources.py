"""Illuminating sources: plane wave, point radiator (horn) and Gaussian beam.

Every source gives its incident field at arbitrary points of a layered medium
(:meth:`field`, the down-going wave, transmitted into the layers) and the
specular reflection of that field from the ground as seen in the air
(:meth:`reflected`, the surface glare). Positions are (x, y, z) in metres, z the
range from the aperture plane; time dependence ``exp(-i*omega*t)``.

The models live in a module each: :mod:`.plane_wave`, :mod:`.point_source` (with
:func:`ray_direction`) and :mod:`.gaussian_beam`; this module holds the
:class:`Source` protocol they satisfy and re-exports them.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from ._geometry import _points as _points
from .gaussian_beam import GaussianBeam
from .medium import Medium
from .plane_wave import PlaneWave
from .point_source import PointSource, ray_direction

__all__ = ["GaussianBeam", "PlaneWave", "PointSource", "Source", "ray_direction"]


class Source(Protocol):
    """What :func:`holoradar.simulate` and the imaging functions need of a source."""

    def field(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray: ...

    def reflected(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray: ...
