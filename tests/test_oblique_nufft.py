"""The ground frame's spectrum by finufft against the direct factored sums and the plain
sum over the elements.

Tolerance: finufft is asked for a relative l2 error ``EPS`` (1e-6 in complex128, 1e-5
in complex64) on the components it sums, the ones that travel in the air; the
evanescent ones are summed directly, exact to rounding. The whole spectrum's relative
l2 error is therefore at most finufft's. ``EPS`` is a target, not a proven bound: its
documentation reports achieved errors within a small factor of it, so the bound here
is ``2 EPS``. The reference is computed in complex128 (its rounding, ~1e-15, is nil
against either bound).
"""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from holoradar.imaging.migration.backends import oblique_sum as oblique
from holoradar.imaging.migration.backends.oblique_nufft import EPS
from holoradar.imaging.migration.backends.oblique_sum import choose_route

F0 = 9.9e9


def _spectrum_on_plane(h: hr.Hologram, grid, pitch, origin, work, *, gap: float,
                       route: str = "auto") -> np.ndarray:
    """The ground frame's spectrum sum of every frame of ``h`` (its own wavenumber, the
    round trip's for a transceiver), shaped (..., My, Mx)."""
    kk = 2 * h.k if h.monostatic else h.k
    d = h.data.reshape(-1, *h.data.shape[-2:])
    H = oblique.sum_to_plane(h, d, kk, grid, pitch, origin, np.dtype(work), gap, route)
    return H.reshape((*h.data.shape[:-2], *grid))


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def _exact(h: hr.Hologram, grid, pitch, origin, kk: float) -> np.ndarray:
    """H(k) = sum_e d_e exp(-i [p (x_e - x0) + q (y_e - y0) + conj(kz) (z_ref - z_e)]),
    element by element, complex128 (the module docstring's definition)."""
    P, Q = np.meshgrid(2 * np.pi * np.fft.fftfreq(grid[1], pitch[0]),
                       2 * np.pi * np.fft.fftfreq(grid[0], pitch[1]))
    kz = np.sqrt((kk**2 - P**2 - Q**2).astype(complex))
    kz = np.where(kz.imag < 0, -kz, kz)
    d = h.data.astype(complex).reshape(-1, h.data.shape[-2] * h.data.shape[-1])
    out = np.zeros((d.shape[0], *grid), complex)
    for e, (px, py, pz) in enumerate(h.points):
        phase = np.exp(-1j * (P * (px - origin[0]) + Q * (py - origin[1])
                              + np.conj(kz) * (origin[2] - pz)))
        out += d[:, e, None, None] * phase
    return out.reshape((*h.data.shape[:-2], *grid))


@pytest.mark.parametrize("dtype", [np.complex128, np.complex64])
@pytest.mark.parametrize(("tilt", "azimuth", "mono"), [
    (35, 90, False),   # x' along x: by grid columns
    (35, 0, True),     # y' along y: by grid rows
    (35, 30, False),   # in full
    (0, 0, True),      # level: every component through finufft
])
def test_nufft_route_matches_the_direct_sums(tilt, azimuth, mono, dtype):
    # Two frames at once (the batch); a grid pitch of 5-6 mm reaches |k_t| = 800 rad/m,
    # beyond k (207) and 2k (415): components evanescent in the air are included (a 5 cm
    # air gap keeps them up to Im(kz) = 368 rad/m).
    rng = np.random.default_rng(7)
    x = (np.arange(10) - 4.5) * 0.015
    y = (np.arange(8) - 3.5) * 0.015
    d = (rng.standard_normal((2, 8, 10)) + 1j * rng.standard_normal((2, 8, 10)))
    pose = hr.Pose((0.01, -0.02, 0.05), tilt=np.radians(tilt), azimuth=np.radians(azimuth))
    h = hr.Hologram(d, x, y, F0, pose=pose, monostatic=mono)
    args = ((40, 44), (0.005, 0.006), (-0.1, -0.1, 0.2))
    ref = _spectrum_on_plane(h, *args, np.dtype(complex), gap=0.05, route="direct")
    work = np.dtype(dtype)
    got = _spectrum_on_plane(h.with_data(d.astype(dtype)), *args, work, gap=0.05,
                             route="nufft")
    assert got.dtype == work
    np.testing.assert_array_equal(got == 0, ref == 0)        # the same components kept
    assert _rel(got, ref) < 2 * EPS[work]


def test_a_tall_aperture_near_the_ground_stays_finite_in_complex64():
    # 48 x 48 elements at 3 cm tilted 60 degrees rise 1.25 m; a 3 cm air gap keeps
    # components evanescent in the air up to Im(kz) = 614 rad/m (the 5 mm grid reaches
    # 890 rad/m). Counted from the aperture's centre, their factors would reach
    # exp(614 x 1.25 / 2) = 1e166, beyond complex64; both routes count from the lowest
    # corner, where every factor is at most 1.
    rng = np.random.default_rng(3)
    n = 48
    x = (np.arange(n) - (n - 1) / 2) * 0.03
    d = (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))).astype(np.complex64)
    pose = hr.Pose((0.0, 0.0, -0.5), tilt=np.radians(60), azimuth=np.radians(30))
    h = hr.Hologram(d, x, x, F0, pose=pose)
    z_ref = float(h.points[:, 2].max())
    args = ((36, 40), (0.005, 0.005), (-0.6, -0.6, z_ref))
    ref = _exact(h, *args, h.k)
    gap = 0.03
    for route in ("nufft", "direct"):
        got = _spectrum_on_plane(h, *args, np.dtype(np.complex64), gap=gap, route=route)
        keep = got != 0
        assert np.all(np.isfinite(got)), route
        # the nufft's bound; the direct route is exact to complex64's rounding
        assert _rel(got[keep], ref[keep]) < 2 * EPS[np.dtype(np.complex64)], route


def test_the_default_route_is_the_faster_as_measured():
    # The choice follows the direct route's multiply-adds (its cost): small sums direct,
    # large ones and any azimuth that does not factor through finufft.
    p90 = hr.Pose(tilt=0.6, azimuth=np.pi / 2)
    p0 = hr.Pose(tilt=0.6)
    p30 = hr.Pose(tilt=0.6, azimuth=np.radians(30))
    limit = oblique.DIRECT_MAX_PRODUCTS
    assert choose_route((40, 44), p90, (8, 10)) == "direct"
    assert choose_route((40, 44), p0, (8, 10)) == "direct"
    assert choose_route((40, 44), p30, (8, 10)) == "direct"   # 140 800 products
    assert choose_route((315, 175), p90, (32, 32)) == "nufft"
    assert 315 * 175 * 32 > limit
    assert choose_route((64, 64), p30, (32, 32)) == "nufft"


def test_migrate_ground_takes_the_route_it_is_given():
    rng = np.random.default_rng(5)
    x = (np.arange(12) - 5.5) * 0.015
    d = rng.standard_normal((12, 12)) + 1j * rng.standard_normal((12, 12))
    pose = hr.Pose((0.0, -0.05, 0.05), tilt=np.radians(35), azimuth=np.radians(90))
    h = hr.Hologram(d, x, x, F0, pose=pose)
    sand = hr.Medium.half_space(0.3, 2.5 + 0.05j)
    images = {r: hr.migrate(h, [0.4], medium=sand, frame="ground", algorithm=r).data
              for r in ("auto", "ground-direct", "ground-nufft")}
    # the default is one of the two, bit for bit (which one: the test above)
    assert sum(np.array_equal(images["auto"], images[r])
               for r in ("ground-direct", "ground-nufft")) == 1
    with pytest.raises(ValueError, match="algorithm must be 'auto'"):
        hr.migrate(h, [0.4], medium=sand, frame="ground", algorithm="fast")
    with pytest.raises(ValueError, match="algorithm='ground-nufft' needs frame='ground'"):
        hr.migrate(h.replace(pose=None), [0.4], medium=sand, algorithm="ground-nufft")


def test_elements_off_a_uniform_grid_take_the_direct_sums():
    # finufft needs uniform modes: a hologram whose x' are not evenly spaced is summed
    # directly by default (exactly: 1e-12 of the largest value, the rounding), and the
    # nufft route refuses it by name.
    rng = np.random.default_rng(2)
    x = np.array([0.0, 0.01, 0.025, 0.03, 0.05, 0.06, 0.08, 0.09])
    y = (np.arange(6) - 2.5) * 0.012
    d = rng.standard_normal((6, 8)) + 1j * rng.standard_normal((6, 8))
    pose = hr.Pose((0.0, 0.0, 0.05), tilt=np.radians(35), azimuth=np.radians(30))
    h = hr.Hologram(d, x, y, F0, pose=pose)
    args = ((128, 128), (0.01, 0.01), (-0.6, -0.6, float(h.points[:, 2].max())))
    # 128^2 x 48 products: evenly spaced, these elements would go to finufft
    assert choose_route(args[0], pose, d.shape) == "nufft"
    got = _spectrum_on_plane(h, *args, np.dtype(complex), gap=0.2)
    ref = _exact(h, *args, h.k)
    keep = got != 0
    np.testing.assert_allclose(got[keep], ref[keep], rtol=0, atol=1e-12 * np.abs(ref).max())
    with pytest.raises(ValueError, match=r"hologram\.x must be uniformly spaced"):
        _spectrum_on_plane(h, *args, np.dtype(complex), gap=0.2, route="nufft")
