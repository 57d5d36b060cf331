"""The wideband phase-shift sum, compiled: one pass over each spectral column.

For every component ``(kx, ky)`` of the (padded) FFT grid that some frequency still
needs, the coherent image's spectrum on uniform planes ``z_j = z_0 + j dz`` is

    I(kx, ky, z_j) = sum_f A_f(kx, ky) s_f(kx, ky)^j,   j <= jmax_f(kx, ky),

``A_f`` the weighted spectrum taken to the first plane and ``s_f = exp(-i conj(Kz_f) dz)``
the plane-to-plane step (the same terms as :mod:`.kspace`, built by
:func:`.kspace.frequency_terms`: in a half-space the ground's
``Kz`` after the air gap's transfer; for a receiver array the normal plane wave's
incident phase). A compiled loop (numba) carries each column's ``nf`` terms from plane
to plane: ``nf`` complex multiply-adds per component and plane, run over blocks of
components in cache, real and imaginary parts apart so that the compiler vectorises
them. Each block of planes is then one pruned inverse FFT (along x over the rows that
hold components, cropped to the aperture, then along y).

The result is the phase-shift sum of :func:`.kspace.migrate_kspace`
to rounding: the recurrence's error grows by one rounding per step, ``~j eps``
(``eps`` = 6e-8 in complex64, 1.1e-16 in complex128).

numba is imported on the first call (not with holoradar); its compiled loop is cached
on disk (``cache=True``) next to this module (numba's own cache: it is written whether
or not Python writes bytecode, ``PYTHONDONTWRITEBYTECODE``), or under
``NUMBA_CACHE_DIR`` where the package's folder is read-only. :func:`warm` builds or
loads it ahead of the first call.
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from .... import _threads
from ...._lazy import lazy_module
from ...._threads import fft_workers, pool
from ....caches import named_cache
from ....physics.spectra import interpolate
from . import kspace
from . import terms as terms_mod
from .terms import TermsKey

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

__all__ = ["TINY", "adjoint_columns", "available", "loaded", "warm"]

_COLS = 256          # components per block of the compiled loop (its terms stay in cache)
_THREADED_TERMS = 1 << 22  # multiply-adds in one call worth sharing among threads
_GATHER_BYTES = 1 << 24  # padded spectra of a group of frequencies transformed together
_BUFFER_SHARE = 0.5  # inverse-FFT buffers at most this share of the output volume,
_BUFFER_MIN = 1 << 24  # or 16 MiB
#: A term whose weight fell below this fraction of its frequency's largest is dropped:
#: below the working precision's rounding (complex64: 6e-8), 1e-17 in complex128 (by
#: dtype character; the forward map drops the same terms).
TINY = {"F": 1e-9, "D": terms_mod.TINY}


def _plan_budget() -> int:
    """Bytes of column plans kept between calls: a sixteenth of the machine's memory,
    at least 256 MiB (a 64-frequency band on a 512 x 512 grid needs 326 MiB; rebuilt at
    every call it cost 1.1 s of 1.9)."""
    try:
        memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        memory = 0
    return max(256 * 2**20, int(memory) // 16)


#: The compiled sum's plans (one per geometry, band and planes), least recently used
#: out beyond :func:`_plan_budget`; :func:`holoradar.caches.clear_caches` frees them.
PLAN_CACHE = named_cache("column plans", max_bytes=_plan_budget())


def available() -> bool:
    """Whether numba can be imported (the compiled sum's only requirement)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


_KERNEL_LOCK = threading.Lock()


def loaded() -> bool:
    """Whether this process has loaded the compiled loop (numba imported, the loop
    built or read from its cache): a next call pays nothing for it."""
    return _build_kernel.cache_info().currsize > 0


def _kernel() -> Any:
    """The compiled column sum (numba, cached on disk; built on first use), built once
    even when a background :func:`warm` and the first migration ask at once."""
    with _KERNEL_LOCK:
        return _build_kernel()


@cache
def _build_kernel() -> Any:
    import numba

    def column_sum(ar, ai, sr, si, jm, bend, pos, order, n, j0, j1, zero, outv):
        # ar, ai (nf, nblocks, L): each term's value at plane j0 (updated in place to
        # j1); block-major (nblocks, nf, L): sr, si its step; jm its last plane; bend
        # (nblocks,) the last
        # plane of any term of a block; pos (nblocks, L) where component b * L + c goes
        # in a plane of outv (real part at 2 pos, imaginary at 2 pos + 1), which holds
        # zeros on entry; order: the blocks to do (a thread's share);
        # n components. Four planes per pass over a block's terms (the terms are read
        # and written once for four multiply-adds), then one plane at a time.
        nf, L = ar.shape[0], ar.shape[2]
        for t in range(order.size):
            b = order[t]
            if bend[b] < j0:
                continue
            m = min(L, n - b * L)
            p = pos[b]
            s_r, s_i, j_m = sr[b], si[b], jm[b]
            acc = np.empty((8, L), ar.dtype)
            stop = min(j1, bend[b] + 1)
            j = j0
            while j < stop:
                k = 4 if j + 4 <= stop else 1
                for c in range(L):
                    for q in range(2 * k):
                        acc[q, c] = zero
                a0r, a0i, a1r, a1i = acc[0], acc[1], acc[2], acc[3]
                a2r, a2i, a3r, a3i = acc[4], acc[5], acc[6], acc[7]
                for f in range(nf):
                    xr_, xi_, sr_, si_, jm_ = ar[f, b], ai[f, b], s_r[f], s_i[f], j_m[f]
                    if k == 4:
                        for c in range(L):
                            xr = xr_[c]
                            xi = xi_[c]
                            cr = sr_[c]
                            ci = si_[c]
                            last = jm_[c]
                            a0r[c] += xr
                            a0i[c] += xi
                            yr = xr * cr - xi * ci
                            yi = xr * ci + xi * cr
                            xr = yr if last > j else zero
                            xi = yi if last > j else zero
                            a1r[c] += xr
                            a1i[c] += xi
                            yr = xr * cr - xi * ci
                            yi = xr * ci + xi * cr
                            xr = yr if last > j + 1 else zero
                            xi = yi if last > j + 1 else zero
                            a2r[c] += xr
                            a2i[c] += xi
                            yr = xr * cr - xi * ci
                            yi = xr * ci + xi * cr
                            xr = yr if last > j + 2 else zero
                            xi = yi if last > j + 2 else zero
                            a3r[c] += xr
                            a3i[c] += xi
                            yr = xr * cr - xi * ci
                            yi = xr * ci + xi * cr
                            xr_[c] = yr if last > j + 3 else zero
                            xi_[c] = yi if last > j + 3 else zero
                    else:
                        for c in range(L):
                            xr = xr_[c]
                            xi = xi_[c]
                            a0r[c] += xr
                            a0i[c] += xi
                            yr = xr * sr_[c] - xi * si_[c]
                            yi = xr * si_[c] + xi * sr_[c]
                            xr_[c] = yr if jm_[c] > j else zero
                            xi_[c] = yi if jm_[c] > j else zero
                for q in range(k):
                    o = outv[j + q - j0]
                    for c in range(m):
                        o[2 * p[c]] = acc[2 * q, c]
                        o[2 * p[c] + 1] = acc[2 * q + 1, c]
                j += k

    options = dict(fastmath=False, nogil=True, error_model="numpy")
    try:
        return numba.njit(cache=True, **options)(column_sum)
    except RuntimeError:   # no writable cache folder (read-only install, no NUMBA_CACHE_DIR)
        return numba.njit(cache=False, **options)(column_sum)


def warm(precisions: tuple[type, ...] = (np.float32, np.float64)) -> None:
    """Import numba and load (or, the first time, compile and cache) the compiled loop in
    both precisions (or those of ``precisions``: ``np.float32`` for complex64 work,
    ``np.float64`` for complex128), so that the next wideband ``migrate`` does not pay
    for it.

    For a long-lived process (a viewer, a server) to call at start-up, e.g. in a
    background thread; and once after installing, to build the on-disk cache (the
    first compilation takes seconds, loading it later a fraction of one).
    """
    kernel = _kernel()

    def frozen(a: np.ndarray) -> np.ndarray:
        a.setflags(write=False)   # as a ColumnPlan's arrays are: numba types them apart
        return a

    for real in precisions:
        z = np.zeros((1, 1, _COLS), dtype=real)
        kernel(z, z.copy(), frozen(z.copy()), frozen(z.copy()),
               frozen(np.zeros((1, 1, _COLS), np.int32)), frozen(np.zeros(1, np.int32)),
               frozen(np.zeros((1, _COLS), np.int64)), np.zeros(1, np.int64),
               0, 0, 1, real(0), np.zeros((1, 2), dtype=real))


def _run(kernel: Any, plan: ColumnPlan, ar: np.ndarray, ai: np.ndarray, j0: int, j1: int,
         zero: Any, outv: np.ndarray) -> None:
    """Planes ``j0 .. j1 - 1`` of the compiled sum into ``outv``, the blocks shared
    among the process's threads when the work is worth it (the loop releases the GIL).

    The blocks go round-robin (the deepest-reaching come first, so each thread gets its
    share of long and short ones); they write disjoint components.
    """
    live = np.flatnonzero(plan.bend >= j0)
    work = int(np.minimum(plan.bend[live] + 1, j1).sum() - j0 * live.size) * plan.nf * _COLS
    nt = min(_threads.POOL_SIZE, live.size)
    if nt < 2 or work < _THREADED_TERMS:
        kernel(ar, ai, plan.sr, plan.si, plan.jm, plan.bend, plan.pos, live, plan.live.size,
               j0, j1, zero, outv)
        return
    list(pool().map(lambda i: kernel(ar, ai, plan.sr, plan.si, plan.jm, plan.bend, plan.pos,
                                     np.ascontiguousarray(live[i::nt]), plan.live.size,
                                     j0, j1, zero, outv),
                    range(nt)))


def adjoint_columns(data: np.ndarray, terms: TermsKey, weights: np.ndarray,
                    upsample: int = 1) -> np.ndarray:
    """The coherent wideband image on the uniform planes of ``terms`` by the compiled
    column sum.

    Parameters
    ----------
    data : numpy.ndarray
        ``(B, nf, ny, nx)``: a transceiver's, or a receiver array's lit by a normal
        plane wave (or none: phase 0 at the aperture assumed).
    terms : TermsKey
        The band, the planes (uniformly spaced, all in the medium's deepest region),
        the layers (lossless, or loss left uncompensated), the model's factors, the
        FFT grid and the working dtype (:class:`.terms.TermsKey`); its ``tiny`` is
        used as given (``TINY[work.char]`` is the compiled loop's own).
    weights : numpy.ndarray
        One weight per frequency.
    upsample : int
        Output pixels per pitch, as in :func:`holoradar.migrate`.

    Returns
    -------
    numpy.ndarray
        ``(B, nz, ny', nx')``: the same sum as :func:`.kspace.adjoint_kspace`, to
        rounding; its exact adjoint is :func:`.kspace.forward_kspace` with the same
        ``terms``.

    Examples
    --------
    Through :func:`holoradar.migrate` (``algorithm="columns"``), which makes the key
    from its plan (:meth:`.terms.TermsKey.of`).
    """
    ny, nx = data.shape[-2:]
    work, zs_size, grid = terms.work, terms.nz, terms.grid
    real = np.float32 if work == np.complex64 else np.float64
    workers = fft_workers(grid[0] * grid[1])
    weights = np.asarray(weights, dtype=float)
    u = int(upsample)
    direct = u == 1 and grid == (ny, nx)
    plan = PLAN_CACHE.get(("columns", terms, direct), lambda: ColumnPlan.build(terms, direct))
    oy, ox = u * (ny - 1) + 1, u * (nx - 1) + 1
    out = np.empty((data.shape[0], zs_size, oy, ox), dtype=work)
    run = _kernel()
    My, Mx = grid
    zero = real(0)
    if plan.direct:
        # Unpadded, no interpolation: the compiled loop writes the spectra into the
        # output itself, transformed there in place.
        chunk = 16
        for b in range(data.shape[0]):
            ar, ai = plan.gather(data[b], weights, work, workers)
            for j0 in range(0, zs_size, chunk):
                j1 = min(zs_size, j0 + chunk)
                o = out[b, j0:j1]
                o.fill(0)
                _run(run, plan, ar, ai, j0, j1, zero, o.view(real).reshape(j1 - j0, -1))
                done = sfft.ifft2(o, axes=(-2, -1), workers=workers, overwrite_x=True)
                if not np.shares_memory(done, o):
                    o[...] = done
    else:
        nr = plan.rows.size
        per_plane = (nr * u * Mx + 2 * u * My * ox) * work.itemsize
        budget = max(_BUFFER_SHARE * out[0].nbytes, _BUFFER_MIN)
        chunk = int(max(1, min(32, budget // per_plane)))
        buf = np.empty((chunk, nr, Mx), dtype=work)
        for b in range(data.shape[0]):
            ar, ai = plan.gather(data[b], weights, work, workers)
            for j0 in range(0, zs_size, chunk):
                j1 = min(zs_size, j0 + chunk)
                m = j1 - j0
                buf.fill(0)
                _run(run, plan, ar, ai, j0, j1, zero, buf.view(real).reshape(chunk, -1))
                nr_j = int(np.count_nonzero(plan.row_reach >= j0))
                xb = buf[:m, :nr_j]
                xb = interpolate(xb, u, -1)
                half = sfft.ifft(xb, axis=-1, workers=workers, overwrite_x=True)
                cols = np.zeros((m, My, ox), dtype=work)
                cols[:, plan.rows[:nr_j]] = half[..., :ox]
                yb = interpolate(cols, u, -2)
                planes = sfft.ifft(yb, axis=-2, workers=workers, overwrite_x=True)
                if u > 1:
                    np.multiply(planes[:, :oy], u * u, out=out[b, j0:j1])
                else:
                    out[b, j0:j1] = planes[:, :oy]
    return out


@dataclass
class ColumnPlan:
    """What a geometry needs for the compiled sum, built once (cached with the
    transfer functions): the live components in row order, and per frequency their
    gain to the first plane, their step (real and imaginary parts apart) and the last
    plane each takes part in."""

    grid: tuple[int, int]
    live: np.ndarray   # (n,) flat indices into the padded grid, deepest-reaching first
    gain: np.ndarray   # (nf, nblocks * _COLS) conj transfer to the first plane (work
    #                    dtype), 0 past n and where a term is never used
    src: np.ndarray    # (nblocks * _COLS,) live, then 0 up to a whole block (gain 0)
    sr: np.ndarray     # (nf, n) step, real part
    si: np.ndarray     # (nf, n) step, imaginary part
    jm: np.ndarray     # (nf, n) int32 last plane (-1: never)
    bend: np.ndarray   # (nblocks,) int32 last plane of any term of a block of _COLS
    rows: np.ndarray   # (nr,) grid rows holding live components, deepest-reaching first
    row_reach: np.ndarray  # (nr,) the last plane any component of each row reaches
    pos: np.ndarray    # (nblocks, _COLS) where each component goes in a plane: its flat
    #                    grid index (direct) or its index in a (nr, Mx) plane of rows
    direct: bool       # the grid is the output's: spectra written into the output itself

    @property
    def nf(self) -> int:
        return self.gain.shape[0]

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in (self.live, self.gain, self.src, self.sr, self.si,
                                      self.jm,
                                      self.bend, self.rows, self.row_reach, self.pos))

    @classmethod
    def build(cls, terms: TermsKey, direct: bool) -> ColumnPlan:
        grid, work, ks = terms.grid, terms.work, terms.ks
        Mx = grid[1]
        gain_q, step_q, jmax, unfold = kspace.frequency_terms(terms)
        reach = jmax.max(axis=0)
        live = np.flatnonzero(reach >= 0)
        # Deepest-reaching first (stable: grid order among equals), so that the blocks
        # still needed at a plane are a prefix and a block's terms end together.
        live = live[np.argsort(-reach[live], kind="stable")]
        n = live.size
        nb = max(1, -(-n // _COLS))
        q_idx = unfold[live]
        jm = jmax[:, live]
        gain = np.zeros((len(ks), nb * _COLS), dtype=work)
        gain[:, :n] = np.where(jm < 0, 0, gain_q[:, q_idx])
        src = np.zeros(nb * _COLS, dtype=np.intp)
        src[:n] = live
        real = np.float32 if work == np.complex64 else np.float64

        def blocked(values: np.ndarray, fill: Any, dtype: Any) -> np.ndarray:
            out = np.full((values.shape[0], nb * _COLS), fill, dtype=dtype)
            out[:, :n] = values
            return np.ascontiguousarray(out.reshape(-1, nb, _COLS).transpose(1, 0, 2))

        step = step_q[:, q_idx]
        bend = np.full(nb, -1, dtype=np.int32)
        if n:
            bend[:] = np.maximum.reduceat(reach[live], np.arange(0, n, _COLS))
        # The row buffer of the inverse FFT holds the rows deepest-reaching first, so
        # that the rows still needed at a plane are a prefix (transformed alone).
        rows = live // Mx
        row_reach = np.full(grid[0], -1, dtype=np.int64)
        np.maximum.at(row_reach, rows, reach[live])
        used_rows = np.argsort(-row_reach, kind="stable")[:np.count_nonzero(row_reach >= 0)]
        rank = np.empty(grid[0], dtype=np.int64)
        rank[used_rows] = np.arange(used_rows.size)
        pos = np.zeros(nb * _COLS, dtype=np.int64)
        pos[:n] = live if direct else rank[rows] * Mx + live % Mx
        plan = cls(grid, live, gain, src, blocked(step.real, 0, real), blocked(step.imag, 0, real),
                   blocked(jm, -1, np.int32), bend, used_rows, row_reach[used_rows],
                   pos.reshape(nb, _COLS), direct)
        for arr in (plan.live, plan.gain, plan.src, plan.sr, plan.si, plan.jm, plan.bend,
                    plan.rows, plan.row_reach, plan.pos):
            arr.setflags(write=False)
        return plan

    def gather(self, data: np.ndarray, weights: np.ndarray, work: np.dtype, workers: int
               ) -> tuple[np.ndarray, np.ndarray]:
        """The live components of ``data`` (nf, ny, nx), weighted and taken to the first
        plane: real and imaginary parts, each (nf, nblocks, _COLS), ready for the
        compiled loop.

        Frequencies in groups of about ``_GATHER_BYTES`` of padded spectra: each group's
        pruned forward FFTs run in place in one zero-padded array (along x over the
        recorded rows, then along y), then its live components are taken, weighted and
        split into real and imaginary parts, frequency-major as the loop reads them.
        """
        My, Mx = self.grid
        ny, nx = data.shape[-2:]
        real = np.float32 if work == np.complex64 else np.float64
        nf, (nb, L) = self.nf, self.sr.shape[::2]
        ar = np.empty((nf, nb, L), dtype=real)
        ai = np.empty_like(ar)
        group = int(max(1, min(nf, _GATHER_BYTES // (My * Mx * work.itemsize))))
        spec = np.empty((group, My, Mx), dtype=work)
        terms = np.empty((group, nb * L), dtype=work)
        w = np.asarray(weights, dtype=float)
        for f0 in range(0, nf, group):
            g = min(group, nf - f0)
            sp, te = spec[:g], terms[:g]
            if (My, Mx) != (ny, nx):
                sp.fill(0)
            sp[:, :ny, :nx] = data[f0:f0 + g]
            rows = sfft.fft(sp[:, :ny], axis=-1, workers=workers, overwrite_x=True)
            if not np.may_share_memory(rows, sp):   # overwrite_x is a hint
                sp[:, :ny] = rows
            full = sfft.fft(sp, axis=-2, workers=workers, overwrite_x=True)
            # Fancy indexing, not np.take(..., axis=1, out=): 2x faster here (measured).
            np.multiply(full.reshape(g, -1)[:, self.src], self.gain[f0:f0 + g], out=te)
            if np.any(w[f0:f0 + g] != 1):
                te *= w[f0:f0 + g, None].astype(work)
            ar[f0:f0 + g] = te.real.reshape(g, nb, L)
            ai[f0:f0 + g] = te.imag.reshape(g, nb, L)
        return ar, ai
