"""Plane by plane: the angular spectrum (``"frequency"``) and the Fresnel kernel (``"fresnel"``).

Per frequency and plane the migration is

    I_z = C( G( conj(U_z) * F(P h) ) ),

``P`` the zero padding onto the FFT grid (``pad``), ``F`` the FFT, ``U_z`` the
transfer from range z to the aperture (:class:`~holoradar.AngularSpectrum` or
:class:`~holoradar.Fresnel`, with the loss compensation's real gain when asked), ``G``
the inverse FFT (with ``upsample = u > 1``: ``u^2`` times that of the spectrum
zero-padded ``u`` times) and ``C`` the crop to the aperture's footprint (``fov="full"``:
the roll that centres it). A band's images are weighted (``w_f``), multiplied by the
illumination's ``conj(psi)`` and added (or kept apart). The forward map is the exact
adjoint, ``h = P^T F^-1( U_z * fold(F(C^T I_z)) )`` summed over planes
(:mod:`~holoradar.physics.spectra`).

Where ``psi`` is one number per plane (a transceiver, a normal plane wave, none) the
frequencies of one FFT grid are summed in the spectrum, before one inverse FFT per
plane (the same image to rounding, one inverse FFT instead of one per frequency).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .... import _threads
from ...._lazy import lazy_module
from ...._threads import pool
from ....physics.propagation import AngularSpectrum, Fresnel, PlaneOperator
from ....physics.spectra import fft2_padded, fold, ifft2_cropped, interpolate
from .. import illumination, units
from ..plan import MigrationPlan
from .base import Backend

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

__all__ = ["FresnelPlanes", "PlaneByPlane"]

_CHUNK = 8  # planes per batched inverse FFT
_THREADED_MULTIPLY = 1 << 19  # products (planes x components) worth sharing among threads
_SUM_BYTES = 1 << 28  # spectra of a band held at once to sum them before the inverse FFT
_KEEP_BYTES = 1 << 27  # a plan's effective transfers kept with it up to this size


class PlaneByPlane(Backend):
    """The exact angular spectrum, each frequency and plane on its own (the reference)."""

    name = "frequency"
    propagator_class: type[PlaneOperator] = AngularSpectrum

    def refuses(self, plan: MigrationPlan) -> str | None:
        if plan.settings.frame != "aperture":
            return "the aperture's own frame (frame='aperture')"
        if plan.settings.method != "angular":
            return f"method='angular' (got {plan.settings.method!r})"
        if plan.settings.band_limit == "smooth" and plan.settings.fov == "full":
            return "fov='aperture' for band_limit='smooth' (its taper is sized by the aperture)"
        return None

    # ------------------------------------------------------------------ geometry
    def propagator(self, plan: MigrationPlan, i: int) -> PlaneOperator:
        """Frequency ``i``'s propagator onto the plan's planes (made once per plan; its
        transfer functions cached)."""
        key = ("propagator", self.name, i)
        op = plan.memo.get(key)
        if op is None:
            g = plan.geometry
            dx, dy = g.pitch
            snr = plan.snr_db
            smooth = plan.settings.band_limit == "smooth"
            op = plan.memo[key] = self.propagator_class(
                plan.grid, dx, dy, float(plan.wavenumbers[i]), plan.z, plan.local, plan.pad,
                plan.work, compensate_loss=snr is not None,
                snr_db=40.0 if snr is None else snr, monostatic=g.monostatic,
                band_limit="smooth" if smooth else True)
        return op

    def _frame(self, plan: MigrationPlan, grid: tuple[int, int]) -> tuple[int, int, int, int]:
        """``(oy, ox, sy, sx)``: the output's size and the shift of the aperture in it."""
        ny, nx = plan.grid
        u = plan.settings.upsample
        if plan.settings.fov == "full":
            My, Mx = grid
            return u * My, u * Mx, u * ((My - ny) // 2), u * ((Mx - nx) // 2)
        return u * (ny - 1) + 1, u * (nx - 1) + 1, 0, 0

    def axes(self, plan: MigrationPlan) -> tuple[np.ndarray, np.ndarray]:
        key = ("axes", self.name)
        if key not in plan.memo:
            g = plan.geometry
            dx, dy = g.pitch
            u = plan.settings.upsample
            grid = self.propagator(plan, plan.nf - 1).fft_shape
            oy, ox, sy, sx = self._frame(plan, grid)
            x = g.x[0] + (np.arange(ox) - sx) * dx / u
            y = g.y[0] + (np.arange(oy) - sy) * dy / u
            x.setflags(write=False)
            y.setflags(write=False)
            plan.memo[key] = (x, y)
        return plan.memo[key]

    # ------------------------------------------------------------------- adjoint
    def adjoint(self, plan: MigrationPlan, data: np.ndarray) -> np.ndarray:
        nf = data.shape[1]
        ops = [self.propagator(plan, i) for i in range(nf)]
        bar = _Progress(plan, nf)
        try:
            if nf == 1 and plan.illumination == "none" and plan.weights[0] == 1 and \
                    not units.is_point(plan):
                return self._plane_images(plan, ops[0], data[:, 0], bar)
            if not plan.separate and illumination.is_uniform(plan) and \
                    _spectra_fit(ops, data.shape[0], plan.work):
                return self._summed_adjoint(plan, ops, data, bar)
            return self._per_frequency_adjoint(plan, ops, data, bar)
        finally:
            bar.close()

    def _per_frequency_adjoint(self, plan: MigrationPlan, ops: list[PlaneOperator],
                               data: np.ndarray, bar: _Progress) -> np.ndarray:
        x, y = self.axes(plan)
        acc: np.ndarray | None = None
        parts = []
        for i, op in enumerate(ops):
            img = self._plane_images(plan, op, data[:, i], bar,
                                     self.effective(plan, ops, i, fold=False))
            phasor = illumination.on_planes(plan, i, x, y)
            if phasor is not None:
                img = img * phasor
            img = plan.weights[i] * img if plan.nf > 1 else img
            if plan.separate:
                parts.append(img)
            else:
                acc = img if acc is None else acc + img
        return np.stack(parts, axis=1) if plan.separate else acc

    def _summed_adjoint(self, plan: MigrationPlan, ops: list[PlaneOperator],
                        data: np.ndarray, bar: _Progress) -> np.ndarray:
        """The band's spectra summed per FFT grid before one inverse FFT per plane."""
        B, nz = data.shape[0], plan.z.size
        H = [op.spectrum(data[:, i]) for i, op in enumerate(ops)]
        out: np.ndarray | None = None
        for grid, members in _groups(ops).items():
            frame = self._frame(plan, grid)
            U = {i: self.effective(plan, ops, i) for i in members}
            for c0 in range(0, nz, _CHUNK):
                sel = range(c0, min(nz, c0 + _CHUNK))
                # One plane of one frequency: multiplied in its own spectrum (ours).
                S = H[members[0]][:, None] if nz == 1 and len(members) == 1 else \
                    np.empty((B, len(sel), *grid), dtype=plan.work)
                for j, iz in enumerate(sel):
                    np.multiply(H[members[0]], U[members[0]][iz], out=S[:, j])
                    for i in members[1:]:
                        S[:, j] += H[i] * U[i][iz]
                planes = self._inverse(plan, S, grid, frame, ops[0].workers)
                if out is None and len(sel) == nz:
                    out = planes   # one chunk of one grid: the image itself
                else:
                    if out is None:
                        out = np.zeros((B, nz, frame[0], frame[1]), dtype=plan.work)
                    out[:, c0:c0 + len(sel)] += planes
                bar.update(len(sel) * len(members))
        assert out is not None
        return out

    def effective(self, plan: MigrationPlan, ops: list[PlaneOperator], i: int, *,
                  forward: bool = False, fold: bool = True) -> list[np.ndarray]:
        """Frequency ``i``'s adjoint transfers (``forward``: their conjugates, the
        forward map's), one per plane, with the point unit's factor (``scatterer=
        "point"``) and, with ``fold``, its weight and the uniform illumination's
        ``conj(psi)`` folded in: kept with the plan while they are small enough (the
        next call, a solver's next iterate, reuses them)."""
        key = ("effective", self.name, i, forward, fold)
        if key in plan.memo:
            return plan.memo[key]
        op = ops[i]
        Ucs = op.adjoint_transfers
        w = float(plan.weights[i]) if plan.nf > 1 and fold else 1.0
        f = illumination.uniform(plan, i) if fold else None
        point = units.is_point(plan)
        if w == 1.0 and f is None and not point and not forward:
            return Ucs
        scale = np.full(len(Ucs), w, dtype=complex) * (1 if f is None else f)
        out = []
        for j, (U, c) in enumerate(zip(Ucs, scale, strict=True)):
            if point:   # conj(S): the adjoint of the point unit's factor
                S = units.point_factor(op.fft_shape, (op.dx, op.dy), op.k, plan.local,
                                       float(plan.z[j]), plan.monostatic,
                                       plan.geometry.pitch[0] * plan.geometry.pitch[1],
                                       plan.work, units.polarization(plan))
                U = U * np.conj(S)
            V = U * plan.work.type(c) if c != 1 else U
            out.append(np.conj(V) if forward else V)
        for U in out:
            U.setflags(write=False)
        if sum(U.nbytes for U in out) <= _KEEP_BYTES:
            plan.memo[key] = out
        return out

    def _inverse(self, plan: MigrationPlan, S: np.ndarray, grid: tuple[int, int],
                 frame: tuple[int, int, int, int], workers: int) -> np.ndarray:
        """``C(G(S))`` of spectra (..., My, Mx), consumed."""
        u = plan.settings.upsample
        oy, ox, sy, sx = frame
        if u > 1:
            S = interpolate(S, u)
        if plan.settings.fov == "full":
            planes = np.roll(sfft.ifft2(S, axes=(-2, -1), workers=workers, overwrite_x=True),
                             (sy, sx), axis=(-2, -1))
        else:
            planes = ifft2_cropped(S, (oy, ox), workers, overwrite=True)
        return planes * (u * u) if u > 1 else planes

    def _plane_images(self, plan: MigrationPlan, op: PlaneOperator, d: np.ndarray,
                      bar: _Progress, transfers: list[np.ndarray] | None = None
                      ) -> np.ndarray:
        """One frequency's back-propagation ``(B, ny, nx) -> (B, nz, oy, ox)`` (by
        ``transfers``, default the propagator's adjoint ones)."""
        zs = plan.z
        H = op.spectrum(d)
        ny, nx = op.shape
        u = plan.settings.upsample
        B = H.shape[0]
        My, Mx = H.shape[-2:]
        oy, ox, sy, sx = self._frame(plan, (My, Mx))
        full = plan.settings.fov == "full"
        # Without crop or interpolation the products are computed in the output array
        # itself and transformed in place: one multiply and one inverse FFT per plane.
        in_place = u == 1 and (My, Mx) == (ny, nx) and not full
        out = None if in_place and zs.size == 1 else np.empty((B, zs.size, oy, ox),
                                                              dtype=plan.work)
        chunk = zs.size if in_place else _CHUNK
        for c0 in range(0, zs.size, chunk):
            Ucs = (op.adjoint_transfers if transfers is None else transfers)[c0:c0 + chunk]
            if zs.size == 1:
                # One plane: multiply into the spectrum itself (ours, no longer needed)
                # and transform it in place; unpadded it is the image: no allocation.
                prod = H[:, None, :, :]
                if in_place:
                    out = prod
            else:
                prod = out[:, c0:c0 + len(Ucs)] if in_place else np.empty(
                    (B, len(Ucs), My, Mx), dtype=plan.work)
            multiply_planes(H, Ucs, prod)
            if in_place:
                planes = sfft.ifft2(prod, axes=(-2, -1), workers=op.workers, overwrite_x=True)
                if not np.may_share_memory(planes, out):
                    out[:, c0:c0 + len(Ucs)] = planes
            else:
                out[:, c0:c0 + len(Ucs)] = self._inverse(plan, prod, (My, Mx),
                                                         (oy, ox, sy, sx), op.workers)
            bar.update(len(Ucs))
        return out

    # ------------------------------------------------------------------- forward
    def forward(self, plan: MigrationPlan, image: np.ndarray) -> np.ndarray:
        B, nf = image.shape[0], plan.nf
        ops = [self.propagator(plan, i) for i in range(nf)]
        ny, nx = plan.grid
        out = np.empty((B, nf, ny, nx), dtype=plan.work)
        uniform = illumination.is_uniform(plan) and not plan.separate
        x, y = self.axes(plan)
        for grid, members in _groups(ops).items():
            frame = self._frame(plan, grid)
            acc: dict[int, np.ndarray] = {}
            for i in (members if not uniform else [None]):
                # A uniform illumination is folded into the (kept) forward transfers; a
                # per-pixel one multiplies each frequency's reflectivity.
                r = image if i is None else self._illuminated(plan, image, i, x, y)
                for j in range(plan.z.size):
                    R = self._spectrum_of(plan, r[:, j], grid, frame, ops[members[0]].workers)
                    these = members if i is None else [i]
                    for m in these:
                        U = self.effective(plan, ops, m, forward=True, fold=uniform)[j]
                        if m in acc:
                            acc[m] += R * U
                        elif m == these[-1]:   # R's last use: multiplied in place
                            acc[m] = np.multiply(R, U, out=R)
                        else:
                            acc[m] = R * U
            for i in members:
                back = ifft2_cropped(acc[i], (ny, nx), ops[i].workers, overwrite=True)
                w = plan.weights[i] if plan.nf > 1 and not uniform else 1.0
                out[:, i] = back * plan.work.type(w) if w != 1.0 else back
        return out

    def _illuminated(self, plan: MigrationPlan, image: np.ndarray, i: int, x: np.ndarray,
                     y: np.ndarray) -> np.ndarray:
        """Frequency ``i``'s reflectivity times ``psi`` (``(B, nz, oy, ox)``)."""
        r = image[:, i] if plan.separate else image
        phasor = illumination.on_planes(plan, i, x, y)
        return r if phasor is None else r * np.conj(phasor)

    def _spectrum_of(self, plan: MigrationPlan, img: np.ndarray, grid: tuple[int, int],
                     frame: tuple[int, int, int, int], workers: int) -> np.ndarray:
        """``fold(F(C^T img))``: the adjoint of :meth:`_inverse` times ``My Mx``."""
        u = plan.settings.upsample
        fine = (u * grid[0], u * grid[1])
        if plan.settings.fov == "full":
            _, _, sy, sx = frame
            img = np.roll(img, (-sy, -sx), axis=(-2, -1))
        return fold(fft2_padded(img, fine, plan.work, workers), u)


class FresnelPlanes(PlaneByPlane):
    """The paper's paraxial Fresnel kernel, plane by plane (``method="fresnel"``)."""

    name = "fresnel"
    propagator_class = Fresnel

    def refuses(self, plan: MigrationPlan) -> str | None:
        if plan.settings.frame != "aperture":
            return "the aperture's own frame (frame='aperture')"
        if plan.settings.method != "fresnel":
            return f"method='fresnel' (got {plan.settings.method!r})"
        if units.is_point(plan) or plan.settings.band_limit == "smooth":
            return "the angular spectrum for point scatterers or a smooth band limit"
        return None


def _groups(ops: list[PlaneOperator]) -> dict[tuple[int, int], list[int]]:
    """Frequencies by FFT grid (``pad=True`` sizes it by the wavelength: across a band
    one or two grids)."""
    groups: dict[tuple[int, int], list[int]] = {}
    for i, op in enumerate(ops):
        groups.setdefault(op.fft_shape, []).append(i)
    return groups


def _spectra_fit(ops: list[PlaneOperator], frames: int, work: np.dtype) -> bool:
    """Whether a band's padded spectra may all be held at once (:data:`_SUM_BYTES`)."""
    return sum(math.prod(op.fft_shape) for op in ops) * frames * work.itemsize <= _SUM_BYTES


def multiply_planes(H: np.ndarray, Ucs: list[np.ndarray], prod: np.ndarray) -> None:
    """``prod[..., i, :, :] = H * Ucs[i]`` for every plane, on all cores when large.

    NumPy's multiply is single-threaded but releases the GIL, so a thread per core
    takes a share of the planes; on a volume this is most of the work besides FFTs.
    Below ``_THREADED_MULTIPLY`` products (one 512 x 512 plane: 0.10 ms in one thread,
    0.23 ms shared among two) the threads' hand-offs cost more than they share.
    """
    rows = H.shape[-2]
    if _threads.POOL_SIZE < 2 or len(Ucs) * H.size < _THREADED_MULTIPLY:
        for i, Uc in enumerate(Ucs):   # small: threads cost more than they share
            np.multiply(H, Uc, out=prod[..., i, :, :])
        return
    # Tasks: (plane, row block); a single plane is split in row blocks across cores.
    blocks = max(1, -(-_threads.POOL_SIZE // len(Ucs))) if rows >= 64 else 1
    edges = np.linspace(0, rows, blocks + 1).astype(int)
    tasks = [(i, slice(edges[b], edges[b + 1])) for i in range(len(Ucs)) for b in range(blocks)]

    def work(task: tuple[int, slice]) -> None:
        i, r = task
        np.multiply(H[..., r, :], Ucs[i][r, :], out=prod[..., i, r, :])

    if len(tasks) < 2:
        for t in tasks:
            work(t)
        return
    list(pool().map(work, tasks))


class _Progress:
    """A progress bar over planes for outputs that take long (or when asked)."""

    def __init__(self, plan: MigrationPlan, nf: int) -> None:
        s = plan.settings
        total = plan.z.size * nf
        self.bar: Any = None
        if s.progress is False:
            return
        import sys

        # Unasked (None): a bar for long work on a terminal only (a bar redraws its
        # line: in a pipe or a log it is hundreds of lines of noise).
        big = total * plan.grid[0] * plan.grid[1] * s.upsample ** 2 > 2e8
        if s.progress or (big and sys.stderr.isatty()):
            from tqdm.auto import tqdm  # here, not at import: holoradar._lazy

            # delay: a bar only for work that lasts (progress=True shows it after 1 s)
            self.bar = tqdm(total=total, desc="migrate", unit="plane", delay=1.0)

    def update(self, n: int) -> None:
        if self.bar is not None:
            self.bar.update(n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
