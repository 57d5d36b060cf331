"""Imaging from a posed (tilted) aperture onto horizontal planes through the layers.

Method: an exact rotation of the angular spectrum. Below the aperture the field
is a sum of up-going plane waves. On a horizontal reference plane ``z_ref``
(the range of the aperture's lowest element) and a periodic world grid of
pitch ``(dx, dy)`` and ``(Mx, My)`` points from ``(x0, y0)``, the field of a
plane-wave spectrum ``U`` at an element ``r_e`` above that plane is

    u(r_e) = (1/(Mx My)) sum_k U(k) exp(i [p (x_e - x0) + q (y_e - y0)
                                          + kz (z_ref - z_e)]),

``kz = sqrt(k^2 - p^2 - q^2)`` (a transceiver's round trip:
``sqrt(4 k^2 - p^2 - q^2)``). Its adjoint, applied to the hologram ``d_e``, is
the data's spectrum on the reference plane,

    H(k) = sum_e d_e exp(-i K.(r_e - r0)),   K = (p, q, -conj(kz)),

a non-uniform Fourier sum evaluated exactly at every grid wavenumber (no
interpolation, hence no Jacobian to carry: the remapping of the aperture's
spectral coordinates ``(K.u, K.v)`` onto the world's ``(p, q)`` is implicit;
:mod:`.oblique_sum`, by factored matrix products or finufft). From ``H`` on the
reference plane the usual exact migration carries every component down through
the layers (``conj`` of the transfer, loss compensation, band limit) onto
horizontal planes at world ranges ``z``: one inverse FFT per plane
(:func:`adjoint_ground`). :func:`forward_ground` is its exact adjoint: each plane's
spectrum carried up by the transfer and summed at the elements.

For a level aperture whose elements sit on the grid this is exactly the
frontal migration (tested). Evanescent components in the air are kept while
the air gap leaves them above ``1e-8`` of a travelling one; below that they
cannot reach the ground.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...._lazy import lazy_module
from ...._threads import fft_workers
from ...._validate import as_axis, uniform_step
from ....data.hologram import Hologram
from ....physics.medium import Medium
from ....physics.propagation import (
    TRANSFER_CACHE,
    band_taper,
    basis_of,
    lateral_travel,
    make_angular_transfer,
    padded_shape,
)
from ....physics.spectra import fft2_padded, fold, interpolate
from .oblique_sum import EVANESCENT_FLOOR, sum_to_elements, sum_to_plane

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

def ground_grid(hologram: Hologram, zs: np.ndarray, medium: Medium,
                upsample: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """The default world grid of ``frame="ground"``: what the aperture looks at.

    The aperture's corners are carried along its normal down to the surface and on
    along the refracted direction (Snell, ``Re(n)`` of each layer) to the shallowest
    and the deepest image plane; the grid spans those points at the element pitch
    divided by ``upsample``. A level aperture gets its own footprint.
    """
    pose = hologram.pose
    corners = pose.grid_points(hologram.x[[0, -1]], hologram.y[[0, -1]]).reshape(-1, 3)
    n = pose.normal
    s_air = np.hypot(n[0], n[1])                    # sin of the angle from vertical
    lateral = n[:2] / s_air if s_air > 0 else np.zeros(2)
    ends = []
    for z in (float(zs.min()), float(zs.max())):
        for c in corners:
            shift, top = 0.0, float(c[2])
            for m in range(medium.n_regions):
                # The air path runs from the corner itself (it may lie above z = 0).
                lo = top if m == 0 else max(top, medium.top_of(m))
                hi = min(z, medium.z_interfaces[m] if m < medium.n_regions - 1 else np.inf)
                if hi > lo:
                    sin_t = min(s_air / medium.n(m).real, 0.999)
                    shift += (hi - lo) * sin_t / np.sqrt(1 - sin_t**2)
            ends.append(c[:2] + shift * lateral)
    ends = np.array(ends)
    step = min(hologram.pitch) / upsample
    lo, hi = ends.min(axis=0), ends.max(axis=0)
    # ceil: the grid reaches the farthest corner's footprint.
    nx = int(np.ceil((hi[0] - lo[0]) / step - 1e-9)) + 1
    ny = int(np.ceil((hi[1] - lo[1]) / step - 1e-9)) + 1
    return lo[0] + step * np.arange(max(nx, 2)), lo[1] + step * np.arange(max(ny, 2))


@dataclass(frozen=True)
class GroundGrid:
    """The periodic world grid of one frequency's ground-frame migration (see
    :func:`ground_setup`)."""

    x: np.ndarray            # output pixels, world metres
    y: np.ndarray
    grid: tuple[int, int]    # (My, Mx) FFT grid
    pitch: tuple[float, float]   # its pitch (dcx, dcy)
    up: tuple[int, int]      # (uy, ux): interpolation of the spectrum onto the output
    down: tuple[int, int]    # (my, mx): every m-th interpolated sample is an output pixel
    z_ref: float             # the reference plane (the lowest element's world range)
    rise: float              # height span of the elements
    reach: tuple[float, float]   # farthest element-pixel distance along x, y
    gap: float               # shortest air path below the reference plane
    medium: Medium           # the layers seen from the reference plane
    k: float
    mono: bool
    workers: int

    @property
    def crop(self) -> tuple[int, int]:
        my, mx = self.down
        return my * (self.y.size - 1) + 1, mx * (self.x.size - 1) + 1

    def transfer(self, z: float, work: np.dtype, snr: float | None) -> np.ndarray:
        """The adjoint transfer from world range ``z`` to the reference plane, band
        limited (cached)."""
        return _ground_transfer(self.grid, self.pitch, self.k, self.medium, float(z - self.z_ref),
                                self.rise, self.mono, self.reach, work, snr)


def ground_setup(geometry: Hologram, k: float, zs: np.ndarray, medium: Medium, *,
                 x: Any = None, y: Any = None, pad: Any = True,
                 upsample: int = 1) -> GroundGrid:
    """Check a ground-frame migration's planes and size its world FFT grid.

    ``geometry``: the posed hologram (its elements' world positions, pose, grid);
    ``k`` the wavenumber in air of the frequency (rad/m). ``ValueError`` when the
    aperture's elements reach the ground or a plane lies above the lowest element.
    """
    mono = geometry.monostatic
    pts = geometry.points
    z_ref = float(pts[:, 2].max())
    if not medium.is_free_space and z_ref >= medium.z_interfaces[0]:
        raise ValueError(f"hologram.pose puts elements at or below the ground surface (z = "
                         f"{medium.z_interfaces[0]} m): the lowest is at z = {z_ref:.4g} m")
    if np.any(zs <= z_ref):
        raise ValueError(f"z must lie below the aperture's lowest element (world range "
                         f"{z_ref:.4g} m) in frame='ground', got min(z) = {zs.min():.4g} m")
    if x is None or y is None:
        gx, gy = ground_grid(geometry, zs, medium, upsample)
        x = gx if x is None else x
        y = gy if y is None else y
    xo = as_axis(x, "x")
    yo = as_axis(y, "y")
    dxw, dyw = uniform_step(xo, "x"), uniform_step(yo, "y")
    kk = 2 * k if mono else k
    # The shortest air path below the reference plane to anything imaged: components
    # evanescent in the air that it damps below 1e-8 cannot matter; the rest of the
    # spectrum lies within kappa_max, so the FFT grid needs a pitch of pi/kappa_max
    # at most: a finer output grid is reached by exact (zero-padded spectrum)
    # interpolation, u times along each axis.
    gap = float(min(zs.min(), medium.z_interfaces[0] if not medium.is_free_space
                    else np.inf) - z_ref)
    kappa_max = np.hypot(kk, -np.log(EVANESCENT_FLOOR) / max(gap, 1e-12))
    # The grid's pitch is the output's times u (interpolated up) or divided by m
    # (an output coarser than the spectrum needs: every m-th sample is kept).
    ux, uy = (max(1, int(np.floor(np.pi / (kappa_max * d) + 1e-9))) for d in (dxw, dyw))
    mx, my = (max(1, int(np.ceil(kappa_max * d / np.pi - 1e-9))) for d in (dxw, dyw))
    dcx, dcy = ux * dxw / mx, uy * dyw / my
    # The world grid starts at the first output pixel and spans the output and the
    # elements (the grid is periodic: elements before the origin wrap, harmlessly,
    # as long as nothing overlaps), padded for the lateral travel down to z.
    span_x = max(xo[-1], pts[:, 0].max()) - min(xo[0], pts[:, 0].min()) + dcx
    span_y = max(yo[-1], pts[:, 1].max()) - min(yo[0], pts[:, 1].min()) + dcy
    n0 = (int(np.ceil(span_y / dcy - 1e-9)), int(np.ceil(span_x / dcx - 1e-9)))
    lam = 2 * np.pi / kk
    rise = float(z_ref - pts[:, 2].min())       # height span of the elements
    # The farthest any element lies from any pixel, along x and y: a component that
    # shifts laterally by t maps an element onto the pixel t away, and, the grid
    # being periodic, also onto the one t - M dx away; that alias misses every pixel
    # while t <= M dx - reach (and every true pair needs t <= reach).
    reach = (max(xo[-1] - pts[:, 0].min(), pts[:, 0].max() - xo[0]),
             max(yo[-1] - pts[:, 1].min(), pts[:, 1].max() - yo[0]))
    grid = padded_shape(n0, pad, pitch=(dcx, dcy), wavelength=lam,
                        z_max=float(zs.max() - z_ref + rise))
    if pad is True:
        # Room for the smooth band limit between reach and M d - reach: M d >= 4 reach
        # (the kernel then matches the exact layered Green's function to ~1%, tested).
        grid = tuple(max(m, sfft.next_fast_len(int(np.ceil(4 * r / d)), real=False))
                     for m, r, d in zip(grid, reach[::-1], (dcy, dcx), strict=True))
    xo.setflags(write=False)
    yo.setflags(write=False)
    return GroundGrid(xo, yo, grid, (dcx, dcy), (uy, ux), (my, mx), z_ref, rise, reach, gap,
                      medium.seen_from(z_ref), float(k), mono,
                      fft_workers(grid[0] * grid[1] * ux * uy))


def adjoint_ground(geometry: Hologram, data: np.ndarray, g: GroundGrid, zs: np.ndarray, *,
                   snr: float | None, work: np.dtype, route: str,
                   unit: Callable[[float], Any] | None = None) -> np.ndarray:
    """One frequency's image of posed data ``(B, ny, nx)`` on horizontal world planes
    ``zs``: ``(B, nz, ny', nx')`` on ``g``'s output grid.

    ``snr``: the SNR in dB that limits the loss compensation, or None for the plain
    adjoint. ``route``: how the data's spectrum on the reference plane is summed:
    ``"direct"`` (the factored sums, exact to rounding) or ``"nufft"`` (finufft,
    relative error ``oblique_nufft.EPS``: 1e-6 in complex128, 1e-5 in complex64).
    ``unit``: a voxel's factor on the world grid at range z (the point unit of
    :mod:`holoradar.imaging.migration.units`), or None (the plane's reflectivity).
    """
    H = spectrum_on_plane(geometry, data, g, work, route)
    out = np.empty((data.shape[0], zs.size, g.y.size, g.x.size), dtype=work)
    my, mx = g.down
    for j, z in enumerate(zs):
        U = g.transfer(z, work, snr)
        if unit is not None:
            U = U * np.conj(unit(float(z)))
        full = _inverse_upsampled(H * U, g.up, g.crop, g.workers)
        # ifft2 gives the kernel times the grid's cell area: scaled to the output's.
        out[:, j] = full[..., ::my, ::mx] * (mx * my) if mx * my > 1 else full
    return out


def forward_ground(geometry: Hologram, image: np.ndarray, g: GroundGrid, zs: np.ndarray, *,
                   snr: float | None, work: np.dtype, route: str,
                   unit: Callable[[float], Any] | None = None) -> np.ndarray:
    """The exact adjoint of :func:`adjoint_ground`: world planes ``(B, nz, ny', nx')`` ->
    samples at the posed elements ``(B, ny, nx)``.

    Each plane is placed on the interpolated grid (every m-th sample), transformed and
    folded (the adjoint of the interpolated, cropped inverse FFT), carried up to the
    reference plane by the conjugate of the adjoint transfer, and the sum over planes
    is evaluated at the elements by the adjoint of the spectrum's sum
    (:func:`spectrum_at_elements`).
    """
    My, Mx = g.grid
    uy, ux = g.up
    my, mx = g.down
    cy, cx = g.crop
    acc = np.zeros((image.shape[0], My, Mx), dtype=work)
    for j, z in enumerate(zs):
        placed = np.zeros((image.shape[0], cy, cx), dtype=work)
        placed[:, ::my, ::mx] = image[:, j] * (mx * my) if mx * my > 1 else image[:, j]
        R = fold(fold(fft2_padded(placed, (uy * My, ux * Mx), work, g.workers), uy, -2),
                 ux, -1)
        U = g.transfer(z, work, snr)
        if unit is not None:
            U = U * np.conj(unit(float(z)))
        acc += R * np.conj(U)
    return spectrum_at_elements(geometry, acc / (My * Mx), g, work, route)


def _inverse_upsampled(S: np.ndarray, u: tuple[int, int], crop: tuple[int, int],
                       workers: int) -> np.ndarray:
    """``ifft2`` of spectra ``S`` interpolated ``u = (uy, ux)`` times (zero padding of
    the spectrum), cropped to ``crop``: along x, crop, then along y."""
    uy, ux = u
    oy, ox = crop
    half = sfft.ifft(interpolate(S, ux, -1), axis=-1, workers=workers,
                     overwrite_x=True)[..., :ox]
    out = sfft.ifft(interpolate(half, uy, -2), axis=-2, workers=workers,
                    overwrite_x=True)[..., :oy, :]
    return out * (ux * uy) if ux * uy > 1 else out


def _ground_transfer(grid: tuple[int, int], pitch: tuple[float, float], k: float,
                     medium: Medium, z: float, rise: float, mono: bool,
                     reach: tuple[float, float], work: np.dtype,
                     compensate_loss: float | None) -> np.ndarray:
    """The adjoint transfer from range ``z`` to the reference plane times the band
    limit of the whole path (cached as one array)."""
    key = ("ground-transfer", grid, pitch, k, medium, z, rise, mono, reach, work.str,
           compensate_loss)

    def make() -> np.ndarray:
        U = make_angular_transfer(grid, *pitch, k, z, medium, False, work, True,
                                   compensate_loss, mono)
        out = U * _make_band_limit(grid, pitch, k, medium, z, rise, mono, reach)
        out = out.astype(work, copy=False)
        out.setflags(write=False)
        return out

    return TRANSFER_CACHE.get(key, make)


def _make_band_limit(grid: tuple[int, int], pitch: tuple[float, float], k: float,
                     medium: Medium, z: float, rise: float, mono: bool,
                     reach: tuple[float, float]) -> np.ndarray:
    My, Mx = grid
    dx, dy = pitch
    # On one quadrant of the spectrum (|p|, |q|), from the cached basis: below the
    # last interface the travel grows linearly, t = t_top + (z - top) / Re(kz).
    b = basis_of(grid, dx, dy, k, medium, mono)
    if medium.region_of(z) == medium.n_regions - 1:
        with np.errstate(invalid="ignore"):
            t = b.t_top + (b.rate * (z - b.top) if z > b.top else 0.0)
    elif mono:
        t = 0.5 * lateral_travel(k, medium, b.kappa2 / 4, z)
    else:
        t = lateral_travel(k, medium, b.kappa2, z)
    kz0 = (2 * medium.kz(k, b.kappa2 / 4, 0) if mono else medium.kz(k, b.kappa2, 0)).real
    with np.errstate(divide="ignore", invalid="ignore"):
        # The shift to the lowest element (t) and to the highest (t + up).
        up = np.where(kz0 > 0, rise / np.where(kz0 > 0, kz0, 1), np.inf)
        ap, aq = b.p[None, :], b.q[:, None]
        wx = band_taper(ap * t, ap * (t + up), reach[0], Mx * dx - reach[0])
        wy = band_taper(aq * t, aq * (t + up), reach[1], My * dy - reach[1])
        # Evanescent across the air but travelling in the ground (a small air gap):
        # they shift only in the ground, and alias as any other component would.
        tg = (0.5 * lateral_travel(k, medium, b.kappa2 / 4, z, below_surface=True) if mono
              else lateral_travel(k, medium, b.kappa2, z, below_surface=True))
        ge = band_taper(ap * tg, ap * tg, reach[0], Mx * dx - reach[0]) \
            * band_taper(aq * tg, aq * tg, reach[1], My * dy - reach[1])
    w_ev = np.where(np.isfinite(tg), ge, 1.0)      # 1: evanescent all the way down
    mask = np.where(b.evanescent, w_ev, wx * wy).ravel()[b.unfold].reshape(grid)
    mask.setflags(write=False)
    return mask


def spectrum_on_plane(geometry: Hologram, data: np.ndarray, g: GroundGrid, work: np.dtype,
                      route: str = "auto") -> np.ndarray:
    """``H(k)`` on ``g``'s world grid: the adjoint of the plane-wave field at the
    elements (module docstring), for every frame of ``data`` ``(B, ny, nx)`` ->
    ``(B, My, Mx)`` (:func:`sum_to_plane` on ``g``'s grid)."""
    kk, origin = _sum_terms(g)
    return sum_to_plane(geometry, data, kk, g.grid, g.pitch, origin, work, g.gap, route)


def spectrum_at_elements(geometry: Hologram, G: np.ndarray, g: GroundGrid, work: np.dtype,
                         route: str = "auto") -> np.ndarray:
    """The exact adjoint of :func:`spectrum_on_plane` (:func:`sum_to_elements`)."""
    kk, origin = _sum_terms(g)
    return sum_to_elements(geometry, G, kk, g.grid, g.pitch, origin, work, g.gap, route)


def _sum_terms(g: GroundGrid) -> tuple[float, tuple[float, float, float]]:
    """The sum's wavenumber and the grid's origin."""
    return 2 * g.k if g.mono else g.k, (float(g.x[0]), float(g.y[0]), g.z_ref)

