"""``hr.invert``: reflectivity by inverting the migration operator, checked on scenes
simulated with the vector model (dipoles induced in each target by a polarised source,
the elements recording E_y), which the inversion's operator (the scalar point unit
with the recorded component's dipole factor) did not make.

Bounds: a quarter of the resolution cell for positions (lateral ``lambda L / A``; in
range, one frequency's depth response ``4.97 lambda (L / A)^2``); the sidelobe floor
-30 dB; equal objects' reflectivities within 2 dB; the discrepancy stop's residual
within 10 % of the noise's norm.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.ndimage import maximum_filter

import holoradar as hr

F0 = 9.9e9
LAM = hr.C0 / F0
Y = (0, 1, 0)


def _peaks(img: hr.Image, floor: float = 0.3) -> list[tuple[float, float]]:
    """Local maxima of one plane above ``floor`` of the largest, (x, y) metres."""
    a = np.abs(img.data if img.data.ndim == 2 else img.data[0])
    keep = (a == maximum_filter(a, 3)) & (a > floor * a.max())
    iy, ix = np.nonzero(keep)
    return [(float(img.x[j]), float(img.y[i])) for i, j in zip(iy, ix, strict=True)]


def _array(n: int = 32, pitch: float = 0.0125, **kw) -> hr.Aperture:
    return hr.Aperture.grid(n, pitch, polarization=Y, **kw)


@pytest.fixture(scope="module")
def two_points():
    z, aperture = 0.4, 32 * 0.0125
    cell = LAM * z / aperture                  # Rayleigh spacing, 3.0 cm
    sep = 0.6 * cell
    targets = [hr.PointTarget((-sep / 2, 0.0, z)), hr.PointTarget((sep / 2, 0.0, z))]
    h = hr.simulate(hr.Scene(hr.Medium.free_space(), hr.PlaneWave(polarization=Y), targets),
                    _array(), F0, snr_db=30, seed=1)
    return h, z, cell, sep


def test_two_points_closer_than_the_rayleigh_spacing_are_resolved(two_points):
    h, z, cell, sep = two_points
    img = hr.migrate(h, z, upsample=2)
    assert len(_peaks(img)) == 1                           # the adjoint: one blob
    r = hr.invert(h, z, method="sparse", upsample=2, progress=False)
    found = sorted(_peaks(r))
    assert len(found) == 2
    for (x, y), x_true in zip(found, (-sep / 2, sep / 2), strict=True):
        assert abs(x - x_true) < cell / 4 and abs(y) < cell / 4


def test_a_points_reflectivity_has_no_sidelobes(two_points):
    # One point: outside its cell the adjoint keeps the aperture's sidelobes (-13 dB);
    # the sparse reflectivity nothing above -30 dB.
    _h, z, cell, _ = two_points
    one = hr.simulate(hr.Scene(hr.Medium.free_space(), hr.PlaneWave(polarization=Y),
                               [hr.PointTarget((0.003, -0.002, z))]), _array(), F0,
                      snr_db=30, seed=2)
    for how, bound in (("adjoint", -20.0), ("sparse", -30.0)):
        img = hr.migrate(one, z, upsample=2) if how == "adjoint" else \
            hr.invert(one, z, method="sparse", upsample=2, progress=False)
        a = np.abs(img.data)
        X, Y_ = np.meshgrid(img.x, img.y)
        outside = np.hypot(X - 0.003, Y_ + 0.002) > cell
        level = 20 * np.log10(a[outside].max() / a.max())
        assert (level > bound) if how == "adjoint" else (level < bound), (how, level)


@pytest.mark.slow   # test_detect_inversion's three bars beside a dipole cover it quickly
def test_equal_bars_under_a_dipole_beside_the_array_are_equal():
    # Three equal bars 6 cm under a concrete surface, along the dipole that lights
    # them from 25 cm beside the array: the adjoint image falls by the illumination
    # across them; the reflectivity divides it out.
    concrete = hr.Medium.half_space(0.20, 6.0 + 0.3j)
    dipole = hr.Dipole((-0.25, 0.0, 0.05), Y)
    bars = [hr.LineTarget((xb, -0.15, 0.25), (xb, 0.15, 0.25), radius=0.006)
            for xb in (-0.12, 0.0, 0.12)]
    h = hr.simulate(hr.Scene(concrete, dipole, bars), _array(41, 0.01),
                    np.linspace(8e9, 12e9, 5), include_surface=False, snr_db=30, seed=3)
    zs = np.arange(0.22, 0.29, 0.01)

    def levels(img: hr.Image) -> np.ndarray:
        a = np.abs(img.data)
        v = [a[:, np.abs(img.y) < 0.1][:, :, np.abs(img.x - xb) < 0.02].max()
             for xb in (-0.12, 0.0, 0.12)]
        return 20 * np.log10(np.array(v) / max(v))

    assert levels(hr.migrate(h, zs, medium=concrete)).min() < -6    # measured -11 dB
    r = hr.invert(h, zs, medium=concrete, progress=False)
    assert levels(r).min() > -2.0


def test_the_least_squares_stop_at_the_noise():
    h = hr.simulate(hr.Scene(hr.Medium.free_space(), hr.PlaneWave(polarization=Y),
                             [hr.PointTarget((0.01, 0.0, 0.4))]), _array(), F0, snr_db=30,
                    seed=5)
    sigma = np.sqrt(np.mean(np.abs(h.data) ** 2) / 1000)      # the 30 dB simulated
    r = hr.invert(h, [0.38, 0.40], noise=sigma, progress=False)
    step = r.history[0]
    assert step["stop"].startswith("the residual reached the noise")
    assert 0.9 < step["residual_over_noise"] <= 1.0
    assert r.method == "invert:lsqr" and step["unit"].startswith("Born")


@pytest.mark.parametrize("tilted", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_one_frequency_point_within_a_quarter_cell(tilted):
    # A point 10-12 cm deep in sand, one frequency: under a level array 50 cm above the
    # sand (the adjoint's maximum lies 9 cm short), and under a 35-degree array (the
    # adjoint's maximum 7 cm short along its line of sight). The planes reach 10 cm past
    # the point on either side: the brightest voxel is the reflectivity's, not an edge's
    # (measured: 0 and 1 cm in range, 0.4 and 0.5 cm across).
    if tilted:
        sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
        truth = np.array([0.0, 0.05, 0.42])
        ap = hr.Aperture.grid(24, 0.0125, polarization=(1, 0, 0), pose=hr.Pose(
            (0.0, -0.15, 0.05), tilt=np.radians(35), azimuth=np.radians(90)))
        src, size = hr.PlaneWave(polarization=(1, 0, 0)), 0.30
        grid = {"frame": "ground", "x": np.arange(-0.04, 0.0401, 0.005),
                "y": np.arange(0.01, 0.0901, 0.005)}
        zs = np.arange(0.34, 0.55, 0.01)
    else:
        sand = hr.Medium.half_space(0.50, 2.5 + 0.0125j)
        truth = np.array([0.01, -0.005, 0.60])
        ap, src, size = _array(), hr.PlaneWave(polarization=Y), 0.40
        grid = {"upsample": 1}
        zs = np.arange(0.50, 0.71, 0.01)
    h = hr.simulate(hr.Scene(sand, src, [hr.PointTarget(tuple(truth))]), ap, F0,
                    include_surface=False, snr_db=30, seed=4)
    L = sand.apparent_distance(truth[2])
    lateral, depth = LAM * L / size, 4.97 * LAM * (L / size) ** 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        r = hr.invert(h, zs, medium=sand, method="sparse", progress=False, **grid)
    err = np.abs(np.array(r.peak()) - truth)
    assert err[0] < lateral / 4 and err[1] < lateral / 4 and err[2] < depth / 4, err


def test_bad_input_is_refused_with_its_name():
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))],
                             source=hr.PlaneWave()), hr.Aperture.grid(8, 0.01), F0)
    with pytest.raises(ValueError, match="method must be 'lsqr' or 'sparse'"):
        hr.invert(h, 0.3, method="sparce")
    with pytest.raises(ValueError, match="noise must be the receiver noise"):
        hr.invert(h, 0.3, noise=-1.0)
    with pytest.raises(ValueError, match=r"hologram\.source is needed"):
        hr.invert(h.replace(source=None), 0.3)
    with pytest.raises(ValueError, match="max_iter must be a positive integer"):
        hr.invert(h, 0.3, max_iter=0)
    with pytest.raises(ValueError, match="one frame"):
        hr.invert(h.with_data(np.stack([h.data, h.data])), 0.3)


def test_a_grid_too_large_for_memory_is_refused_before_any_work(monkeypatch):
    # The solver's vectors are counted against the memory available before a step: the
    # refusal names the grid's size and the ways out.
    from holoradar.imaging.inversion import api

    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))],
                             source=hr.PlaneWave()), hr.Aperture.grid(8, 0.01), F0)
    monkeypatch.setattr(api, "available_memory", lambda: 1 << 16)
    calls = []
    monkeypatch.setattr(api, "column_norms", lambda *a, **k: calls.append(1))
    with pytest.raises(MemoryError, match=r"voxels needs about .* GiB.*fewer planes"):
        hr.invert(h, np.linspace(0.2, 0.4, 30), upsample=4)
    assert not calls
