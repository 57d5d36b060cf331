"""The two noise levels the inversions stop and threshold at, checked where a wrong
formula shows: the least-squares stop at the noise's norm ``sigma sqrt(M)`` (not
``sigma M``), and the sparse threshold ``sigma sqrt(log N + log(1/p))`` that pure
noise passes on at most a fraction ``p`` of realisations."""

from __future__ import annotations

import math

import numpy as np
import pytest

import holoradar as hr

Y = (0, 1, 0)


def test_the_least_squares_stop_is_the_noises_norm():
    # 32 x 32 elements, one frequency: M = 1024 samples; at 20 dB the data's norm is
    # sqrt(M) * 10 sigma = 320 sigma, while sigma M = 1024 sigma lies above it (a stop
    # there would never step). The discrepancy principle stops at the first step whose
    # residual is below sigma sqrt(M) = 32 sigma; one LSQR step near the noise lowers it
    # by a few percent, so the residual lies within 10 % under that norm.
    h = hr.simulate(hr.Scene(hr.Medium.free_space(), hr.PlaneWave(polarization=Y),
                             [hr.PointTarget((0.01, 0.0, 0.4))]),
                    hr.Aperture.grid(32, 0.0125, polarization=Y), 9.9e9, snr_db=20, seed=5)
    M = h.data.size
    sigma = math.sqrt(float(np.mean(np.abs(h.data) ** 2)) / 100)   # the 20 dB simulated
    assert sigma * M > np.linalg.norm(h.data)
    r = hr.invert(h, [0.38, 0.40], noise=sigma, progress=False)
    step = r.history[0]
    norm = sigma * math.sqrt(M)
    assert step["noise_norm"] == pytest.approx(norm, rel=1e-9)
    assert 0.9 * norm < step["residual"] <= norm * (1 + 1e-6)
    assert step["stop"].startswith("the residual reached the noise")


def test_pure_noise_leaves_no_voxel_in_all_but_p_of_the_realisations():
    # Monte Carlo: complex white noise of known sigma through the sparse inversion on a
    # 16 x 16 transceiver scan's operator (5 frequencies, 3 planes: N = 2883 voxels),
    # p = 1 %: the threshold is the level the largest of N unit-variance correlations
    # passes with probability p (a union bound: correlated neighbours make it pass less
    # often), so over 200 seeds the count with any voxel kept is Binomial(200, <= 0.01);
    # more than 6 has probability below 0.5 % under it. (Without its log(1/p) term 54 of
    # 200 keep voxels; at half the threshold all 200.)
    from holoradar.imaging.inversion.api import _cell_px, _options
    from holoradar.imaging.inversion.columns import column_norms
    from holoradar.imaging.inversion.solvers import sparse
    from holoradar.imaging.migration.linear import migration_operator

    h = hr.simulate(hr.Scene(hr.Medium.free_space(), hr.PlaneWave(),
                             [hr.PointTarget((0.0, 0.0, 0.3))]),
                    hr.Aperture.grid(16, 0.01, monostatic=True), np.linspace(8e9, 12e9, 5))
    z = [0.28, 0.30, 0.32]
    A = migration_operator(h, z, **_options(h, z, {}))
    c = column_norms(A, _cell_px(A, h))
    sigma, seeds, p = 0.7, 200, 0.01
    rng = np.random.default_rng(0)
    M = A.shape[0]
    warm, kept = None, 0
    for _ in range(seeds):
        d = sigma * (rng.standard_normal(M) + 1j * rng.standard_normal(M)) / math.sqrt(2)
        sol = sparse(A, d.astype(A.dtype), sigma, c, 1000, False, p, warm=warm)
        warm = (sol.warm[0], None, None)   # the step size kept, the start from zero
        kept += sol.extra["voxels_kept"] > 0
    assert kept <= 6, kept
