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
needed (lossless layers, or ``compensate_loss=False``) (the ``"kspace"`` backend
of :mod:`holoradar.imaging.migration` says what blocks it). :func:`forward_kspace`
is the exact adjoint of the same sum: ``H_f = sum_j conj(w_f gain_f step_f^j) R_j`` over
the planes each term reaches, ``R_j`` the spectrum of image plane j.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...._lazy import lazy_module
from ...._threads import fft_workers
from ....physics.propagation import (
    TRANSFER_CACHE,
    inverse_kz,
    lateral_travel,
    spectral_axes,
    spectral_quadrant,
    spectral_step,
    two_way_transfer,
)
from ....physics.spectra import fft2_padded, fold, ifft2_cropped, interpolate
from .terms import TINY, TermsKey

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

_CHUNK = 8      # planes per inverse-FFT batch (memory: _CHUNK padded planes)
_BLOCK = 2048   # spectral components per cache block of the recurrence


def adjoint_kspace(data: np.ndarray, terms: TermsKey, weights: np.ndarray,
                   upsample: int = 1) -> np.ndarray:
    """The coherent image on the uniform planes of ``terms`` (see the module docstring).

    ``data``: ``(B, nf, ny, nx)``; returns ``(B, nz, oy, ox)``; ``weights`` one per
    frequency; ``upsample`` the output's pixels per pitch.
    """
    ny, nx = data.shape[-2:]
    workers = fft_workers(terms.grid[0] * terms.grid[1])
    weights = np.asarray(weights, dtype=float)
    plan = TRANSFER_CACHE.get(("kspace", terms), lambda: _Plan.build(terms))
    Hc = plan.gather(data, weights, terms.work, workers)
    u = int(upsample)
    oy, ox = u * (ny - 1) + 1, u * (nx - 1) + 1
    out = np.empty((data.shape[0], terms.nz, oy, ox), dtype=terms.work)
    plan.sum_planes(Hc, out, u, workers)
    return out


def forward_kspace(image: np.ndarray, shape: tuple[int, int], terms: TermsKey,
                   weights: np.ndarray, upsample: int = 1) -> np.ndarray:
    """The exact adjoint of :func:`adjoint_kspace` (and of the compiled sum with its
    ``terms.tiny``): image ``(B, nz, oy, ox)`` -> samples ``(B, nf, ny, nx)``.

    Each image plane's spectrum (the adjoint of the cropped, interpolated inverse
    FFT) meets every frequency's terms: ``H_f += conj(w_f gain_f step_f^j) R_j`` while
    plane ``j`` is within the term's reach; one inverse FFT per frequency.
    """
    ny, nx = shape
    My, Mx = terms.grid
    work = terms.work
    workers = fft_workers(My * Mx)
    w = np.asarray(weights, dtype=float)
    gain, step, jmax, unfold = frequency_terms(terms)
    # Conjugated, weighted and on the whole grid: the forward terms.
    cur = np.conj(gain[:, unfold]) * w[:, None].astype(work)
    back = np.conj(step[:, unfold])
    u = int(upsample)
    B = image.shape[0]
    H = np.zeros((B, terms.nf, My * Mx), dtype=work)
    for j in range(terms.nz):
        R = fold(fft2_padded(image[:, j], (u * My, u * Mx), work, workers), u)
        live = jmax >= j
        H += np.where(live, cur, 0)[None] * R.reshape(B, 1, -1)
        cur *= back
    return ifft2_cropped(H.reshape(B, terms.nf, My, Mx), (ny, nx), workers, overwrite=True)


@dataclass
class _Plan:
    """What a geometry needs, built once (cached with the transfer functions).

    The components some frequency still needs, ordered by the last plane they
    reach (so the live ones are a shrinking prefix) and stored block by block
    (each block contiguous, so that the recurrence runs in cache); per frequency
    their gain at the first plane and step to the next; and the drops: a
    component of one frequency that leaves while its block goes on.
    """

    grid: tuple[int, int]
    order: np.ndarray       # (n,) flat indices into the padded grid
    gain: np.ndarray        # (nb, nf, _BLOCK) conj transfer to the first plane
    step: np.ndarray        # (nb, nf, _BLOCK) plane-to-plane factor
    block_end: np.ndarray   # (nb,) last plane any component of a block reaches
    n_live: np.ndarray      # (nz,) live prefix at each chunk of planes
    f_ev: np.ndarray        # drops (frequency, index in block), by (block, plane)
    c_ev: np.ndarray
    ptr: np.ndarray         # CSR pointers into the drops, block * (nz + 1) + plane
    scatter: list           # per chunk: (live rows, index into a buffer of those rows)

    @property
    def nf(self) -> int:
        return self.gain.shape[1]

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in (self.order, self.gain, self.step, self.block_end,
                                      self.n_live, self.f_ev, self.c_ev, self.ptr,
                                      *(a for pair in self.scatter for a in pair)))

    @classmethod
    def build(cls, terms: TermsKey) -> _Plan:
        grid, nz, nf = terms.grid, terms.nz, terms.nf
        Mx = grid[1]
        gain, step, jmax, unfold = frequency_terms(terms)
        reach = jmax.max(axis=0)
        live = np.flatnonzero(reach >= 0)
        # Live ones first, chunk of planes by chunk (a prefix for each chunk), in grid
        # order within a chunk (the scatter into the grid then runs forwards).
        order = live[np.argsort((-(reach[live] // _CHUNK)).astype(_small_int(nz)),
                                kind="stable")]   # a radix sort on small integers
        reach, jm = reach[order], jmax[:, order]
        del jmax
        n = order.size
        nb = -(-n // _BLOCK)
        blocked = np.zeros(nb * _BLOCK, dtype=np.intp)
        blocked[:n] = unfold[order]
        gain, step = gain[:, blocked], step[:, blocked]
        gain[:, :n][jm < 0] = 0              # a frequency that never needs it
        gain[:, n:] = 0
        gain = np.ascontiguousarray(gain.reshape(nf, nb, _BLOCK).transpose(1, 0, 2))
        step = np.ascontiguousarray(step.reshape(nf, nb, _BLOCK).transpose(1, 0, 2))
        cls_ = reach // _CHUNK
        n_live = np.searchsorted(-cls_, -(np.arange(nz) // _CHUNK), side="right")
        block_end = np.maximum.reduceat(reach, np.arange(0, n, _BLOCK)) if n else reach
        f_ev, c_ev = np.nonzero((jm >= 0) & (jm < np.repeat(block_end, _BLOCK)[:n]))
        key = (c_ev // _BLOCK) * (nz + 1) + jm[f_ev, c_ev]
        srt = np.argsort(key.astype(_small_int(nb * (nz + 1))), kind="stable")
        ptr = np.searchsorted(key[srt], np.arange(nb * (nz + 1) + 1))
        # Where each chunk's live components go in its inverse FFT's buffer of live rows.
        scatter = []
        for c0 in range(0, nz, _CHUNK):
            m = min(n, -(-int(n_live[c0]) // _BLOCK) * _BLOCK)
            rows = order[:m] // Mx
            used = np.unique(rows)
            scatter.append((used, np.searchsorted(used, rows) * Mx + order[:m] % Mx))
        plan = cls(grid, order, gain, step, block_end, n_live, f_ev[srt].astype(np.intp),
                   (c_ev[srt] % _BLOCK).astype(np.intp), ptr, scatter)
        for arr in (plan.order, plan.gain, plan.step, plan.block_end, plan.n_live, plan.f_ev,
                    plan.c_ev, plan.ptr, *(a for pair in scatter for a in pair)):
            arr.setflags(write=False)
        return plan

    def gather(self, data: np.ndarray, weights: np.ndarray, work: np.dtype,
               workers: int) -> np.ndarray:
        """The live spectral components of ``data`` (``(B, nf, ny, nx)``), weighted
        and taken to the first plane, block by block: ``(nb, B, nf, _BLOCK)``.

        One frequency at a time (the padded spectra of all of them are never held
        at once): a pruned forward FFT, along x over the recorded rows only, then
        along y.
        """
        My, Mx = self.grid
        B = data.shape[0]
        nb = self.gain.shape[0]
        idx = np.zeros(nb * _BLOCK, dtype=np.intp)
        idx[:self.order.size] = self.order
        Hc = np.empty((nb, B, self.nf, _BLOCK), dtype=work)
        for i in range(self.nf):
            H = sfft.fft(data[:, i].astype(work, copy=False), n=Mx, axis=-1, workers=workers)
            H = sfft.fft(H, n=My, axis=-2, workers=workers, overwrite_x=True)
            H = H.reshape((B, My * Mx))[:, idx].reshape((B, nb, _BLOCK)).transpose(1, 0, 2)
            np.multiply(H, self.gain[:, None, i] * work.type(weights[i]), out=Hc[:, :, i])
        return Hc

    def sum_planes(self, Hc: np.ndarray, out: np.ndarray, u: int, workers: int) -> None:
        """``out[b, j] = crop(ifft2(sum_f H[b, f] step[f]^j))`` with the drops.

        The recurrence runs block by block through a chunk of planes, each block's
        data and steps contiguous and in cache. ``Hc`` (from :meth:`gather`) is
        consumed.
        """
        B = Hc.shape[1]
        nz, oy, ox = out.shape[-3:]
        size = self.order.size
        ptr = self.ptr.tolist()              # Python ints: no NumPy scalar per plane
        block_end = self.block_end.tolist()
        add = np.add.reduce                  # np.sum without its wrapper, per plane
        for c0 in range(0, nz, _CHUNK):
            c1 = min(nz, c0 + _CHUNK)
            # Whole blocks: a live block's tail (already zeroed by its drops) comes along.
            n_blocks = -(-int(self.n_live[c0]) // _BLOCK)
            spec = np.empty((B, c1 - c0, n_blocks * _BLOCK), dtype=Hc.dtype)
            for b in range(n_blocks):
                s0, s1 = b * _BLOCK, (b + 1) * _BLOCK
                hb, sb = Hc[b], self.step[b]
                j1 = min(c1, block_end[b] + 1)
                for j in range(c0, j1):
                    add(hb, axis=1, out=spec[:, j - c0, s0:s1])
                    hb *= sb
                    e0, e1 = ptr[b * (nz + 1) + j], ptr[b * (nz + 1) + j + 1]
                    if e1 > e0:
                        hb[:, self.f_ev[e0:e1], self.c_ev[e0:e1]] = 0
                spec[:, j1 - c0:, s0:s1] = 0
            m = min(size, n_blocks * _BLOCK)
            out[:, c0:c1] = _inverse_cropped(spec[..., :m], self.order[:m],
                                             self.scatter[c0 // _CHUNK], self.grid, (oy, ox),
                                             u, workers)


def frequency_terms(terms: TermsKey
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per frequency, on one quadrant of the spectrum: the conjugate transfer to the
    first plane (a receiver array's: times the conjugate of a normal plane wave's
    incident factor, ``terms.incident`` "phase" ``E0/|E0|`` or "field" ``E0``, or
    "none"; with ``terms.point_area``, a receiver array's voxels of that cell as point
    scatterers: times ``conj(2 pi i/(kz dA))``, and with ``terms.pol`` the vector
    model's dipole factor, :mod:`holoradar.imaging.migration.units`), the
    plane-to-plane step ``exp(-i conj(Kz) dz)``, and the last plane each component of
    the full grid takes part in (-1: none; a frequency whose ``terms.used`` is False
    takes part nowhere). A term whose weight has fallen below ``terms.tiny`` of its
    frequency's largest is dropped (see :func:`_last_planes`).

    Returns ``(gain, step, jmax, unfold)``: ``gain`` and ``step`` of shape (nf, quadrant
    size) in ``terms.work``; ``jmax`` (nf, My * Mx) int32 on the full grid; ``unfold``
    the quadrant index of every grid component (:func:`spectral_quadrant`). Everything
    depends on ``|p|`` and ``|q|`` only: computed on one quadrant (four times less work
    for a cold start).
    """
    grid, (dx, dy), medium, mono = terms.grid, terms.pitch, terms.medium, terms.mono
    z0, dz, nz, incident = terms.z0, terms.dz, terms.nz, terms.incident
    point_area, pol = terms.point_area, terms.pol
    p, q, kappa2, unfold = spectral_quadrant(grid, dx, dy)
    last = medium.n_regions - 1
    n_last = medium.n(last)
    nf = terms.nf
    shape = (nf, p.size * q.size)
    gain, step = np.empty(shape, dtype=terms.work), np.empty(shape, dtype=terms.work)
    jmax = np.empty(shape, dtype=np.int32)
    for i, k in enumerate(terms.ks):
        if mono:
            a = np.conj(two_way_transfer(k, medium, kappa2, z0))
            Kz = 2 * medium.kz(k, kappa2 / 4, last)
            t0 = 0.5 * lateral_travel(k, medium, kappa2 / 4, z0)
            evanescent = kappa2 > 4 * k * k
        else:
            a = np.conj(medium.vertical_transfer(k, kappa2, z0, 0.0))
            Kz = medium.kz(k, kappa2, last)
            t0 = lateral_travel(k, medium, kappa2, z0)
            evanescent = kappa2 > k * k
            if incident != "none":
                e0 = complex(medium.vertical_transfer(k, np.array(0.0), 0.0, z0))
                a = a * (np.conj(e0) / abs(e0) if incident == "phase" else np.conj(e0))
            if point_area is not None:   # conj of the point unit's 2 pi i <1/kz> / dA
                a = a * np.conj(2j * np.pi * inverse_kz(
                    k * n_last, np.sqrt(kappa2), spectral_step(*spectral_axes(
                        grid, dx, dy))) / point_area)
        if pol is not None:   # the dipole's G_uu (real: its own conjugate)
            legs, kk = (2, 2 * k) if mono else (1, k)
            a = a * (1 - ((pol[0] * p[None, :] + pol[1] * q[:, None]) / kk) ** 2) ** legs
        rate = np.where(Kz.real > 0, 1 / np.where(Kz.real > 0, Kz.real, 1), np.inf)
        s = np.exp(-1j * np.conj(Kz) * dz)
        if not mono and incident == "phase":
            s = s * np.exp(-1j * (k * n_last).real * dz)
        elif not mono and incident == "field":   # E0 grows by exp(i k n dz) a plane
            s = s * np.exp(-1j * np.conj(k * n_last) * dz)
        gain[i], step[i] = a.ravel(), s.ravel()
        # The band limit at the first plane (jmax < 0) is the per-plane one.
        jmax[i] = _last_planes(a, s, evanescent, p, q, t0, rate, dz, grid, (dx, dy),
                               nz, terms.tiny).ravel() if terms.used[i] else -1
    return gain, step, jmax[:, unfold], unfold


def _small_int(top: int) -> type:
    """The smallest signed integer type holding ``-top..top`` (numpy sorts 16-bit
    integers by radix, stably and fast)."""
    return np.int16 if top < 2**15 else np.int32 if top < 2**31 else np.int64


def _last_planes(a: np.ndarray, step: np.ndarray, evanescent: np.ndarray, p: np.ndarray,
                 q: np.ndarray, t0: np.ndarray, rate: np.ndarray, dz: float,
                 grid: tuple[int, int], pitch: tuple[float, float], nz: int,
                 tiny: float = TINY) -> np.ndarray:
    """The last plane index each component takes part in (-1: none, at most nz - 1).

    Band limit: the lateral shift ``|p| t(z)``, ``t(z) = t0 + (z - z0) rate``, must
    stay within half the grid (as in the per-plane transfer). Decay: a component
    whose weight ``|a| |step|^j`` has fallen below ``tiny`` (default :data:`.terms.TINY`) of the
    frequency's largest is zero to rounding (evanescent waves, absorption).
    """
    My, Mx = grid
    dx, dy = pitch
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        room = np.minimum(np.where(p[None, :] != 0, Mx * dx / 2 / np.abs(p[None, :]), np.inf),
                          np.where(q[:, None] != 0, My * dy / 2 / np.abs(q[:, None]), np.inf))
        j_band = np.floor((room - t0) / (rate * dz))
        j_band = np.where(evanescent, np.inf, np.nan_to_num(j_band, nan=np.inf, neginf=-1))
        # A grazing component (kz = 0, e.g. the Nyquist column of a lambda/2 grid) has
        # no finite travel: out of the band from the first plane on, as per plane.
        j_band = np.where(np.isinf(t0) & ~evanescent, -1, j_band)
        mag = np.abs(a)
        floor = tiny * mag.max(initial=0.0)
        decay = np.abs(step)
        j_decay = np.where(decay < 1, np.floor(np.log(floor / mag) / np.log(decay)), np.inf)
        j_decay = np.where(mag > floor, np.nan_to_num(j_decay, nan=np.inf), -1)
    return np.clip(np.minimum(j_band, j_decay), -1, nz - 1).astype(np.int32)


def _inverse_cropped(spec: np.ndarray, flat: np.ndarray, scatter: tuple, grid: tuple[int, int],
                     crop: tuple[int, int], u: int, workers: int) -> np.ndarray:
    """Inverse 2-D FFT of sparse spectra (values ``spec[..., m]`` at flat indices
    ``flat`` of a ``grid``), interpolated ``u`` times (zero padding of the
    spectrum) and cropped to ``crop``: along x over the live rows only
    (``scatter``: those rows, and where each value goes in a buffer of them),
    crop, then along y."""
    My, Mx = grid
    oy, ox = crop
    lead = spec.shape[:-1]
    used, pos = scatter
    buf = np.zeros((*lead, used.size * Mx), dtype=spec.dtype)
    for i in np.ndindex(lead):   # one index at a time: much faster than broadcast
        buf[i][pos] = spec[i]
    buf = interpolate(buf.reshape((*lead, used.size, Mx)), u, -1)
    half = sfft.ifft(buf, axis=-1, workers=workers, overwrite_x=True)[..., :ox]
    cols = np.zeros((*lead, My, ox), dtype=spec.dtype)
    cols[..., used, :] = half
    planes = sfft.ifft(interpolate(cols, u, -2), axis=-2, workers=workers,
                       overwrite_x=True)[..., :oy, :]
    return planes * (u * u) if u > 1 else planes
