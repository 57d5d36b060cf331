"""``hr.propagate``: the recorded field carried to a parallel plane, either way, checked
against closed forms: a plane wave of the FFT grid is carried exactly (its phase
``exp(i kz d)``, a transceiver's ``exp(i sqrt(4k^2 - kx^2) d)``); an evanescent one
decays both ways."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from conftest import migrate64

N, P, F = 64, 0.005, 10e9
K = 2 * np.pi * F / hr.C0
X = (np.arange(N) - N / 2) * P


def _wave(m: int) -> tuple[np.ndarray, float]:
    """A plane wave of the grid (periodic on it: no edge) and its kx."""
    kx = 2 * np.pi * m / (N * P)
    return np.exp(1j * kx * X)[None, :] * np.ones((N, 1)), kx


@pytest.mark.parametrize("d", [0.07, -0.07])
def test_a_plane_wave_is_carried_by_its_phase(d):
    # Unpadded, the FFT grid is the wave's period: the result is exact to rounding.
    u, kx = _wave(7)
    h = hr.Hologram(u, X, X, F)
    out = hr.propagate(h, d, pad=False)
    kz = np.sqrt(K**2 - kx**2)
    np.testing.assert_allclose(out.data, u * np.exp(1j * kz * d), rtol=0, atol=1e-12)
    # a ground below the array changes nothing above it (d > 0), and nothing above
    # its surface (d < 0 ending short of it)
    sand = hr.Medium.half_space(0.10, 2.5 + 0.01j)
    np.testing.assert_allclose(hr.propagate(h, d, pad=False, medium=sand).data, out.data,
                               rtol=0, atol=1e-12)


def test_back_through_the_ground_is_migrates_plane():
    # Down through a sand half-space: the plane migrate images at that range with the
    # exact adjoint (no loss compensation) on the same grid.
    scene = hr.Scene(hr.Medium.half_space(0.05, 2.5 + 0.01j), hr.PlaneWave(),
                     [hr.PointTarget((0.01, 0.0, 0.12))])
    h = hr.simulate(scene, hr.Aperture.grid(32, 0.01), F, snr_db=40, seed=1,
                    include_surface=False)
    sand = hr.Medium.half_space(0.05, 2.5 + 0.01j)
    got = hr.propagate(h, -0.09, medium=sand)
    ref = migrate64(h, 0.09, medium=sand, compensate_loss=False)
    np.testing.assert_allclose(got.data, ref.data, rtol=0, atol=1e-9 * np.abs(ref.data).max())


def test_a_transceivers_round_trip_and_a_band():
    u, kx = _wave(5)
    f = np.array([9e9, 10e9, 11e9])
    h = hr.Hologram(np.stack([u] * 3), X, X, f, monostatic=True)
    out = hr.propagate(h, 0.05, pad=False)
    for i, fi in enumerate(f):
        k = 2 * np.pi * fi / hr.C0
        want = u * np.exp(1j * np.sqrt(4 * k**2 - kx**2) * 0.05)
        np.testing.assert_allclose(out.data[i], want, rtol=0, atol=1e-12)


def test_evanescent_waves_decay_both_ways():
    # kx > k: the wave decays as exp(-|kz| |d|) forward; back towards the sources it is
    # not regrown (it would grow from the noise): the same decay.
    u, kx = _wave(30)          # below the grid's Nyquist (32): not aliased
    assert kx > K
    h = hr.Hologram(u, X, X, F)
    decay = np.exp(-np.sqrt(kx**2 - K**2) * 0.01)
    for d in (0.01, -0.01):
        out = hr.propagate(h, d, pad=False)
        np.testing.assert_allclose(np.abs(out.data), decay, rtol=1e-9)


def test_bad_input_is_refused_by_name():
    h = hr.Hologram(np.ones((8, 8)), X[:8], X[:8], F)
    with pytest.raises(ValueError, match="distance must be a finite number"):
        hr.propagate(h, float("nan"))
    with pytest.raises(ValueError, match=r"medium must be a holoradar\.Medium"):
        hr.propagate(h, 0.1, medium=2.5)
    with pytest.raises(ValueError, match=r"hologram must be a holoradar\.Hologram"):
        hr.propagate(np.ones((8, 8)), 0.1)
    assert hr.propagate(h, 0.0) is h
