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
spectral coordinates ``(K.u, K.v)`` onto the world's ``(p, q)`` is implicit).
With element coordinates ``(x'_j, y'_i)`` on the aperture's own axes ``u``,
``v`` it factors: ``H(k) = exp(-i K.(c - r0)) sum_i exp(-i y'_i K.v)
sum_j d_ij exp(-i x'_j K.u)``: two small matrix products (the "direct" route).
The same sum is a type-2 non-uniform FFT of the data at the points ``(K.v dy',
K.u dx')`` for the components that travel in the air (the "nufft" route,
:mod:`.oblique_nufft`, finufft); :func:`choose_route` takes the faster, as
measured (the direct sums for small grids and arrays). From ``H`` on the
reference plane the usual exact migration carries every component down through
the layers (``conj`` of the transfer, loss compensation, band limit) onto
horizontal planes at world ranges ``z``: one inverse FFT per plane.

For a level aperture whose elements sit on the grid this is exactly the
frontal migration (tested). Evanescent components in the air are kept while
the air gap leaves them above ``1e-8`` of a travelling one; below that they
cannot reach the ground.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._lazy import lazy_module
from .._threads import fft_workers
from .._validate import as_axis, uniform_step
from ..data.hologram import Hologram
from ..physics.medium import Medium
from ..physics.propagation import (
    _CACHE,
    _basis,
    _make_angular_transfer,
    lateral_travel,
    padded_shape,
    spectral_axes,
)
from ..physics.spectra import fft2_padded, fold, interpolate
from .oblique_nufft import elements_nufft, spectrum_nufft

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

_EVANESCENT_FLOOR = 1e-8


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
    kappa_max = np.hypot(kk, -np.log(_EVANESCENT_FLOOR) / max(gap, 1e-12))
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
                      _shifted(medium, z_ref), float(k), mono,
                      fft_workers(grid[0] * grid[1] * ux * uy))


def adjoint_ground(geometry: Hologram, data: np.ndarray, g: GroundGrid, zs: np.ndarray, *,
                   snr: float | None, work: np.dtype, route: str) -> np.ndarray:
    """One frequency's image of posed data ``(B, ny, nx)`` on horizontal world planes
    ``zs``: ``(B, nz, ny', nx')`` on ``g``'s output grid.

    ``snr``: the SNR in dB that limits the loss compensation, or None for the plain
    adjoint. ``route``: how the data's spectrum on the reference plane is summed:
    ``"direct"`` (the factored sums, exact to rounding) or ``"nufft"`` (finufft,
    relative error ``oblique_nufft.EPS``: 1e-6 in complex128, 1e-5 in complex64).
    """
    H = spectrum_on_plane(geometry, data, g, work, route)
    out = np.empty((data.shape[0], zs.size, g.y.size, g.x.size), dtype=work)
    my, mx = g.down
    for j, z in enumerate(zs):
        full = _inverse_upsampled(H * g.transfer(z, work, snr), g.up, g.crop, g.workers)
        # ifft2 gives the kernel times the grid's cell area: scaled to the output's.
        out[:, j] = full[..., ::my, ::mx] * (mx * my) if mx * my > 1 else full
    return out


def forward_ground(geometry: Hologram, image: np.ndarray, g: GroundGrid, zs: np.ndarray, *,
                   snr: float | None, work: np.dtype, route: str) -> np.ndarray:
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
        acc += R * np.conj(g.transfer(z, work, snr))
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
        U = _make_angular_transfer(grid, *pitch, k, z, medium, False, work, True,
                                   compensate_loss, mono)
        out = U * _make_band_limit(grid, pitch, k, medium, z, rise, mono, reach)
        out = out.astype(work, copy=False)
        out.setflags(write=False)
        return out

    return _CACHE.get(key, make)


def _make_band_limit(grid: tuple[int, int], pitch: tuple[float, float], k: float,
                     medium: Medium, z: float, rise: float, mono: bool,
                     reach: tuple[float, float]) -> np.ndarray:
    My, Mx = grid
    dx, dy = pitch
    # On one quadrant of the spectrum (|p|, |q|), from the cached basis: below the
    # last interface the travel grows linearly, t = t_top + (z - top) / Re(kz).
    b = _basis(grid, dx, dy, k, medium, mono)
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
        wx = _taper(ap * t, ap * (t + up), reach[0], Mx * dx - reach[0])
        wy = _taper(aq * t, aq * (t + up), reach[1], My * dy - reach[1])
        # Evanescent across the air but travelling in the ground (a small air gap):
        # they shift only in the ground, and alias as any other component would.
        tg = (0.5 * lateral_travel(k, medium, b.kappa2 / 4, z, below_surface=True) if mono
              else lateral_travel(k, medium, b.kappa2, z, below_surface=True))
        ge = _taper(ap * tg, ap * tg, reach[0], Mx * dx - reach[0]) \
            * _taper(aq * tg, aq * tg, reach[1], My * dy - reach[1])
    w_ev = np.where(np.isfinite(tg), ge, 1.0)      # 1: evanescent all the way down
    mask = np.where(b.evanescent, w_ev, wx * wy).ravel()[b.unfold].reshape(grid)
    mask.setflags(write=False)
    return mask


def _taper(low: np.ndarray, high: np.ndarray, needed: float, limit: float) -> np.ndarray:
    """Weight of components whose shift is ``low`` to the lowest element and
    ``high`` to the highest: 1 while a pixel-element pair may need them
    (``low <= needed``), 0 once their periodic alias could reach a pixel
    (``high >= limit``), a raised cosine between. The components it tapers are
    used by no pair; the smooth edge keeps the kernel from ringing back into the
    pairs that are (a sharp cut does, by a few percent)."""
    room = limit - (high - low) - needed
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(room > 0, (low - needed) / np.where(room > 0, room, 1.0),
                     np.where(low <= needed, 0.0, 1.0))
    f = np.nan_to_num(np.clip(f, 0.0, 1.0), nan=1.0)
    w = 0.5 * (1 + np.cos(np.pi * f))
    return np.where(np.isfinite(high) & (high < limit) | (low <= needed) & (high < limit),
                    w, 0.0)


def _shifted(medium: Medium, z_ref: float) -> Medium:
    """The medium seen from a reference plane at world range ``z_ref`` in the air."""
    if z_ref == 0.0 or medium.is_free_space:
        return medium
    return Medium(tuple(z - z_ref for z in medium.z_interfaces), medium.eps,
                  medium.polarization)


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


def sum_to_plane(geometry: Hologram, data: np.ndarray, kk: float, grid: tuple[int, int],
                 pitch: tuple[float, float], origin: tuple[float, float, float],
                 work: np.dtype, gap: float, route: str = "auto") -> np.ndarray:
    """``H(k) = sum_e d_e exp(-i K.(r_e - r0))`` at every wavenumber of a world grid.

    Parameters
    ----------
    geometry : Hologram
        The posed aperture (pose, element axes).
    data : numpy.ndarray
        ``(B, ny, nx)`` samples.
    kk : float
        The sum's wavenumber, rad/m (``2 k`` for a transceiver's round trip).
    grid, pitch, origin
        The world FFT grid ``(My, Mx)``, its pitch ``(dx, dy)`` and its origin
        ``(x0, y0, z_ref)``, metres.
    work : numpy.dtype
    gap : float
        The shortest air path below the reference plane to anything imaged, metres:
        components evanescent in the air that it damps below 1e-8 are left out.
    route : {"auto", "direct", "nufft"}
        ``"direct"`` (the factored sums below, exact to rounding), ``"nufft"``
        (:func:`.oblique_nufft.spectrum_nufft`, finufft to its ``EPS``) or ``"auto"``
        (:func:`choose_route`).

    Returns
    -------
    numpy.ndarray
        ``(B, My, Mx)``.
    """
    route = _route(geometry, grid, route)
    reach = -np.log(_EVANESCENT_FLOOR) / max(gap, 1e-12)   # largest Im(kz) kept
    if route == "nufft":
        return spectrum_nufft(geometry, data, kk, grid, pitch, origin, work, reach)
    basis = _remap(geometry, kk, grid, pitch, origin, work, reach)
    My, Mx = grid
    d = data.astype(work, copy=False)
    if basis.mode == "columns":
        # x' horizontal along x: its phase depends on the grid column only. One small
        # product per column, then per column a (My x ny) matrix-vector product.
        t = np.matmul(d, basis.ea.T)                             # (B, ny, Mx)
        t = np.moveaxis(t, 2, 1)[..., None]                      # (B, Mx, ny, 1)
        Hd = np.matmul(basis.eb, t)[..., 0]                      # (B, Mx, My)
        return np.swapaxes(Hd, 1, 2) * basis.phase
    if basis.mode == "rows":
        # y' horizontal along y: the same with the roles of the axes exchanged.
        t = np.matmul(basis.eb, d)[..., None]                    # (B, My, nx, 1)
        Hd = np.matmul(basis.ea, t)[..., 0]                      # (B, My, Mx)
        return Hd * basis.phase
    # sum_j d[b, i, j] Ea[m, j] -> (B, n, ny), then sum_i Eb[m, i] * that.
    t = np.einsum("bij,mj->bmi", d, basis.ea, optimize=True)
    vals = np.einsum("bmi,mi->bm", t, basis.eb, optimize=True)
    vals = vals * basis.phase
    H = np.zeros((d.shape[0], My * Mx), dtype=work)
    H[:, basis.index] = vals
    return H.reshape(d.shape[0], My, Mx)


def sum_to_elements(geometry: Hologram, G: np.ndarray, kk: float, grid: tuple[int, int],
                    pitch: tuple[float, float], origin: tuple[float, float, float],
                    work: np.dtype, gap: float, route: str = "auto") -> np.ndarray:
    """The exact adjoint of :func:`sum_to_plane`: a spectrum ``(B, My, Mx)`` evaluated at
    the posed elements, ``sum_k G(k) conj(exp(-i K.(r_e - r0)))`` -> ``(B, ny, nx)``
    (divided by ``My Mx``: the field of those plane waves there, the module
    docstring's ``u(r_e)``); the nufft route to finufft's ``EPS``."""
    route = _route(geometry, grid, route)
    reach = -np.log(_EVANESCENT_FLOOR) / max(gap, 1e-12)
    if route == "nufft":
        return elements_nufft(geometry, G, kk, grid, pitch, origin, work, reach)
    basis = _remap(geometry, kk, grid, pitch, origin, work, reach)
    B = G.shape[0]
    if basis.mode == "columns":
        Hd = np.swapaxes(G * np.conj(basis.phase), 1, 2)         # (B, Mx, My)
        t = np.matmul(np.conj(np.swapaxes(basis.eb, 1, 2)), Hd[..., None])[..., 0]
        return np.einsum("bxi,xj->bij", t, np.conj(basis.ea), optimize=True)
    if basis.mode == "rows":
        gp = G * np.conj(basis.phase)                            # (B, My, Mx)
        t = np.einsum("yxj,byx->byj", np.conj(basis.ea), gp, optimize=True)
        return np.einsum("yi,byj->bij", np.conj(basis.eb), t, optimize=True)
    vals = G.reshape(B, -1)[:, basis.index] * np.conj(basis.phase)
    t = vals[:, :, None] * np.conj(basis.eb)[None]              # (B, n, ny)
    return np.einsum("bmi,mj->bij", t, np.conj(basis.ea), optimize=True)


def _route(geometry: Hologram, grid: tuple[int, int], route: str) -> str:
    if route not in ("auto", "nufft", "direct"):
        raise ValueError(f"route must be 'auto', 'nufft' or 'direct', got {route!r}")
    if route == "auto":
        # finufft needs the elements on a uniform grid; the direct sums do not
        return choose_route(grid, geometry.pose, geometry.data.shape[-2:]) \
            if _uniform(geometry.x) and _uniform(geometry.y) else "direct"
    return route


def _sum_terms(g: GroundGrid) -> tuple[float, tuple[float, float, float]]:
    """The sum's wavenumber and the grid's origin."""
    return 2 * g.k if g.mono else g.k, (float(g.x[0]), float(g.y[0]), g.z_ref)


def _remap(geometry: Hologram, kk: float, grid: tuple[int, int], pitch: tuple[float, float],
           origin: tuple[float, float, float], work: np.dtype, reach: float) -> _Remap:
    key = ("ground-basis", grid, pitch, origin, kk, geometry.pose, geometry.x.tobytes(),
           geometry.y.tobytes(), work.str, round(reach, 6))
    return _CACHE.get(key, lambda: _Remap.build(grid, pitch, origin, kk, geometry.pose,
                                                geometry.x, geometry.y, work, reach))


#: The direct route's multiply-adds up to which it stays the default (its cost grows
#: as the grid times the elements, finufft's about as the grid): measured faster than
#: finufft below, slower above (benchmarks/results_oblique.json, docs/oblique.md).
DIRECT_MAX_PRODUCTS = 2**19


def choose_route(grid: tuple[int, int], pose: Any, shape: tuple[int, int]) -> str:
    """The faster route of the spectrum's sum, as measured (``docs/oblique.md``).

    The direct sums cost ``My Mx ny + Mx nx ny`` multiply-adds when the aperture's
    ``x'`` lies along the world's ``x`` (azimuth 90 degrees, or level), ``My Mx nx +
    My nx ny`` when ``y'`` lies along ``y`` (azimuth 0) and ``My Mx nx ny`` otherwise;
    they are chosen while that stays under :data:`DIRECT_MAX_PRODUCTS`, finufft above.

    Parameters
    ----------
    grid : (My, Mx)
        The world FFT grid.
    pose : Pose
        The aperture's pose.
    shape : (ny, nx)
        The aperture's elements.

    Returns
    -------
    str
        ``"direct"`` or ``"nufft"``.
    """
    u, v = pose.u, pose.v
    ny, nx = shape
    My, Mx = grid
    if u[1] == 0 and u[2] == 0:
        products = My * Mx * ny + Mx * nx * ny
    elif v[0] == 0 and v[2] == 0:
        products = My * Mx * nx + My * nx * ny
    else:
        products = My * Mx * nx * ny
    return "direct" if products <= DIRECT_MAX_PRODUCTS else "nufft"


def _uniform(axis: np.ndarray) -> bool:
    """Whether element coordinates are uniformly spaced (one element: trivially)."""
    if axis.size < 2:
        return True
    try:
        uniform_step(axis, "axis")
    except ValueError:
        return False
    return True


def _dense(values: np.ndarray, index: np.ndarray, grid: tuple[int, int]) -> np.ndarray:
    """Values at flat indices of a grid, zero elsewhere, shape ``grid``."""
    out = np.zeros(grid[0] * grid[1], dtype=values.dtype)
    out[index] = values
    return out.reshape(grid)


class _Remap:
    """Cached factors of the non-uniform Fourier sum for one geometry."""

    def __init__(self, index: np.ndarray, ea: np.ndarray, eb: np.ndarray,
                 phase: np.ndarray, mode: str) -> None:
        self.index, self.ea, self.eb, self.phase, self.mode = index, ea, eb, phase, mode
        self.nbytes = index.nbytes + ea.nbytes + eb.nbytes + phase.nbytes

    @classmethod
    def build(cls, grid: tuple[int, int], pitch: tuple[float, float],
              origin: tuple[float, float, float], kk: float, pose: Any, xl: np.ndarray,
              yl: np.ndarray, work: np.dtype, reach: float) -> _Remap:
        p, q = spectral_axes(grid, *pitch)
        P, Q = np.meshgrid(p, q)
        kappa2 = (P**2 + Q**2).ravel()
        kz = np.sqrt((kk * kk - kappa2).astype(complex))
        kz = np.where(kz.imag < 0, -kz, kz)
        # Components evanescent in the air that decay below the floor over the
        # shortest air path to anything imaged are left out.
        keep = kz.imag < reach
        index = np.flatnonzero(keep)
        K = np.stack([P.ravel()[index], Q.ravel()[index], -np.conj(kz[index])], axis=1)
        u, v = pose.u, pose.v
        # Element coordinates counted from the lowest corner (largest z): every factor of
        # an evanescent component then has a modulus of at most 1 (counted from the
        # centre, the two halves' factors reach exp(+-Im(kz) rise / 2), beyond complex64's
        # range for a tall aperture close to the ground).
        x0 = xl[-1] if u[2] > 0 else xl[0]
        y0 = yl[-1] if v[2] > 0 else yl[0]
        a, b = xl - x0, yl - y0
        c = np.asarray(pose.center) + x0 * np.asarray(u) + y0 * np.asarray(v) \
            - np.asarray(origin)
        # An aperture axis along a world axis (azimuth 0 or 90 degrees, or level):
        # its phase depends on one grid index, and the sum over it is a small
        # product per grid row or column (the common layouts, several times faster).
        My, Mx = grid
        phase = np.exp(-1j * (K @ c))
        if u[1] == 0 and u[2] == 0:
            mode = "columns"
            ea = np.exp(-1j * np.outer(p * u[0], a))                  # (Mx, nx)
            eb = np.zeros((Mx * My, yl.size), complex)               # (Mx, My, ny)
            eb[(index % Mx) * My + index // Mx] = np.exp(-1j * np.outer(K @ v, b))
            eb = eb.reshape(Mx, My, yl.size)
            phase = _dense(phase, index, grid)
        elif v[0] == 0 and v[2] == 0:
            mode = "rows"
            ea = np.zeros((My * Mx, xl.size), complex)               # (My, Mx, nx)
            ea[index] = np.exp(-1j * np.outer(K @ u, a))
            ea = ea.reshape(My, Mx, xl.size)
            eb = np.exp(-1j * np.outer(q * v[1], b))                  # (My, ny)
            phase = _dense(phase, index, grid)
        else:
            mode = "full"
            ea = np.exp(-1j * np.outer(K @ u, a))
            eb = np.exp(-1j * np.outer(K @ v, b))
        ea, eb, phase = ea.astype(work), eb.astype(work), phase.astype(work)
        for a in (index, ea, eb, phase):
            a.setflags(write=False)
        return cls(index, ea, eb, phase, mode)
