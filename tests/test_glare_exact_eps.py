"""The Gaussian glare removal's eps from the exact glare fit (``exact_eps=True``).

The Gaussian beam's strength gives a rough eps (no uncertainty): the beam is an
approximation of the radiator's reflected field. With ``exact_eps`` the report's eps
and its 1-sigma are the exact image-source fit's of the same data (the same fit
:func:`holoradar.estimate_permittivity` runs), the cleaned hologram unchanged.
"""

import numpy as np
import pytest

import holoradar as hr


@pytest.fixture(scope="module")
def glare():
    # A point radiator 5 cm over sand (eps 2.5, tan delta 0.005), its glare and a
    # buried point; no direct wave in the data (the reference is the source's own).
    sand = hr.Medium.half_space(0.30, 2.5 * (1 + 0.005j))
    horn = hr.PointSource((0.0, -0.03, -0.05))
    scene = hr.Scene(sand, horn, [hr.PointTarget((0.04, 0.0, 0.42), 0.02)])
    return hr.simulate(scene, hr.Aperture.grid(32, 0.0125), 9.9e9), sand


def test_exact_eps_is_the_image_source_fit_and_leaves_the_cleaning_alone(glare):
    h, _ = glare
    start = hr.Medium.half_space(0.30, 3.0)     # a wrong starting guess
    rough_clean, rough = hr.suppress_surface(h, start, direct=False)
    clean, rep = hr.suppress_surface(h, start, direct=False, exact_eps=True)
    _, exact = hr.suppress_surface(h, start, method="image_source", direct=False)
    assert rough.eps_std is None and rep.eps_std is not None
    assert rep.parameters["eps_gaussian"] == rough.eps
    # The same fit on the same data: equal to its own convergence (the optimizer's
    # relative tolerance, far below sigma).
    assert rep.eps == pytest.approx(exact.eps, rel=1e-6)
    np.testing.assert_array_equal(clean.data, rough_clean.data)
    # The exact model made these data (free of noise): eps' within 3 sigma of the truth.
    assert abs(rep.eps.real - 2.5) < 3 * rep.eps_std[0]
