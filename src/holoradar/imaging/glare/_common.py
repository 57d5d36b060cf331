"""Pieces the glare fits share: the radiator's direct wave and linear least squares.

``direct_wave`` is also imported by :mod:`holoradar.imaging.stream`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...data.hologram import Hologram, has_polarization
from ...physics.dipole import Dipole
from ...physics.medium import Medium
from ...physics.sources import GaussianBeam, PointSource

Radiator = PointSource | GaussianBeam | Dipole


def recorded_polarization(hologram: Hologram, src: object) -> np.ndarray | None:
    """The recorded field component when the vector model applies, else None."""
    if hologram.polarization is not None and has_polarization(src):
        return np.asarray(hologram.polarization)
    return None


def direct_wave(src: Radiator, k: float, pts: np.ndarray,
                 pol: np.ndarray | None = None) -> np.ndarray:
    """The radiator's own wave at air points, for unit amplitude: ``exp(ikR)/R`` times its
    pattern along the straight ray, or the incoming Gaussian beam (the shape the
    direct-wave fit scales); with ``pol``, the component ``pol . E`` of its vector
    field."""
    unit = replace(src, amplitude=1.0)
    if pol is not None:
        return unit.field_vector(k, Medium.free_space(), pts) @ pol
    return unit.field(k, Medium.free_space(), pts)


def _require_direct_wave(D: np.ndarray, h: np.ndarray) -> None:
    """Refuse the direct wave as the glare's amplitude reference when the data hold
    almost none of it (it explains < 1% of their energy): the fitted amplitude would
    then be noise, and the glare's strength, hence eps, anything (a 1e6 was seen)."""
    h = np.ravel(h)
    share = abs(np.vdot(D, h)) ** 2 / max(np.vdot(D, D).real * np.vdot(h, h).real, 1e-300)
    if share < 0.01:
        raise ValueError("direct=True takes the radiator's direct wave as the amplitude "
                         "reference, but the hologram holds almost none of it (the direct "
                         "wave explains <1% of it): pass direct=False (holoradar suppress "
                         "--no-direct) with a calibrated source amplitude")


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
