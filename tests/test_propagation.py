"""Propagators: dot tests (forward vs adjoint), identities, closed forms.

Migration is the adjoint of forward propagation.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.fft as sfft

import holoradar as hr
from conftest import F0, crandn
from holoradar.physics.propagation import spectral_axes

K = 2 * np.pi * F0 / hr.C0
MEDIA = {
    "free": hr.Medium.free_space(),
    "sand": hr.Medium.half_space(0.30, 2.5 + 0.0125j),
    "layers": hr.Medium.layered([0.2, 0.27], [4.0 + 0.4j, 9.0 + 0.1j]),
}


def _dot_error(op, rng) -> float:
    """|<A x, y> - <x, A^H y>| / (|A x| |y|): normalised by the operator's action (ODL)."""
    x = crandn(rng, (op.z.size, *op.shape))
    y = crandn(rng, op.shape)
    Ax = op.forward(x)
    AHy = op.adjoint(y)
    lhs = np.vdot(y, Ax)
    rhs = np.vdot(AHy, x)
    return abs(lhs - rhs) / (np.linalg.norm(Ax) * np.linalg.norm(y))


@pytest.mark.parametrize("shape", [(16, 16), (17, 23), (32, 15)])
@pytest.mark.parametrize("medium", list(MEDIA))
@pytest.mark.parametrize("pad", [True, False])
def test_angular_dot_test(shape, medium, pad, rng):
    # float64 round-off of an FFT pair is ~1e-15 * log2(N); 1e-6 is the bound.
    op = hr.AngularSpectrum(shape, 0.012, 0.01, K, [0.1, 0.35, 0.5], MEDIA[medium], pad)
    assert _dot_error(op, rng) < 1e-6


@pytest.mark.parametrize("shape", [(16, 16), (17, 23)])
@pytest.mark.parametrize("medium", ["free", "sand"])
def test_fresnel_dot_test(shape, medium, rng):
    op = hr.Fresnel(shape, 0.012, 0.01, K, [0.3, 0.5], MEDIA[medium], True)
    assert _dot_error(op, rng) < 1e-6


def _band_limited(rng, shape, dx, k, fill=0.9):
    """Random field whose spectrum is zero outside |kappa| < fill*k (propagating only)."""
    p, q = spectral_axes(shape, dx, dx)
    spec = crandn(rng, shape) * ((q[:, None] ** 2 + p[None, :] ** 2) < (fill * k) ** 2)
    return sfft.ifft2(spec)


@pytest.mark.parametrize("shape", [(32, 32), (31, 24)])
def test_forward_then_back_returns_input(shape, rng):
    # Free space, propagating band: |exp(i kz z)| = 1, so conj(U) U = 1 exactly; the
    # periodic grid (pad=False, no band limit) makes the operator square and unitary there.
    dx = 0.01
    f = _band_limited(rng, shape, dx, K)
    op = hr.AngularSpectrum(shape, dx, dx, K, 0.4, None, pad=False, band_limit=False)
    back = op.adjoint(op.forward(f[None]))[0]
    assert np.linalg.norm(back - f) / np.linalg.norm(f) < 1e-10


def test_zero_distance_is_identity(rng):
    f = crandn(rng, (20, 20))
    op = hr.AngularSpectrum((20, 20), 0.01, 0.01, K, 0.0, None, pad=False)
    np.testing.assert_allclose(op.forward(f[None]), f, atol=1e-12)


def test_propagation_composes(rng):
    # exp(i kz z1) exp(i kz z2) = exp(i kz (z1 + z2)) for every component.
    dx = 0.01
    f = _band_limited(rng, (32, 32), dx, K)
    a, b, ab = (hr.AngularSpectrum((32, 32), dx, dx, K, z, None, pad=False, band_limit=False)
                for z in (0.15, 0.25, 0.40))
    np.testing.assert_allclose(b.forward(a.forward(f[None])[None]), ab.forward(f[None]),
                               atol=1e-12)


def test_evanescent_waves_decay():
    # A component with kappa > k decays as exp(-sqrt(kappa^2 - k^2) z) both ways.
    op = hr.AngularSpectrum((64, 64), 0.004, 0.004, K, 0.05, None, pad=False)
    p, q = spectral_axes((64, 64), 0.004, 0.004)
    kap = np.hypot(q[:, None], p[None, :])
    U = op.transfers[0]
    ev = kap > 1.01 * K
    expected = np.exp(-np.sqrt(kap[ev] ** 2 - K**2) * 0.05)
    np.testing.assert_allclose(np.abs(U[ev]), expected, rtol=1e-12)
    assert np.all(np.abs(U[ev].conj()) <= 1)


def test_complex64_path_keeps_precision(rng):
    # complex64 rounding ~6e-8 per operation; an FFT pair of 64x64 adds ~log2(N) of them.
    dx = 0.01
    f = _band_limited(rng, (64, 64), dx, K)
    op64 = hr.AngularSpectrum((64, 64), dx, dx, K, [0.3], None, True, np.complex64)
    op128 = hr.AngularSpectrum((64, 64), dx, dx, K, [0.3], None, True, np.complex128)
    a = op64.adjoint(f.astype(np.complex64))
    b = op128.adjoint(f)
    assert a.dtype == np.complex64
    assert np.linalg.norm(a - b) / np.linalg.norm(b) < 1e-5


@pytest.mark.parametrize("monostatic", [False, True])
@pytest.mark.parametrize("z", [0.12, 0.25, 0.31, 0.47])
def test_cached_transfer_equals_the_layered_recursion(z, monostatic):
    """Planes below the last interface reuse the transfer to its top times one
    exponential, on one quadrant of the spectrum: it must equal the full layered
    recursion evaluated on the whole grid (the band limit included), exactly
    but for rounding: 1e-12."""
    from holoradar.physics.propagation import (
        lateral_travel,
        make_angular_transfer,
        spectral_axes,
        two_way_transfer,
    )

    medium = hr.Medium((0.1, 0.16, 0.3), (1, 4 + 0.3j, 9 + 0.5j, 6 + 0.2j))
    shape, dx, dy, k = (48, 64), 0.004, 0.005, 207.0
    U = make_angular_transfer(shape, dx, dy, k, z, medium, True, np.dtype(complex), False,
                               None, monostatic)
    p, q = spectral_axes(shape, dx, dy)
    kappa2 = q[:, None] ** 2 + p[None, :] ** 2
    if monostatic:
        ref = two_way_transfer(k, medium, kappa2, z)
        t = 0.5 * lateral_travel(k, medium, kappa2 / 4, z)
        evanescent = kappa2 > 4 * k * k
    else:
        ref = medium.vertical_transfer(k, kappa2, z, 0.0)
        t = lateral_travel(k, medium, kappa2, z)
        evanescent = kappa2 > k * k
    with np.errstate(invalid="ignore"):
        ok = (np.abs(p)[None, :] * t <= 64 * dx / 2) & (np.abs(q)[:, None] * t <= 48 * dy / 2)
    ref = np.where(ok | evanescent, ref, 0)
    assert np.count_nonzero(ref) > 0.2 * ref.size
    np.testing.assert_allclose(U, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
