"""The spectrum of a posed hologram on the world grid by a library non-uniform FFT.

The ground-frame imaging path (:mod:`.oblique`) needs the data's
spectrum on a horizontal reference plane at every world-grid wavenumber,

    H(k) = sum_e d_e exp(-i K.(r_e - r0)),   K = (p, q, -conj(kz)),

with the elements ``r_e = c + x'_j u + y'_i v`` on the aperture's uniform grid.
Per wavenumber ``K.(r_e - r0) = K.(c - r0) + s x'_j + t y'_i`` with ``s = K.u``,
``t = K.v``: a Fourier series of the data (uniform modes ``(i, j)``) evaluated at
the points ``(t dy', s dx')``, i.e. a type-2 non-uniform FFT (finufft,
``isign = -1``, modes centred on ``(ny // 2, nx // 2)``). ``s``, ``t`` are real
for the components that travel in the air (``kz`` real), which is where finufft
applies; it aims at a relative l2 error ``eps`` (:data:`EPS`: 1e-6 in complex128,
1e-5 in complex64; measured within 2 eps). The elements must lie on a uniform grid.

The components evanescent in the air (``kz = i kappa``) that the air gap keeps
(``kappa`` below the floor of :mod:`.oblique`) have complex
``s``, ``t`` when the aperture is tilted: they are summed directly, on that subset
only, factored by the aperture's axes (by grid column when ``x'`` lies along the
world ``x``, by grid row when ``y'`` lies along ``y``, then by Horner's rule along
the other axis; in full, in blocks, otherwise). The
element offsets are taken from the lowest corner, so every factor has a modulus
of at most 1 (no overflow however large the aperture's rise). A level aperture
has real ``s``, ``t`` for every component: finufft takes them all.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from ...._lazy import lazy_module
from ...._validate import uniform_step
from ....data.hologram import Hologram
from ....physics.propagation import TRANSFER_CACHE, spectral_axes

finufft = lazy_module("finufft")  # imported on first use: see holoradar._lazy

#: finufft's requested relative accuracy by working precision.
EPS = {np.dtype(np.complex128): 1e-6, np.dtype(np.complex64): 1e-5}

# Below this many targets finufft runs in one thread: its threads cost more than they
# save (measured 4-10x slower with two threads on a 175 x 315 grid, 19 000 targets).
_ONE_THREAD_BELOW = 2**17


def spectrum_nufft(geometry: Hologram, data: np.ndarray, kk: float, grid: tuple[int, int],
                   pitch: tuple[float, float], origin: tuple[float, float, float],
                   work: np.dtype, reach: float) -> np.ndarray:
    """``H(k)`` on the ``(My, Mx)`` world grid for every frame of ``data``.

    Parameters
    ----------
    geometry : Hologram
        The posed aperture (its pose and uniform element grid).
    data : numpy.ndarray
        ``(B, ny, nx)``, the samples.
    kk : float
        The sum's wavenumber, rad/m (``2 k`` for a transceiver's round trip).
    grid : (My, Mx)
        The world FFT grid.
    pitch : (dx, dy)
        Its pitch, metres.
    origin : (x0, y0, z_ref)
        The grid's first sample and the reference plane's world range, metres.
    work : numpy dtype
        complex64 or complex128: the working precision.
    reach : float
        The largest ``Im(kz)`` kept, rad/m: components evanescent in the air that
        decay faster are left out (zero).

    Returns
    -------
    numpy.ndarray
        Shape ``(B, My, Mx)``, dtype ``work``.
    """
    My, Mx = grid
    basis = _basis_of(geometry, kk, grid, pitch, origin, work, reach)
    d = np.ascontiguousarray(data.astype(work, copy=False))       # (B, ny, nx)
    H = np.zeros((d.shape[0], My * Mx), dtype=work)
    if basis.prop.size:
        H[:, basis.prop] = basis.execute(d) * basis.phase
    if basis.ev.size:
        H[:, basis.ev] = basis.evanescent(d)
    return H.reshape(d.shape[0], My, Mx)


def elements_nufft(geometry: Hologram, G: np.ndarray, kk: float, grid: tuple[int, int],
                   pitch: tuple[float, float], origin: tuple[float, float, float],
                   work: np.dtype, reach: float) -> np.ndarray:
    """The adjoint of :func:`spectrum_nufft`: a spectrum ``(B, My, Mx)`` on the world grid
    to ``(B, ny, nx)`` at the elements (a type-1 NUFFT, ``isign = +1``, at the same
    points, and the evanescent sums' transposes), to finufft's ``EPS``."""
    basis = _basis_of(geometry, kk, grid, pitch, origin, work, reach)
    Gf = G.reshape(G.shape[0], -1)
    out = np.zeros((G.shape[0], *basis.shape), dtype=work)
    if basis.prop.size:
        out += basis.execute_adjoint(np.ascontiguousarray(
            Gf[:, basis.prop] * np.conj(basis.phase)))
    if basis.ev.size:
        out += basis.evanescent_adjoint(Gf[:, basis.ev])
    return out


def _basis_of(geometry: Hologram, kk: float, grid: tuple[int, int], pitch: tuple[float, float],
              origin: tuple[float, float, float], work: np.dtype, reach: float) -> _NufftRemap:
    key = ("ground-nufft", grid, pitch, origin, kk, geometry.pose, geometry.x.tobytes(),
           geometry.y.tobytes(), work.str, round(reach, 6))
    return TRANSFER_CACHE.get(key, lambda: _NufftRemap.build(
        grid, pitch, origin, kk, geometry.pose, geometry.x, geometry.y, work, reach))


class _NufftRemap:
    """Cached points and phases of one geometry (see the module docstring).

    The evanescent sums are kept as the ratio ``z`` of consecutive element factors
    along the aperture axis that carries the decay (``exp(-i s dx')`` or
    ``exp(-i t dy')``, oriented so that ``|z| <= 1``) and evaluated by Horner's rule:
    memory ``O(n_ev)`` however large the grid. A pose with no aperture axis along a
    world axis keeps both factors per component, in chunks.
    """

    def __init__(self, shape: tuple[int, int], work: np.dtype, prop: np.ndarray,
                 pts: tuple[np.ndarray, np.ndarray], phase: np.ndarray, ev: np.ndarray,
                 ev_mode: str, ev_line: np.ndarray, ev_z: np.ndarray, ev_w: np.ndarray,
                 ev_phase: np.ndarray, fixed: np.ndarray, flip: tuple[bool, bool]) -> None:
        self.shape, self.work, self.prop, self.pts, self.phase = shape, work, prop, pts, phase
        self.ev, self.ev_mode, self.ev_line = ev, ev_mode, ev_line
        self.ev_z, self.ev_w, self.ev_phase, self.fixed, self.flip = \
            ev_z, ev_w, ev_phase, fixed, flip
        self._plans: dict[int, Any] = {}
        self._lock = threading.Lock()
        arrays = (prop, *pts, phase, ev, ev_line, ev_z, ev_w, ev_phase, fixed)
        self.nbytes = sum(a.nbytes for a in arrays)

    def execute(self, d: np.ndarray) -> np.ndarray:
        """The type-2 sums at the travelling components, ``(B, n_prop)``."""
        n = d.shape[0]
        with self._lock:                      # a finufft plan is not re-entrant
            plan = self._plans.get(n)
            if plan is None:
                threads = 1 if self.prop.size < _ONE_THREAD_BELOW else 0
                plan = finufft.Plan(2, self.shape, n_trans=n, eps=EPS[self.work], isign=-1,
                                    dtype=self.work.name, nthreads=threads)
                plan.setpts(*self.pts)
                self._plans[n] = plan
            out = plan.execute(d if n > 1 else d[0])
        return out.reshape(n, -1)

    def evanescent(self, d: np.ndarray) -> np.ndarray:
        """The direct sums at the kept air-evanescent components, ``(B, n_ev)`` in the
        order of ``self.ev``."""
        # Element offsets counted from the lowest corner: reverse an axis whose offsets
        # run negative, so that the k-th sample carries z**k.
        if self.flip[0]:
            d = d[..., ::-1]
        if self.flip[1]:
            d = d[..., ::-1, :]
        if self.ev_mode == "columns":
            # x' along x: one product at the grid's p (``fixed``: (Mx, nx)), then for each
            # component a polynomial in z along y' of its grid column's values.
            t = np.matmul(d, self.fixed.T)                             # (B, ny, Mx)
            return _horner(t, self.ev_line, self.ev_z) * self.ev_phase
        if self.ev_mode == "rows":
            t = np.swapaxes(np.matmul(self.fixed, d), 1, 2)           # (B, nx, My)
            return _horner(t, self.ev_line, self.ev_w) * self.ev_phase
        out = np.empty((d.shape[0], self.ev.size), dtype=self.work)
        nx, ny = d.shape[-1], d.shape[-2]
        for lo in range(0, self.ev.size, _CHUNK):
            sl = slice(lo, lo + _CHUNK)
            ea = _powers(self.ev_w[sl], nx)                           # (c, nx)
            eb = _powers(self.ev_z[sl], ny)                           # (c, ny)
            t = np.matmul(d, ea.T)                                     # (B, ny, c)
            out[:, sl] = np.einsum("bic,ci->bc", t, eb) * self.ev_phase[sl]
        return out

    def execute_adjoint(self, c: np.ndarray) -> np.ndarray:
        """The type-1 sums from the travelling components' values ``(B, n_prop)`` onto
        the element modes, ``(B, ny, nx)``: the adjoint of :meth:`execute`."""
        n = c.shape[0]
        with self._lock:
            plan = self._plans.get(-n)
            if plan is None:
                threads = 1 if self.prop.size < _ONE_THREAD_BELOW else 0
                plan = finufft.Plan(1, self.shape, n_trans=n, eps=EPS[self.work], isign=1,
                                    dtype=self.work.name, nthreads=threads)
                plan.setpts(*self.pts)
                self._plans[-n] = plan
            out = plan.execute(c.astype(self.work, copy=False) if n > 1 else
                               c[0].astype(self.work, copy=False))
        return out.reshape(n, *self.shape)

    def evanescent_adjoint(self, g: np.ndarray) -> np.ndarray:
        """The adjoint of :meth:`evanescent`: values at the kept air-evanescent
        components ``(B, n_ev)`` to ``(B, ny, nx)``."""
        g = g * np.conj(self.ev_phase)
        ny, nx = self.shape
        B = g.shape[0]
        if self.ev_mode == "columns":
            t = _horner_adjoint(g, self.ev_line, np.conj(self.ev_z), ny,
                                self.fixed.shape[0])                       # (B, ny, Mx)
            d = np.matmul(t, np.conj(self.fixed))                          # (B, ny, nx)
        elif self.ev_mode == "rows":
            t = _horner_adjoint(g, self.ev_line, np.conj(self.ev_w), nx,
                                self.fixed.shape[0])                       # (B, nx, My)
            d = np.matmul(np.conj(self.fixed).T, np.swapaxes(t, 1, 2))    # (B, ny, nx)
        else:
            d = np.zeros((B, ny, nx), dtype=self.work)
            for lo in range(0, self.ev.size, _CHUNK):
                sl = slice(lo, lo + _CHUNK)
                ea = np.conj(_powers(self.ev_w[sl], nx))                   # (c, nx)
                eb = np.conj(_powers(self.ev_z[sl], ny))                   # (c, ny)
                d += np.einsum("bc,ci,cj->bij", g[:, sl], eb, ea, optimize=True)
        if self.flip[1]:
            d = d[..., ::-1, :]
        if self.flip[0]:
            d = d[..., ::-1]
        return d

    @classmethod
    def build(cls, grid: tuple[int, int], pitch: tuple[float, float],
              origin: tuple[float, float, float], kk: float, pose: Any, xl: np.ndarray,
              yl: np.ndarray, work: np.dtype, reach: float) -> _NufftRemap:
        real = np.float32 if work == np.complex64 else np.float64
        Mx = grid[1]
        p, q = spectral_axes(grid, *pitch)
        P, Q = np.meshgrid(p, q)
        kz = np.sqrt((kk * kk - (P**2 + Q**2)).ravel().astype(complex))
        kz = np.where(kz.imag < 0, -kz, kz)
        u, v = np.asarray(pose.u, float), np.asarray(pose.v, float)
        c = np.asarray(pose.center, float) - np.asarray(origin, float)
        dxl = uniform_step(xl, "hologram.x") if xl.size > 1 else 1.0
        dyl = uniform_step(yl, "hologram.y") if yl.size > 1 else 1.0
        level = u[2] == 0 and v[2] == 0
        # Travelling in the air (or every kept one, for a level aperture: s, t real).
        travel = (kz.imag < reach) if level else (kz.imag == 0)
        prop = np.flatnonzero(travel)
        K = np.stack([P.ravel()[prop], Q.ravel()[prop], -np.conj(kz[prop])], axis=1)
        s, t = (K @ u).real, (K @ v).real
        # Modes centred on (ny // 2, nx // 2): the phase of that element is factored out.
        xc, yc = xl[xl.size // 2], yl[yl.size // 2]
        phase = np.exp(-1j * (K @ c + s * xc + t * yc)).astype(work)
        pts = tuple(np.ascontiguousarray(np.mod(w * h + np.pi, 2 * np.pi) - np.pi, dtype=real)
                    for w, h in ((t, dyl), (s, dxl)))
        # Evanescent in the air, kept, tilted aperture: the direct sums. Offsets from
        # the lowest corner (largest z), k steps of dx' (dy') away: factor z**k, |z| <= 1.
        ev = np.flatnonzero((kz.imag > 0) & (kz.imag < reach)) if not level \
            else np.zeros(0, np.intp)
        Ke = np.stack([P.ravel()[ev], Q.ravel()[ev], -np.conj(kz[ev])], axis=1)
        flip = (bool(u[2] > 0), bool(v[2] > 0))
        x0 = xl[-1] if flip[0] else xl[0]
        y0 = yl[-1] if flip[1] else yl[0]
        sx = -dxl if flip[0] else dxl
        sy = -dyl if flip[1] else dyl
        ev_phase = np.exp(-1j * (Ke @ (c + x0 * u + y0 * v))).astype(work)
        ev_w = np.exp(-1j * (Ke @ u) * sx).astype(work)
        ev_z = np.exp(-1j * (Ke @ v) * sy).astype(work)
        a = sx * np.arange(xl.size)
        b = sy * np.arange(yl.size)
        if u[1] == 0 and u[2] == 0:
            mode, line = "columns", ev % Mx
            fixed = np.exp(-1j * np.outer(p * u[0], a))               # (Mx, nx)
        elif v[0] == 0 and v[2] == 0:
            mode, line = "rows", ev // Mx
            fixed = np.exp(-1j * np.outer(q * v[1], b))               # (My, ny)
        else:
            mode, line, fixed = "full", np.zeros(0, np.intp), np.zeros((0, 0))
        fixed = fixed.astype(work)
        for arr in (prop, *pts, phase, ev, line, ev_z, ev_w, ev_phase, fixed):
            arr.setflags(write=False)
        return cls((yl.size, xl.size), work, prop, pts, phase, ev, mode, line, ev_z, ev_w,
                   ev_phase, fixed, flip)


_CHUNK = 4096  # components per block of the full evanescent sums


def _horner(t: np.ndarray, line: np.ndarray, z: np.ndarray) -> np.ndarray:
    """``sum_k z_m**k t[:, k, line_m]`` for every component ``m``: ``(B, n)``."""
    acc = np.zeros((t.shape[0], z.size), dtype=np.result_type(t, z))
    for k in range(t.shape[1] - 1, -1, -1):
        acc *= z
        acc += t[:, k, line]
    return acc


def _horner_adjoint(g: np.ndarray, line: np.ndarray, zc: np.ndarray, n: int,
                    width: int) -> np.ndarray:
    """The adjoint of :func:`_horner`: ``t[:, k, line_m] += zc_m**k g[:, m]`` for
    ``k < n``, ``zc`` the conjugate ratios; ``(B, n, width)``."""
    t = np.zeros((g.shape[0], n, width), dtype=np.result_type(g, zc))
    cur = g.copy()
    for k in range(n):
        for b in range(g.shape[0]):
            t[b, k] = np.bincount(line, cur[b].real, width) + 1j * np.bincount(
                line, cur[b].imag, width)
        cur *= zc
    return t


def _powers(z: np.ndarray, n: int) -> np.ndarray:
    """``z[:, None] ** arange(n)`` by repeated products (|z| <= 1: no overflow)."""
    out = np.empty((z.size, n), dtype=z.dtype)
    out[:, 0] = 1
    for k in range(1, n):
        np.multiply(out[:, k - 1], z, out=out[:, k])
    return out
