"""The plane-by-plane migration's work around its FFTs gives the plain FFT result.

The padded forward transform runs along x over the recorded rows only, then along y;
small products are multiplied in one thread: each must equal the textbook
``ifft2(fft2(h, s=padded) * conj(U))[:ny, :nx]`` to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.fft as sfft

import holoradar as hr
from conftest import migrate64
from holoradar.imaging.migration.backends import planes as planes_module
from holoradar.physics.propagation import AngularSpectrum

F0 = 9.9e9
DX = hr.C0 / F0 / 2
TOL = {np.complex64: 1e-6, np.complex128: 1e-12}


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def _field(shape: tuple[int, ...], dtype: type, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(dtype)


@pytest.mark.parametrize("dtype", [np.complex64, np.complex128])
@pytest.mark.parametrize("shape", [(40, 40), (37, 52), (3, 21, 30)])
def test_padded_spectrum_is_the_zero_padded_fft2(dtype, shape):
    a = _field(shape, dtype)
    op = AngularSpectrum(shape[-2:], DX, DX, 2 * np.pi / (2 * DX), 0.4, dtype=dtype)
    assert op.fft_shape[0] > shape[-2]
    ref = sfft.fft2(a.astype(np.complex128), s=op.fft_shape, axes=(-2, -1))
    got = op.spectrum(a)
    assert got.dtype == dtype and got.shape == (*shape[:-2], *op.fft_shape)
    assert _rel(got, ref) < TOL[dtype]


@pytest.mark.parametrize("dtype", [np.complex64, np.complex128])
@pytest.mark.parametrize("medium", [None, hr.Medium.half_space(0.2, 4.0),
                                    hr.Medium.half_space(0.2, 6 + 1j)])
def test_padded_plane_equals_the_plain_fft_pipeline(dtype, medium):
    ny, nx = 45, 60
    a = _field((ny, nx), dtype, seed=1)
    x, y = np.arange(nx) * DX, np.arange(ny) * DX
    h = hr.Hologram(a, x, y, F0)
    img = migrate64(h, 0.4, medium=medium, snr_db=40.0, dtype=dtype)
    op = AngularSpectrum((ny, nx), DX, DX, h.k, 0.4, medium, True, dtype,
                         compensate_loss=True, snr_db=40.0)
    spec = np.fft.fft2(a.astype(np.complex128), s=op.fft_shape)
    ref = np.fft.ifft2(spec * op.adjoint_transfers[0])[:ny, :nx]
    assert img.data.dtype == dtype
    assert _rel(img.data, ref) < TOL[dtype]


@pytest.mark.parametrize("dtype", [np.complex64, np.complex128, np.complex64(1).real.dtype])
@pytest.mark.parametrize("pad", [False, True])
def test_plane_leaves_the_hologram_untouched_and_equals_the_plain_pipeline(dtype, pad):
    # The forward FFT writes its first pass into new memory and runs the second in
    # place (and, for data that needs converting, transforms the converted copy in
    # place): the caller's data must come out bit-identical, the image the textbook one.
    ny, nx = 40, 52
    a = _field((ny, nx), np.complex128, seed=5)
    a = a.real.astype(dtype) if np.dtype(dtype).kind == "f" else a.astype(dtype)
    before = a.copy()
    h = hr.Hologram(a, np.arange(nx) * DX, np.arange(ny) * DX, F0)
    img = migrate64(h, 0.4, pad=pad)
    np.testing.assert_array_equal(h.data, before)
    work = img.data.dtype.type
    op = AngularSpectrum((ny, nx), DX, DX, h.k, 0.4, None, pad, work,
                         compensate_loss=True, snr_db=40.0)
    spec = np.fft.fft2(before.astype(np.complex128), s=op.fft_shape)
    ref = np.fft.ifft2(spec * op.adjoint_transfers[0])[:ny, :nx]
    assert _rel(img.data, ref) < TOL[work]


@pytest.mark.parametrize("dtype", [np.complex64, np.complex128])
def test_grazing_component_is_out_of_band_in_the_phase_step_too(dtype):
    # On a lambda/2 grid the Nyquist column kx = pi/dx = k has kz = 0: it travels
    # sideways without end, so the per-plane band limit drops it at every range. The
    # plane-to-plane phase step ("kspace") must drop it as well (it kept it: 2.4e-3 of
    # a noise hologram's image). Both are the same exact sum otherwise: their
    # difference is the step's rounding over the 10 planes, ~10 eps of the dtype.
    a = _field((48, 64), dtype, seed=6)
    h = hr.Hologram(a, np.arange(64) * DX, np.arange(48) * DX, F0)
    zs = np.linspace(0.2, 0.5, 10)
    per_plane = migrate64(h, zs, pad=False, algorithm="frequency").data
    stepped = migrate64(h, zs, pad=False, algorithm="kspace").data
    assert _rel(stepped, per_plane) < 100 * np.finfo(dtype).eps


@pytest.mark.parametrize("threshold", [0, 1 << 40])   # always threads / never threads
def test_plane_products_are_exact_in_one_thread_or_many(monkeypatch, threshold):
    monkeypatch.setattr(planes_module, "_THREADED_MULTIPLY", threshold)
    H = _field((2, 70, 33), np.complex64, seed=2)
    Us = [_field((70, 33), np.complex64, seed=3 + i) for i in range(3)]
    prod = np.empty((2, 3, 70, 33), np.complex64)
    planes_module.multiply_planes(H, Us, prod)
    for i, U in enumerate(Us):
        np.testing.assert_array_equal(prod[:, i], H * U)


def test_volume_in_one_thread_equals_the_threaded_volume(monkeypatch):
    a = _field((64, 64), np.complex128, seed=4)
    h = hr.Hologram(a, np.arange(64) * DX, np.arange(64) * DX, F0)
    zs = np.linspace(0.2, 0.5, 12)
    one = migrate64(h, zs, pad=False, algorithm="frequency").data
    monkeypatch.setattr(planes_module, "_THREADED_MULTIPLY", 0)
    many = migrate64(h, zs, pad=False, algorithm="frequency").data
    np.testing.assert_array_equal(one, many)
