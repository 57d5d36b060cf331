"""Pieces the glare fits share: the radiator's direct wave and linear least squares.

``_direct_wave`` is also imported by :mod:`holoradar.imaging.stream`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...physics.medium import Medium
from ...physics.sources import GaussianBeam, PointSource


def _direct_wave(src: PointSource | GaussianBeam, k: float, pts: np.ndarray) -> np.ndarray:
    """The radiator's own wave at air points, for unit amplitude: ``exp(ikR)/R`` times its
    pattern along the straight ray, or the incoming Gaussian beam (the shape the
    direct-wave fit scales)."""
    return replace(src, amplitude=1.0).field(k, Medium.free_space(), pts)


def _joint_direct(h: np.ndarray, glare: np.ndarray, D: np.ndarray | None
                  ) -> tuple[complex | None, np.ndarray, np.ndarray]:
    """Fit the direct wave's amplitude to what the glare leaves."""
    if D is None:
        return None, glare, np.zeros_like(h)
    rest = h - glare
    d = complex(np.vdot(D, rest) / np.vdot(D, D))
    return d, glare, d * D


def _linear_fit(h: np.ndarray, basis: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares complex coefficients of ``basis`` columns; returns (coef, model)."""
    B = np.stack(basis, axis=1)
    coef, *_ = np.linalg.lstsq(B, h, rcond=None)
    return coef, B @ coef
