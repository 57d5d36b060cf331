"""A perfectly conducting ground (a metal plate, ``PEC_EPS``): the glare is the source's
mirror image in closed form, and what would need a field inside or below the conductor
is refused with a message.

Tolerance. ``PEC_EPS`` departs from a perfect conductor by ``|1 + r| <= 2/|n|`` (about
2e-15, holoradar.physics.conductor); the closed forms of the code and of the test then
differ by rounding only: the mirror distance R' computed two ways differs by a few
units in the last place, which moves the phase ``k R'`` by ``k R' * eps`` per ulp. Each
element is asserted to ``2/|n| + 16 k R'_max eps`` relative (a margin of 16 ulps).
"""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from holoradar.physics.conductor import PEC_EPS
from holoradar.physics.dyadic import free_space_dyadic

F = 9.9e9
K = 2 * np.pi * F / hr.C0
PLATE = 0.30
SRC = np.array([0.01, -0.03, 0.05])
IMAGE = np.array([SRC[0], SRC[1], 2 * PLATE - SRC[2]])
AP = hr.Aperture.grid(8, 0.02)
N_PEC = abs(np.sqrt(PEC_EPS))


def _tol(r_max: float) -> float:
    return 2 / N_PEC + 16 * K * r_max * np.finfo(float).eps


def _rel(got: np.ndarray, want: np.ndarray) -> float:
    return float(np.max(np.abs(got - want) / np.abs(want)))


def test_a_metal_plate_glares_as_the_mirror_image_of_a_point_source():
    pec = hr.Medium.half_space(PLATE, PEC_EPS)
    h = hr.simulate(hr.Scene(pec, hr.PointSource(SRC), []), AP, F)
    # Reflection -1 at every angle: -exp(i k R')/R' from the image at range 2 z0 - z_s.
    r = np.linalg.norm(AP.points - IMAGE, axis=1)
    assert _rel(h.data.ravel(), -np.exp(1j * K * r) / r) < _tol(r.max())
    # Scanned transceivers: each sees its own image at twice the plate's range.
    mono = hr.simulate(hr.Scene(pec, hr.PointSource((0, 0, 0)), []), AP, F, monostatic=True)
    d = 2 * PLATE
    assert _rel(mono.data, np.full(mono.shape, -np.exp(1j * K * d) / d)) < _tol(d)


@pytest.mark.parametrize("vector", [False, True])
def test_a_metal_plate_glares_as_the_mirror_image_of_a_dipole(vector):
    pec = hr.Medium.half_space(PLATE, PEC_EPS)
    p = np.array([0.3, 1.0, 0.4j])
    dip = hr.Dipole(SRC, moment=p)
    pol = np.array([0.0, 1.0, 0.0])
    ap = hr.Aperture.grid(8, 0.02, polarization=pol if vector else None)
    h = hr.simulate(hr.Scene(pec, dip, []), ap, F)
    # R_h = R_v = -1 (tangential E reversed; the magnetic-field r_p = +1): the image
    # dipole has its horizontal moment reversed and its vertical one kept.
    E = free_space_dyadic(K, IMAGE, ap.points) @ (p * [-1, -1, 1])
    want = E @ (pol if vector else dip.polarization)
    r = np.linalg.norm(ap.points - IMAGE, axis=1)
    assert _rel(h.data.ravel(), want) < _tol(r.max())


def test_fields_inside_or_below_a_perfect_conductor_are_refused_clearly():
    pec = hr.Medium.half_space(PLATE, PEC_EPS)
    target = [hr.PointTarget((0.0, 0.0, 0.4))]
    for src, pol in ((hr.PointSource(SRC), None), (hr.Dipole(SRC, moment=(0, 1, 0)), (0, 1, 0))):
        with pytest.raises(ValueError, match=r"perfect conductor.*targets must lie above it"):
            hr.simulate(hr.Scene(pec, src, target), hr.Aperture.grid(8, 0.02, polarization=pol),
                        F)
    under = hr.Medium.layered([PLATE, 0.35], [2.5, PEC_EPS])  # sand on a metal sheet
    with pytest.raises(ValueError, match="region 2 of the ground is a perfect conductor"):
        hr.simulate(hr.Scene(under, hr.PointSource(SRC), []), AP, F)
    # A target in the air above the plate is lit and seen directly, and its echo too.
    above = hr.Scene(pec, hr.PointSource(SRC), [hr.PointTarget((0.0, 0.0, 0.2))])
    assert np.all(np.isfinite(hr.simulate(above, AP, F).data))
