"""The paper's device and scenes (Popov et al., Remote Sensing 2022)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.scene import Aperture, Scene
from ..model.targets import PlanarTarget
from ..physics.medium import Medium, permittivity
from ..physics.sources import PointSource

__all__ = ["PAPER_FREQUENCY", "SAND_EPS", "LabStand", "lab_stand"]

PAPER_FREQUENCY = 9.9e9
"""Operating frequency of the paper's device, Hz."""

SAND_EPS = permittivity(2.5, 0.005)
"""Dry sand of the lab stand: eps' = 2.5, tan_delta = 0.005."""


@dataclass(frozen=True)
class LabStand:
    """A ready-made scene with its array and frequency (see :func:`lab_stand`)."""

    scene: Scene
    aperture: Aperture
    frequency: float
    z_surface: float
    z_object: float
    target: PlanarTarget


def lab_stand(*, depth: float = 0.12, z_surface: float = 0.30,
              horn_position: tuple[float, float, float] = (0.0, -0.25, 0.0),
              horn_pattern: float = 2.0) -> LabStand:
    """The paper's lab stand: letter-R stencil in sand under the 16 x 16 array.

    16 x 16 receivers at 2.5 cm (40 cm square), 9.9 GHz; sand eps' = 2.5,
    tan_delta = 0.005 with its surface 30 cm from the array; a 10 x 15 cm metal
    letter R (reflection -1) 12 cm deep; a horn beside the array (default
    25 cm off its centre along -y, in the aperture plane) aimed at the stencil,
    with a ``cos^2`` amplitude pattern.

    Examples
    --------
    >>> stand = lab_stand()
    >>> stand.z_object
    0.42
    """
    z_obj = round(z_surface + depth, 12)
    target = PlanarTarget.from_shape("letter_r", z_obj, reflection=-1.0, width=0.10,
                                     height=0.15)
    pos = np.asarray(horn_position, float)
    axis = np.array([0.0, 0.0, z_obj]) - pos
    horn = PointSource(pos, pattern_exponent=horn_pattern, axis=axis)
    scene = Scene(Medium.half_space(z_surface, SAND_EPS), horn, [target])
    return LabStand(scene, Aperture.paper(), PAPER_FREQUENCY, z_surface, z_obj, target)
