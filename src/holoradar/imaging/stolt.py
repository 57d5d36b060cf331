"""Stolt's migration: the plane waves of each spectral column resampled onto a uniform
kz grid, then one inverse FFT along z.

Within the deepest region the coherent wideband image's spectrum on uniform planes
``z_j = z_0 + j dz`` is, per component ``(kx, ky)``, a sum of plane waves in z,

    I(kx, ky, z_j) = sum_f A_f exp(-i theta_f j),   theta_f = Re(Kz_f) dz  [+ k_f n dz],

``A_f`` the weighted spectrum taken to the first plane (the terms of
:mod:`holoradar.imaging.kspace`; the bracket: a receiver array's incident phase).
Stolt's step puts each propagating term that every plane needs on a uniform grid of
``M = OVERSAMPLE * nz`` phases
``2 pi m / M`` (cubic Lagrange weights on the four nearest nodes, the phase referred to
the middle plane ``jc``), after which one FFT of length M per column gives every plane:
``O(M log M)`` per column instead of ``nf * nz`` multiply-adds.

Error (per plane wave, relative to its amplitude): interpolating ``exp(-i u phi)``,
``phi = 2 pi (j - jc) / M`` at most ``pi / OVERSAMPLE`` in size, at ``u = t`` in [0, 1)
from the nodes -1, 0, 1, 2 errs by at most ``max|t (t+1) (t-1) (t-2)| / 4! * phi^4 =
(9/16) / 24 * (pi/4)^4 = 0.89%`` for ``OVERSAMPLE = 4``. The other terms, evanescent
(complex Kz) or dropped by the band limit before the last plane (the phase-shift sum
drops a component from the plane where its lateral travel leaves the FFT grid), are
summed exactly plane by plane: the difference from the phase-shift sum is the
interpolation's alone, so the image's relative L2 error is at most ``ERROR_BOUND``
times ``sum |A_f|`` over the resampled terms divided by the image's norm (0.89% for
waves that add in phase; measured 1e-4 to 1e-3 on simulated scans).

Applies where the phase-shift sum does (uniform planes in the deepest region, lossless
or loss not compensated, ``fov="aperture"``, ``combine="coherent"``, a transceiver or
a receiver array lit by a normal plane wave), except that a receiver array must carry
its ``source``: :func:`check_applicable` names what blocks it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._lazy import lazy_module
from .._threads import fft_workers
from ..data.hologram import Hologram, Image
from ..physics.medium import Medium
from ..physics.propagation import padded_shape
from ..physics.sources import PlaneWave
from . import kspace

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

__all__ = ["ERROR_BOUND", "OVERSAMPLE", "check_applicable", "migrate_stolt"]

OVERSAMPLE = 4   # kz grid points per plane
_GRID_BYTES = 1 << 25   # the kz grids of a block of columns (complex128)
_PLANES = 8             # planes per inverse FFT
ERROR_BOUND = (9 / 16) / 24 * (np.pi / OVERSAMPLE) ** 4   # per plane wave: 0.0089


def check_applicable(hologram: Hologram, zs: np.ndarray, medium: Medium, *, method: str,
                     fov: str, combine: str, compensate_loss: bool, frame: str) -> None:
    """Raise a ``ValueError`` naming what keeps ``algorithm="stolt"`` from applying."""
    why = []
    if method != "angular":
        why.append(f"method='angular' (got {method!r})")
    if fov != "aperture":
        why.append(f"fov='aperture' (got {fov!r})")
    if combine != "coherent":
        why.append(f"combine='coherent' (got {combine!r})")
    if frame != "aperture" or not hologram.pose.is_identity:
        why.append("the aperture's own frame, untilted at z = 0 (frame='aperture', "
                   "hologram.pose the identity)")
    steps = np.diff(zs)
    if zs.size < 2 or not np.allclose(steps, steps[0], rtol=1e-9, atol=0) or steps[0] <= 0:
        why.append("two or more uniformly spaced planes, increasing (its FFT along z "
                   "samples uniform z)")
    last = medium.n_regions - 1
    if np.any(np.asarray(medium.region_of(zs)) != last):
        why.append(f"all planes in the deepest layer (z >= {medium.z_interfaces[-1]} m): "
                   "one kz per column")
    if compensate_loss and not medium.is_lossless:
        lossy = sum(complex(e).imag != 0 for e in medium.eps)
        why.append(f"no loss to compensate ({lossy} lossy layer(s); give "
                   "compensate_loss=False, or use 'auto')")
    if not hologram.monostatic:
        src = hologram.source
        if src is None:
            why.append("a receiver array's hologram.source (without it the incident "
                       "phase of each frequency cannot be compensated)")
        elif not (isinstance(src, PlaneWave) and src.alpha == 0 and src.beta == 0):
            why.append("a transceiver, or a receiver array lit by a plane wave at normal "
                       f"incidence (hologram.source is {type(src).__name__}: its incident "
                       "phase varies across each plane)")
    if why:
        raise ValueError("algorithm='stolt' needs " + "; ".join(why) + "; use 'auto'")


def migrate_stolt(hologram: Hologram, zs: np.ndarray, medium: Medium, weights: np.ndarray,
                  *, pad: Any = True, upsample: int = 1, dtype: Any = None) -> Image:
    """The coherent wideband image on uniform planes ``zs`` by Stolt's resampling.

    Parameters
    ----------
    hologram : Hologram
        Wideband (..., nf, ny, nx): a transceiver's, or a receiver array's lit by a
        plane wave at normal incidence.
    zs : numpy.ndarray
        Uniformly spaced ranges, metres, in the medium's deepest region.
    medium : Medium
        The layers; lossless, or loss left uncompensated.
    weights : numpy.ndarray
        One weight per frequency.
    pad, upsample, dtype
        As in :func:`holoradar.migrate`.

    Returns
    -------
    Image
        (..., nz, ny', nx'), ``method="stolt:coherent"``; within :data:`ERROR_BOUND`
        per plane wave of the phase-shift sum (see the module docstring).

    Notes
    -----
    Peak memory: the output, plus the spectra of all planes on the FFT grid (the
    output's size unpadded, ~4x padded), plus the terms: measured 4.5x the output
    unpadded and 12x padded (11 x 144 x 187 onto 110 planes from the aperture, where
    every component is live at the first planes). ``"auto"`` stays within ~2x.
    """
    mono = hologram.monostatic
    dx, dy = hologram.pitch
    ny, nx = hologram.data.shape[-2:]
    work = np.dtype(dtype if dtype is not None else (
        np.complex64 if hologram.data.dtype == np.complex64 else np.complex128))
    lam = (0.5 if mono else 1.0) * 2 * np.pi / hologram.wavenumbers.min()
    grid = padded_shape((ny, nx), pad, pitch=(dx, dy), wavelength=lam, z_max=float(zs.max()))
    My, Mx = grid
    workers = fft_workers(My * Mx)
    nz = zs.size
    dz = float(zs[1] - zs[0])
    w = np.asarray(weights, dtype=float)
    gain_q, step_q, jmax, unfold = kspace.frequency_terms(
        grid, dx, dy, tuple(float(k) for k in hologram.wavenumbers), float(zs[0]), dz, nz,
        medium, mono, True, work, w != 0)
    live = np.flatnonzero((jmax >= 0).any(axis=0))
    q_idx = unfold[live]
    jm = jmax[:, live]
    step = step_q[:, q_idx]
    # Resampled: the propagating waves (|step| = 1: real Kz) that every plane needs.
    # The rest (evanescent, or dropped by the band limit before the last plane) are few
    # and summed exactly, plane by plane.
    full = (np.abs(np.abs(step) - 1) < 1e-6) & (jm >= nz - 1)
    gridded = np.flatnonzero(full.any(axis=0))      # columns with resampled terms
    rest_f, rest_c = np.nonzero((jm >= 0) & ~full)
    reach = jm[rest_f, rest_c]
    by_reach = np.argsort(-reach, kind="stable")   # the terms a plane needs: a prefix
    rest_f, rest_c = rest_f[by_reach], rest_c[by_reach]
    n_on = np.searchsorted(-reach[by_reach], -np.arange(nz), side="right")
    gain = np.where(jm >= 0, gain_q[:, q_idx], 0)
    s_rest = step[rest_f, rest_c]
    # The resampled terms' phase per plane in [0, 2 pi), on the gridded columns only.
    theta = np.mod(-np.angle(step[:, gridded]), 2 * np.pi)
    weight = np.where(full[:, gridded], np.exp(-1j * theta * ((nz - 1) // 2)), 0)
    del step, jm, full
    M = OVERSAMPLE * nz
    jc = (nz - 1) // 2       # the phase referred to the middle plane (in weight)
    u = theta / (2 * np.pi / M)
    m0 = np.floor(u).astype(np.int64)
    t = u - m0
    nodes = [(-1, -t * (t - 1) * (t - 2) / 6), (0, (t + 1) * (t - 1) * (t - 2) / 2),
             (1, -(t + 1) * t * (t - 2) / 2), (2, (t + 1) * t * (t - 1) / 6)]
    del theta, u, t
    data = hologram.data if hologram.is_wideband else hologram.data[..., None, :, :]
    batch = data.shape[:-3]
    data = data.reshape((-1, *data.shape[-3:]))
    up = int(upsample)
    oy, ox = up * (ny - 1) + 1, up * (nx - 1) + 1
    out = np.empty((data.shape[0], nz, oy, ox), dtype=work)
    nc = live.size
    rows_z = np.mod(np.arange(nz) - jc, M)
    per = max(1, _GRID_BYTES // (16 * M))             # gridded columns per block
    for b in range(data.shape[0]):
        A = np.empty((hologram.nf, nc), dtype=np.complex128)
        for i in range(hologram.nf):
            H = sfft.fft(data[b, i].astype(work, copy=False), n=Mx, axis=-1, workers=workers)
            H = sfft.fft(H, n=My, axis=-2, workers=workers, overwrite_x=True)
            A[i] = H.reshape(-1)[live] * gain[i] * w[i]
        # The spectra of all planes on the grid, filled column block by column block.
        spec = np.zeros((nz, My * Mx), dtype=work)
        for c0 in range(0, gridded.size, per):
            g = slice(c0, c0 + per)
            cols = gridded[g]
            Ab = A[:, cols] * weight[:, g]
            base = np.arange(cols.size)[None, :] * M
            G = np.zeros(cols.size * M, dtype=np.complex128)
            for shift, wt in nodes:
                idx = (base + np.mod(m0[:, g] + shift, M)).ravel()
                vals = (Ab * wt[:, g]).ravel()
                G.real += np.bincount(idx, vals.real, G.size)
                G.imag += np.bincount(idx, vals.imag, G.size)
            # sum_m G_m exp(-2 pi i m (j - jc) / M): the forward FFT at (j - jc) mod M.
            F = sfft.fft(G.reshape(cols.size, M), axis=-1, workers=workers, overwrite_x=True)
            spec[:, live[cols]] = F[:, rows_z].T
        a = A[rest_f, rest_c].astype(work)
        del A
        for j in range(nz):   # the rest, summed exactly (live ones a shrinking prefix)
            k = int(n_on[j])
            if k == 0:
                break
            part = np.bincount(rest_c[:k], a[:k].real, nc) + 1j * np.bincount(
                rest_c[:k], a[:k].imag, nc)
            spec[j, live] += part.astype(work)
            a[:k] *= s_rest[:k]
        spec = spec.reshape(nz, My, Mx)
        for j0 in range(0, nz, _PLANES):   # inverse FFTs, a few planes at a time
            sl = spec[j0:j0 + _PLANES]
            if up > 1:
                sl = kspace._pad_axis(kspace._pad_axis(sl, up, -1), up, -2)
                planes = sfft.ifft2(sl, axes=(-2, -1), workers=workers, overwrite_x=True)
                out[b, j0:j0 + _PLANES] = planes[:, :oy, :ox] * (up * up)
            else:
                half = sfft.ifft(sl, axis=-1, workers=workers, overwrite_x=True)[..., :ox]
                out[b, j0:j0 + _PLANES] = sfft.ifft(half, axis=-2, workers=workers)[:, :oy]
        del spec
    out = out.reshape((*batch, nz, oy, ox))
    x = hologram.x[0] + np.arange(ox) * dx / up
    y = hologram.y[0] + np.arange(oy) * dy / up
    return Image(out, x, y, zs, hologram.frequencies.copy(), "stolt:coherent")
