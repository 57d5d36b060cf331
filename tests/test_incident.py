"""The unit incident phasors of several sources that multi-view synthesis removes."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import F0
from holoradar.physics.incident import (
    incident_on_planes,
    incident_phasors,
    remove_incident_phase,
)
from holoradar.physics.medium import Medium
from holoradar.physics.sources import GaussianBeam, PlaneWave, PointSource

K = 2 * np.pi * F0 / 299_792_458.0


def _unit(e: np.ndarray) -> np.ndarray:
    mag = np.abs(e)
    return np.divide(e.conj(), mag, out=np.zeros_like(e), where=mag > 0)


@pytest.mark.parametrize("medium", [Medium.half_space(0.3, 2.5 + 0.05j),
                                    Medium.layered([0.3, 0.36], [4.0 + 0.2j, 2.5])])
def test_shared_quadrature_equals_each_sources_own(medium):
    # Sources at two heights (two shared quadratures), a tilted horn, a dipole whose
    # pattern vanishes along its wire, a plane wave and a Gaussian beam (direct path).
    # Both paths evaluate the same Sommerfeld integral on the same radial nodes
    # (lambda/16 apart from rho = 0); the shared rule is only sized for the longest
    # radial grid of its group. That rule is converged to 1e-8 relative (test_green), so
    # the unit phasors agree to 1e-6, well below what a wrong sign or a missing conjugate
    # would leave (order 1).
    srcs = [PointSource((0.0, -0.2, 0.0), pattern_exponent=4, axis=(0.0, 0.3, 1.0)),
            PointSource((0.15, 0.1, 0.0), amplitude=-2j),
            PointSource((0.0, 0.0, 0.05), axis=(0.0, 1.0, 0.0), dipole=True),
            PlaneWave(0.2, 0.0), GaussianBeam(0.1)]
    xs = np.linspace(-0.2, 0.2, 41)
    zs = np.array([0.32, 0.4, 0.45])
    u = incident_phasors(srcs, K, medium, xs, xs, zs)
    assert u.shape == (len(srcs), zs.size, xs.size, xs.size)
    for i, s in enumerate(srcs):
        ref = _unit(incident_on_planes(s, K, medium, xs, xs, zs))
        assert np.max(np.abs(u[i] - ref)) < 1e-6, i
    # In place, plane by plane: the same phasors.
    images = np.ones_like(u)
    remove_incident_phase(images, srcs, K, medium, xs, xs, zs)
    assert np.max(np.abs(images - u)) < 1e-12


def test_free_space_point_sources():
    srcs = [PointSource((0.05, 0.0, 0.0)), PointSource((-0.05, 0.02, -0.1), pattern_exponent=2)]
    xs = np.linspace(-0.1, 0.1, 11)
    u = incident_phasors(srcs, K, Medium.free_space(), xs, xs, np.array([0.3]))
    X, Y = np.meshgrid(xs, xs)
    R = np.hypot(np.hypot(X - 0.05, Y), 0.3)
    # exp(ikR)/R: the unit phasor is exp(-ikR) (closed form). The field is interpolated
    # linearly in phase on a radial grid dr = lambda/16 apart: the phase error is at most
    # dr^2/8 * max|d2(kR)/drho2| = dr^2/8 * k/z (at rho = 0), 3.1e-4 rad here.
    dr = 2 * np.pi / K / 16
    assert np.max(np.abs(u[0, 0] - np.exp(-1j * K * R))) < dr**2 / 8 * K / 0.3
