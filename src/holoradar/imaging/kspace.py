"""Wideband migration in the wavenumber domain (Gazdag's phase shift), for uniform planes.

Within the deepest region of the stack (or free space) the transfer of a plane
wave grows from plane to plane by one factor: ``U(z + dz) = U(z) exp(i Kz dz)``,
``Kz = kz(kappa)`` (``2 kz(kappa/2)`` for a transceiver's round trip). So the
coherent sum over frequencies of the per-frequency back-propagations,

    I(kappa, z_j) = sum_f w_f H_f(kappa) conj(U_f(kappa, z_0)) phasor_f(z_0)
                    * exp(-i conj(Kz_f) j dz) * exp(-i Re(k_f n) j dz),

(the last factor: a normal plane wave's incident phase, receiver arrays only) is
carried from plane to plane by one complex multiply per frequency and component,
and each plane needs one inverse FFT instead of one per frequency. It is the same
sum as the per-frequency angular spectrum, to rounding (tested), including the
band limit of every plane (a component is dropped from the plane where its lateral
travel leaves the grid, as there).

Applies when the planes are uniformly spaced and all lie in the deepest region,
``fov="aperture"``, ``combine="coherent"``, the illumination is a transceiver's
own or a plane wave at normal incidence (or none), and no loss compensation is
needed (lossless layers, or ``compensate_loss=False``). Otherwise
:func:`holoradar.migrate` sums frequency by frequency.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.fft as sfft

from ..data.hologram import Hologram, Image
from ..physics.medium import Medium
from ..physics.propagation import (
    _angular_transfer,
    lateral_travel,
    padded_shape,
    spectral_axes,
)
from ..physics.sources import PlaneWave

_CHUNK = 8


def applicable(hologram: Hologram, zs: np.ndarray, medium: Medium, *, method: str, fov: str,
               combine: str, compensate_loss: bool, phase_incident: bool = True) -> bool:
    """Whether :func:`migrate_kspace` computes exactly what the per-frequency sum does
    (``phase_incident=False``: what the plane-by-plane migration of each frequency does)."""
    if method != "angular" or fov != "aperture" or combine != "coherent" or zs.size < 2:
        return False
    steps = np.diff(zs)
    if not np.allclose(steps, steps[0], rtol=1e-9, atol=0) or steps[0] <= 0:
        return False
    last = medium.n_regions - 1
    if np.any(np.asarray(medium.region_of(zs)) != last):
        return False
    if compensate_loss and any(complex(e).imag != 0 for e in medium.eps):
        return False
    src = hologram.source
    if hologram.monostatic or src is None or not phase_incident:
        return True
    return isinstance(src, PlaneWave) and src.alpha == 0 and src.beta == 0


def migrate_kspace(hologram: Hologram, zs: np.ndarray, medium: Medium, weights: np.ndarray, *,
                   pad: Any = True, upsample: int = 1, dtype: Any = None,
                   phase_incident: bool = True) -> Image:
    """The coherent wideband image on uniform planes ``zs`` (see the module docstring).

    ``phase_incident=False`` leaves each frequency's incident phase in (for one
    frequency: the plain back-propagated field, as :func:`holoradar.migrate`
    returns it), and the data may lack the frequency axis.
    """
    from .migrate import _zero_pad_spectrum

    mono = hologram.monostatic
    dx, dy = hologram.pitch
    ny, nx = hologram.data.shape[-2:]
    work = np.dtype(dtype) if dtype is not None else (
        np.complex64 if hologram.data.dtype == np.complex64 else np.complex128)
    lam = (0.5 if mono else 1.0) * 2 * np.pi / hologram.wavenumbers.min()
    fft_shape = padded_shape((ny, nx), pad, pitch=(dx, dy), wavelength=lam,
                             z_max=float(zs.max()))
    My, Mx = fft_shape
    workers = -1 if My * Mx >= 128 * 128 else 1
    data = hologram.data if hologram.is_wideband else hologram.data[..., None, :, :]
    H = sfft.fft2(data.astype(work, copy=False), s=fft_shape, axes=(-2, -1),
                  workers=workers)                                   # (..., nf, My, Mx)
    p, q = spectral_axes(fft_shape, dx, dy)
    kappa2 = q[:, None] ** 2 + p[None, :] ** 2
    last = medium.n_regions - 1
    dz = float(zs[1] - zs[0])
    n_last = medium.n(last)
    nz = zs.size
    steps = []
    drops = []
    for i, k in enumerate(hologram.wavenumbers):
        Uc = _angular_transfer(fft_shape, dx, dy, float(k), float(zs[0]), medium, True, work,
                               True, None, mono)
        a = weights[i] * Uc
        if mono:
            Kz = 2 * medium.kz(k, kappa2 / 4, last)
            t0 = 0.5 * lateral_travel(k, medium, kappa2 / 4, float(zs[0]))
            rate = np.where(Kz.real > 0, 1 / np.where(Kz.real > 0, Kz.real, 1), np.inf)
            evanescent = kappa2 > 4 * k * k
        else:
            Kz = medium.kz(k, kappa2, last)
            t0 = lateral_travel(k, medium, kappa2, float(zs[0]))
            rate = np.where(Kz.real > 0, 1 / np.where(Kz.real > 0, Kz.real, 1), np.inf)
            evanescent = kappa2 > k * k
            if phase_incident:
                e0 = complex(medium.vertical_transfer(k, np.array(0.0), 0.0, float(zs[0])))
                a = a * (np.conj(e0) / abs(e0))
        step = np.exp(-1j * np.conj(Kz) * dz)
        if not mono and phase_incident:
            step = step * np.exp(-1j * (k * n_last).real * dz)
        # Band limit: the lateral shift |p| t(z), t(z) = t0 + (z - z0) * rate, must stay
        # within half the grid: the last plane index j a component may reach.
        with np.errstate(divide="ignore", invalid="ignore"):
            room = np.minimum(np.where(p[None, :] != 0, Mx * dx / 2 / np.abs(p[None, :]), np.inf),
                              np.where(q[:, None] != 0, My * dy / 2 / np.abs(q[:, None]), np.inf))
            jmax = np.floor((room - t0) / (rate * dz))
        jmax = np.where(evanescent, nz, np.nan_to_num(jmax, nan=nz, posinf=nz, neginf=-1))
        steps.append(step.astype(work))
        # Flat indices of the components leaving after plane j: drop[j] = order[b[j]:b[j+1]].
        flat = jmax.ravel()
        order = np.argsort(flat, kind="stable")
        bounds = np.searchsorted(flat[order], np.arange(nz + 1), side="left")
        drops.append((order, bounds))
        H[..., i, :, :] *= a.astype(work)
    u = int(upsample)
    oy, ox = u * (ny - 1) + 1, u * (nx - 1) + 1
    batch = H.shape[:-3]
    out = np.empty((*batch, nz, oy, ox), dtype=work)
    for c0 in range(0, nz, _CHUNK):
        c1 = min(nz, c0 + _CHUNK)
        prod = np.empty((*batch, c1 - c0, My, Mx), dtype=work)
        for j in range(c0, c1):
            prod[..., j - c0, :, :] = H.sum(axis=-3)
            for i in range(hologram.nf):
                H[..., i, :, :] *= steps[i]
                order, bounds = drops[i]
                idx = order[bounds[j]:bounds[j + 1]]
                if idx.size:  # these leave the grid from the next plane on
                    H[..., i, :, :].reshape((*batch, -1))[..., idx] = 0
        if u > 1:
            prod = _zero_pad_spectrum(prod, u)
        planes = sfft.ifft2(prod, axes=(-2, -1), workers=workers, overwrite_x=True)
        out[..., c0:c1, :, :] = planes[..., :oy, :ox] * (u * u) if u > 1 else planes[
            ..., :oy, :ox]
    x = hologram.x[0] + np.arange(ox) * dx / u
    y = hologram.y[0] + np.arange(oy) * dy / u
    if not hologram.is_wideband:
        return Image(out, x, y, zs, hologram.frequency, "angular")
    return Image(out, x, y, zs, hologram.frequencies.copy(), "kspace:coherent")
