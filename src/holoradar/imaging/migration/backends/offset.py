"""A transmitter beside the receiver (``hologram.tx_offset``): the exact two-leg kernel.

A scanned pair records at the receiver's position ``p`` the echo of a transmitter at
``p + d`` (``d = (dx, dy, dz)``, fixed). A point scatterer of amplitude ``r`` at
``(x, y, z)`` gives

    h_f(p) = r g(p - (x, y); z -> 0) g(p + d_xy - (x, y); z -> dz),

``g`` the layered Green's function (``exp(i k R)/R`` in free space; through the layers
by Sommerfeld integration, :func:`holoradar.physics.green.green_at_distances`). Both
legs move with ``p``, so each plane's response is a convolution of the reflectivity
with one kernel ``K_{f,z}(s) = g(s; z -> 0) g(s + d_xy; z -> dz)`` of the lateral lag
``s``. The kernel is evaluated in space on every lag the grid can show (the image's
pixels, ``pitch / upsample``) and the convolution made by FFT on a grid of at least
twice the aperture (linear, not circular): forward and adjoint are the exact
discrete maps, the adjoint the matched filter ``sum_p h(p) conj(K(p - r))`` at every
pixel, aliasing of an undersampled scan included (the kernel is sampled where the
elements are, not band-limited). A transceiver's round trip (``d = 0``) is the
special case ``g^2``; its spectral round-trip transfer is the stationary-phase form
of the same kernel.

``scatterer="plane"`` (the reflecting plane's coefficient) scales the point's kernel
by ``2 k n L dA / (2 pi i)`` (``L`` the plane's apparent range, ``n`` its layer's
index, ``dA`` the pixel's area): a uniform plane of coefficient 1 then returns
``exp(2 i k z)`` at stationary phase, the transceiver's unit. With
``compensate_loss`` each plane's kernel is scaled by the ratio of its norm in the
lossless ground to its norm in the lossy one (capped by the SNR), a real gain.

The kernel is the scalar Green's function: a recorded polarisation's pattern is not
modelled. Several transmitters (a MIMO array: transmitter ``t`` at ``p + d_t``) are
the sum of such operators, one per offset, each on its own hologram.
"""

from __future__ import annotations

import math

import numpy as np

from ...._lazy import lazy_module
from ...._threads import POOL_SIZE
from ....physics.green import transmitted_profiles
from ....physics.medium import Medium
from .. import units
from ..plan import MigrationPlan
from .base import Backend

sfft = lazy_module("scipy.fft")

__all__ = ["Offset"]

_KEEP_BYTES = 1 << 27  # kernels' spectra kept with the plan up to this size


class Offset(Backend):
    """The two-leg kernel of a transmitter beside the receiver (module docstring)."""

    name = "offset"

    def refuses(self, plan: MigrationPlan) -> str | None:
        g = plan.geometry
        d = g.tx_offset
        if d is None:
            return "a hologram with tx_offset (a transmitter beside each receiver)"
        s = plan.settings
        why = []
        if s.frame != "aperture":
            why.append("the aperture's own frame (frame='aperture')")
        if s.method != "angular":
            why.append(f"method='angular' (got {s.method!r})")
        if s.fov != "aperture":
            why.append(f"fov='aperture' (got {s.fov!r})")
        top = 0.0 if plan.local.is_free_space else float(plan.local.z_interfaces[0])
        if not plan.local.is_free_space and d[2] >= top:
            why.append(f"a transmitter above the ground (tx_offset dz = {d[2]} m, the "
                       f"surface {top} m from the aperture)")
        near = max(0.0, d[2])
        if np.any(plan.z <= near):
            why.append(f"planes beyond the antennas (z > {near} m; the kernel is singular "
                       "at an antenna)")
        return "; ".join(why) if why else None

    # ------------------------------------------------------------------ geometry
    def _fine(self, plan: MigrationPlan) -> tuple[int, int]:
        u = plan.settings.upsample
        ny, nx = plan.grid
        return u * (ny - 1) + 1, u * (nx - 1) + 1

    def _fft_shape(self, plan: MigrationPlan) -> tuple[int, int]:
        return tuple(sfft.next_fast_len(2 * n - 1) for n in self._fine(plan))

    def axes(self, plan: MigrationPlan) -> tuple[np.ndarray, np.ndarray]:
        g = plan.geometry
        dx, dy = g.pitch
        u = plan.settings.upsample
        nyf, nxf = self._fine(plan)
        x = g.x[0] + np.arange(nxf) * (dx / u)
        y = g.y[0] + np.arange(nyf) * (dy / u)
        x.setflags(write=False)
        y.setflags(write=False)
        return x, y

    # ------------------------------------------------------------------ kernels
    def spectra(self, plan: MigrationPlan, i: int) -> np.ndarray:
        """Frequency ``i``'s kernels on every plane, as spectra on the FFT grid (``(nz,
        My, Mx)``, lag ``l`` at index ``l mod M``), with the unit, the weight and the
        loss compensation's gain folded in; kept with the plan while small."""
        key = ("offset-spectra", i)
        if key in plan.memo:
            return plan.memo[key]
        k = float(plan.wavenumbers[i])
        K = kernels(plan, k)
        if plan.compensates:
            K = K * _loss_gain(plan, k, K)[:, None, None]
        if units.is_point(plan):
            scale = np.ones(plan.z.size, complex)
        else:
            scale = np.array([plane_unit(plan, k, float(z)) for z in plan.z])
        scale = scale * float(plan.weights[i])
        M = self._fft_shape(plan)
        nyf, nxf = self._fine(plan)
        pad = np.zeros((plan.z.size, *M), dtype=complex)
        K *= scale[:, None, None]
        # Lag l at index l mod M: the four quadrants of the lags, without a roll.
        for ky, py in ((slice(nyf - 1, None), slice(0, nyf)),
                       (slice(0, nyf - 1), slice(M[0] - (nyf - 1), M[0]))):
            for kx, px in ((slice(nxf - 1, None), slice(0, nxf)),
                           (slice(0, nxf - 1), slice(M[1] - (nxf - 1), M[1]))):
                pad[:, py, px] = K[:, ky, kx]
        out = sfft.fft2(pad, axes=(-2, -1), workers=POOL_SIZE).astype(plan.work, copy=False)
        out.setflags(write=False)
        if out.nbytes * plan.nf <= _KEEP_BYTES:
            plan.memo[key] = out
        return out

    # ------------------------------------------------------------------ the maps
    def adjoint(self, plan: MigrationPlan, data: np.ndarray) -> np.ndarray:
        B, nf = data.shape[:2]
        u = plan.settings.upsample
        nyf, nxf = self._fine(plan)
        M = self._fft_shape(plan)
        pad = np.zeros((B, nf, *M), dtype=plan.work)
        pad[..., :nyf:u, :nxf:u] = data
        D = sfft.fft2(pad, axes=(-2, -1), workers=POOL_SIZE, overwrite_x=True)
        nz = plan.z.size
        shape = (B, nf, nz, *M) if plan.separate else (B, nz, *M)
        S = np.zeros(shape, dtype=plan.work)
        for i in range(nf):
            Kc = np.conj(self.spectra(plan, i))
            if plan.separate:
                np.multiply(D[:, i, None], Kc[None], out=S[:, i])
            else:
                S += D[:, i, None] * Kc[None]
        img = sfft.ifft2(S, axes=(-2, -1), workers=POOL_SIZE, overwrite_x=True)
        return np.ascontiguousarray(img[..., :nyf, :nxf])

    def forward(self, plan: MigrationPlan, image: np.ndarray) -> np.ndarray:
        B = image.shape[0]
        u = plan.settings.upsample
        nyf, nxf = self._fine(plan)
        M = self._fft_shape(plan)
        pad = np.zeros((*image.shape[:-2], *M), dtype=plan.work)
        pad[..., :nyf, :nxf] = image
        R = sfft.fft2(pad, axes=(-2, -1), workers=POOL_SIZE, overwrite_x=True)
        H = np.empty((B, plan.nf, *M), dtype=plan.work)
        for i in range(plan.nf):
            K = self.spectra(plan, i)
            planes = R[:, i] if plan.separate else R
            H[:, i] = np.einsum("bzyx,zyx->byx", planes, K)
        h = sfft.ifft2(H, axes=(-2, -1), workers=POOL_SIZE, overwrite_x=True)
        return np.ascontiguousarray(h[..., :nyf:u, :nxf:u])


def kernels(plan: MigrationPlan, k: float, medium: Medium | None = None) -> np.ndarray:
    """``K_z(s) = g(s; z -> 0) g(s + d_xy; z -> dz)`` on every lag of the image's grid,
    ``(nz, 2 nyf - 1, 2 nxf - 1)``, lag ``-(n - 1) .. n - 1`` pixels along each axis.

    Free space: ``exp(i k (R_rx + R_tx)) / (R_rx R_tx)`` in closed form (the ranges
    kept with the plan: one complex exponential per lag, plane and frequency). Layered
    ground: each leg's radial profile by Sommerfeld integration for all planes at once
    (reciprocity: the field at the antenna of a point on the plane is the antenna's
    field on the plane), on a radial grid of a sixteenth of the shortest wavelength,
    its amplitude and unwrapped phase interpolated linearly to the lags (both smooth
    on the scale of the ranges)."""
    m = plan.local if medium is None else medium
    rho_rx, rho_tx = _lags(plan)
    dz = plan.geometry.tx_offset[2]
    if m.is_free_space:
        key = ("offset-ranges",)
        if key not in plan.memo:
            z = plan.z[:, None, None]
            r1 = np.sqrt(rho_rx**2 + z**2)
            r2 = np.sqrt(rho_tx**2 + (z - dz) ** 2)
            plan.memo[key] = (r1 + r2, 1.0 / (r1 * r2))
        path, amp = plan.memo[key]
        return amp * _phasor(plan, k, path)
    step = 2 * np.pi / (k * max(abs(m.n(j)) for j in range(m.n_regions))) / 16
    top = max(float(rho_rx.max()), float(rho_tx.max()))
    grid = np.arange(0.0, top + 3 * step, step)
    out = np.ones((plan.z.size, *rho_rx.shape), dtype=complex)
    profiles: dict[float, tuple[np.ndarray, np.ndarray]] = {}
    for z_antenna, rho in ((0.0, rho_rx), (float(dz), rho_tx)):
        if z_antenna not in profiles:   # both antennas at one height (dz = 0): one integral
            prof = transmitted_profiles(k, m, z_antenna, plan.z, grid)
            profiles[z_antenna] = (np.abs(prof), np.unwrap(np.angle(prof), axis=-1))
        amp, phase = profiles[z_antenna]
        for j in range(plan.z.size):
            out[j] *= np.interp(rho, grid, amp[j]) * np.exp(1j * np.interp(rho, grid,
                                                                         phase[j]))
    return out


_RESEED = 32  # steps of the frequency recurrence between exact exponentials


def _phasor(plan: MigrationPlan, k: float, path: np.ndarray) -> np.ndarray:
    """``exp(i k path)``; on a band of equally spaced frequencies asked for in turn, the
    previous one's times ``exp(i dk path)`` (one product instead of an exponential per
    lag; exact exponentials every few steps keep the rounding at 1e-14)."""
    ks = plan.wavenumbers
    i = int(np.argmin(np.abs(ks - k)))
    last = plan.memo.get("offset-phasor")
    uniform = ks.size > 2 and np.allclose(np.diff(ks), ks[1] - ks[0], rtol=1e-9, atol=0)
    if uniform and last is not None and last[0] == i - 1 and i % _RESEED and ks[i] == k:
        step = plan.memo.get("offset-step")
        if step is None:
            step = plan.memo["offset-step"] = np.exp(1j * (ks[1] - ks[0]) * path)
        out = last[1] * step
    else:
        out = np.exp(1j * k * path)
    if uniform and ks[i] == k:
        plan.memo["offset-phasor"] = (i, out)
    return out


def _lags(plan: MigrationPlan) -> tuple[np.ndarray, np.ndarray]:
    """The lateral distances of every lag to the receiver and to the transmitter."""
    g = plan.geometry
    dx, dy, _ = g.tx_offset
    u = plan.settings.upsample
    px, py = g.pitch[0] / u, g.pitch[1] / u
    nyf, nxf = (u * (n - 1) + 1 for n in plan.grid)
    sx = np.arange(-(nxf - 1), nxf) * px
    sy = np.arange(-(nyf - 1), nyf) * py
    SX, SY = np.meshgrid(sx, sy)
    return np.hypot(SX, SY), np.hypot(SX + dx, SY + dy)


def plane_unit(plan: MigrationPlan, k: float, z: float) -> complex:
    """The point kernel's factor for a reflecting plane's coefficient, ``2 k n L dA /
    (2 pi i)`` (module docstring)."""
    m = plan.local
    n = float(m.n(int(m.region_of(z))).real)
    u = plan.settings.upsample
    area = plan.geometry.pitch[0] * plan.geometry.pitch[1] / u**2
    return complex(2 * k * n * m.apparent_distance(z) * area / (2j * math.pi))


def _loss_gain(plan: MigrationPlan, k: float, K: np.ndarray) -> np.ndarray:
    """Per plane, ``|K lossless| / |K|`` (norms over the lags), capped by the SNR."""
    m = plan.local
    lossless = Medium(m.z_interfaces, tuple(complex(e).real for e in m.eps), m.polarization)
    ref = kernels(plan, k, lossless)
    num = np.sqrt(np.sum(np.abs(ref) ** 2, axis=(-2, -1)))
    den = np.sqrt(np.sum(np.abs(K) ** 2, axis=(-2, -1)))
    cap = 10 ** (float(plan.snr_db) / 20)
    return np.minimum(np.divide(num, den, out=np.full_like(num, cap), where=den > 0), cap)
