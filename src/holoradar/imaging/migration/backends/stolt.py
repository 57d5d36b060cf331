"""Stolt's migration: the plane waves of each spectral column resampled onto a uniform
kz grid, then one inverse FFT along z.

Within the deepest region the coherent wideband image's spectrum on uniform planes
``z_j = z_0 + j dz`` is, per component ``(kx, ky)``, a sum of plane waves in z,

    I(kx, ky, z_j) = sum_f A_f exp(-i theta_f j),   theta_f = Re(Kz_f) dz  [+ k_f n dz],

``A_f`` the weighted spectrum taken to the first plane (the terms of
:mod:`.kspace`; the bracket: a receiver array's incident phase).
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
its ``source``: the ``"stolt"`` backend of :mod:`holoradar.imaging.migration` names
what blocks it. :func:`forward_stolt` is the exact adjoint of :func:`adjoint_stolt`
(the interpolation's transpose, then the phase-shift terms' conjugates), so that the
pair passes the dot test to rounding although each is 0.9 % from the exact operator.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...._lazy import lazy_module
from ...._threads import fft_workers
from ....physics.spectra import fft2_padded, fold, ifft2_cropped, interpolate
from . import kspace
from .terms import TermsKey

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

__all__ = ["ERROR_BOUND", "OVERSAMPLE", "adjoint_stolt", "forward_stolt"]

OVERSAMPLE = 4   # kz grid points per plane
_GRID_BYTES = 1 << 25   # the kz grids of a block of columns (complex128)
_PLANES = 8             # planes per inverse FFT
ERROR_BOUND = (9 / 16) / 24 * (np.pi / OVERSAMPLE) ** 4   # per plane wave: 0.0089


@dataclass
class _Terms:
    """The resampling of one geometry: which terms go on the kz grid and how, and the
    rest, summed exactly (see the module docstring)."""

    grid: tuple[int, int]
    live: np.ndarray        # (nc,) flat grid indices of the components some term needs
    gain: np.ndarray        # (nf, nc) conj transfer to the first plane (0: never used)
    gridded: np.ndarray     # columns (indices into live) with resampled terms
    weight: np.ndarray      # (nf, len(gridded)) the middle plane's phase (0: not gridded)
    m0: np.ndarray          # (nf, len(gridded)) kz node below each term
    nodes: list             # [(shift, weights (nf, len(gridded)))] cubic Lagrange
    rest_f: np.ndarray      # the exactly summed terms: frequency,
    rest_c: np.ndarray      # column (index into live),
    s_rest: np.ndarray      # step,
    n_on: np.ndarray        # (nz,) how many of them (a prefix) each plane needs
    rows_z: np.ndarray      # (nz,) each plane's row of the length-M FFT
    M: int

    @classmethod
    def build(cls, terms: TermsKey) -> _Terms:
        grid, nz = terms.grid, terms.nz
        gain_q, step_q, jmax, unfold = kspace.frequency_terms(terms)
        live = np.flatnonzero((jmax >= 0).any(axis=0))
        q_idx = unfold[live]
        jm = jmax[:, live]
        step = step_q[:, q_idx]
        # Resampled: the propagating waves (|step| = 1: real Kz) that every plane needs.
        # The rest (evanescent, or dropped by the band limit before the last plane) are
        # few and summed exactly, plane by plane.
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
        M = OVERSAMPLE * nz
        jc = (nz - 1) // 2       # the phase referred to the middle plane (in weight)
        u = theta / (2 * np.pi / M)
        m0 = np.floor(u).astype(np.int64)
        t = u - m0
        nodes = [(-1, -t * (t - 1) * (t - 2) / 6), (0, (t + 1) * (t - 1) * (t - 2) / 2),
                 (1, -(t + 1) * t * (t - 2) / 2), (2, (t + 1) * t * (t - 1) / 6)]
        return cls(grid, live, gain, gridded, weight, m0, nodes, rest_f, rest_c, s_rest,
                   n_on, np.mod(np.arange(nz) - jc, M), M)

    def blocks(self) -> Any:
        """Slices of the gridded columns, a kz grid's worth of memory each."""
        per = max(1, _GRID_BYTES // (16 * self.M))
        return (slice(c0, c0 + per) for c0 in range(0, self.gridded.size, per))

    def node_index(self, g: slice, shift: int) -> np.ndarray:
        """Where each term of the block ``g`` lands on its column's kz grid."""
        base = np.arange(self.gridded[g].size)[None, :] * self.M
        return (base + np.mod(self.m0[:, g] + shift, self.M)).ravel()


def adjoint_stolt(data: np.ndarray, terms: TermsKey, weights: np.ndarray,
                  upsample: int = 1) -> np.ndarray:
    """The coherent wideband image on the uniform planes of ``terms`` by Stolt's
    resampling.

    Parameters
    ----------
    data : numpy.ndarray
        ``(B, nf, ny, nx)``: a transceiver's, or a receiver array's lit by a plane
        wave at normal incidence.
    terms : TermsKey
        The band, the planes (uniformly spaced, in the medium's deepest region), the
        layers (lossless, or loss left uncompensated), the model's factors, the FFT
        grid and the working dtype (:class:`.terms.TermsKey`).
    weights : numpy.ndarray
        One weight per frequency.
    upsample : int
        Output pixels per pitch, as in :func:`holoradar.migrate`.

    Returns
    -------
    numpy.ndarray
        ``(B, nz, ny', nx')``; within :data:`ERROR_BOUND` per plane wave of the
        phase-shift sum (see the module docstring).

    Notes
    -----
    Peak memory: the output, plus the spectra of all planes on the FFT grid (the
    output's size unpadded, ~4x padded), plus the terms: measured 4.5x the output
    unpadded and 12x padded (11 x 144 x 187 onto 110 planes from the aperture, where
    every component is live at the first planes). ``"auto"`` stays within ~2x.
    """
    ny, nx = data.shape[-2:]
    T = _Terms.build(terms)
    work, nf = terms.work, terms.nf
    My, Mx = T.grid
    workers = fft_workers(My * Mx)
    nz, nc = terms.nz, T.live.size
    w = np.asarray(weights, dtype=float)
    up = int(upsample)
    oy, ox = up * (ny - 1) + 1, up * (nx - 1) + 1
    out = np.empty((data.shape[0], nz, oy, ox), dtype=work)
    for b in range(data.shape[0]):
        A = np.empty((nf, nc), dtype=np.complex128)
        for i in range(nf):
            H = fft2_padded(data[b, i], T.grid, work, workers)
            A[i] = H.reshape(-1)[T.live] * T.gain[i] * w[i]
        # The spectra of all planes on the grid, filled column block by column block.
        spec = np.zeros((nz, My * Mx), dtype=work)
        for g in T.blocks():
            cols = T.gridded[g]
            Ab = A[:, cols] * T.weight[:, g]
            G = np.zeros(cols.size * T.M, dtype=np.complex128)
            for shift, wt in T.nodes:
                idx = T.node_index(g, shift)
                vals = (Ab * wt[:, g]).ravel()
                G.real += np.bincount(idx, vals.real, G.size)
                G.imag += np.bincount(idx, vals.imag, G.size)
            # sum_m G_m exp(-2 pi i m (j - jc) / M): the forward FFT at (j - jc) mod M.
            F = sfft.fft(G.reshape(cols.size, T.M), axis=-1, workers=workers, overwrite_x=True)
            spec[:, T.live[cols]] = F[:, T.rows_z].T
        a = A[T.rest_f, T.rest_c].astype(work)
        del A
        for j in range(nz):   # the rest, summed exactly (live ones a shrinking prefix)
            k = int(T.n_on[j])
            if k == 0:
                break
            part = np.bincount(T.rest_c[:k], a[:k].real, nc) + 1j * np.bincount(
                T.rest_c[:k], a[:k].imag, nc)
            spec[j, T.live] += part.astype(work)
            a[:k] *= T.s_rest[:k]
        spec = spec.reshape(nz, My, Mx)
        for j0 in range(0, nz, _PLANES):   # inverse FFTs, a few planes at a time
            sl = spec[j0:j0 + _PLANES]
            if up > 1:
                sl = interpolate(sl, up)
                planes = sfft.ifft2(sl, axes=(-2, -1), workers=workers, overwrite_x=True)
                out[b, j0:j0 + _PLANES] = planes[:, :oy, :ox] * (up * up)
            else:
                half = sfft.ifft(sl, axis=-1, workers=workers, overwrite_x=True)[..., :ox]
                out[b, j0:j0 + _PLANES] = sfft.ifft(half, axis=-2, workers=workers)[:, :oy]
        del spec
    return out


def forward_stolt(image: np.ndarray, shape: tuple[int, int], terms: TermsKey,
                  weights: np.ndarray, upsample: int = 1) -> np.ndarray:
    """The exact adjoint of :func:`adjoint_stolt`: image ``(B, nz, oy, ox)`` -> samples
    ``(B, nf, ny, nx)``.

    Each plane's spectrum (the adjoint of the cropped, interpolated inverse FFT); on
    every gridded column the adjoint of the length-M FFT (``M`` times its inverse, at
    the planes' rows) and of the cubic interpolation (each term gathers its four kz
    nodes with the conjugate weights); the rest's conjugate steps; the conjugate gains
    and weights; one inverse FFT per frequency.
    """
    T = _Terms.build(terms)
    work = terms.work
    My, Mx = T.grid
    workers = fft_workers(My * Mx)
    nz, nc, nf = terms.nz, T.live.size, terms.nf
    up = int(upsample)
    w = np.asarray(weights, dtype=float)
    out = np.empty((image.shape[0], nf, *shape), dtype=work)
    for b in range(image.shape[0]):
        R = np.empty((nz, nc), dtype=np.complex128)
        for j in range(nz):
            S = fold(fft2_padded(image[b, j], (up * My, up * Mx), work, workers), up)
            R[j] = S.reshape(-1)[T.live]
        A = np.zeros((nf, nc), dtype=np.complex128)
        for g in T.blocks():
            cols = T.gridded[g]
            V = np.zeros((cols.size, T.M), dtype=np.complex128)
            V[:, T.rows_z] = R[:, cols].T
            Gp = sfft.ifft(V, axis=-1, workers=workers, overwrite_x=True).ravel() * T.M
            acc = np.zeros((nf, cols.size), dtype=np.complex128)
            for shift, wt in T.nodes:
                acc += Gp[T.node_index(g, shift)].reshape(nf, cols.size) * wt[:, g]
            A[:, cols] += acc * np.conj(T.weight[:, g])
        cur = np.ones(T.rest_f.size, dtype=np.complex128)
        s_conj = np.conj(T.s_rest.astype(np.complex128))
        back = np.zeros(T.rest_f.size, dtype=np.complex128)
        for j in range(nz):
            k = int(T.n_on[j])
            if k == 0:
                break
            back[:k] += cur[:k] * R[j, T.rest_c[:k]]
            cur[:k] *= s_conj[:k]
        np.add.at(A, (T.rest_f, T.rest_c), back)
        H = np.zeros((nf, My * Mx), dtype=work)
        H[:, T.live] = (A * np.conj(T.gain) * w[:, None]).astype(work)
        out[b] = ifft2_cropped(H.reshape(nf, My, Mx), shape, workers, overwrite=True)
    return out
