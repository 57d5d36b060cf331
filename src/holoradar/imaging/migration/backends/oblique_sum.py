"""The ground frame's spectrum sums: posed samples onto a world grid's plane waves, and back.

On a horizontal reference plane ``z_ref`` (the lowest element's world range) and a
periodic world grid of pitch ``(dx, dy)`` from ``(x0, y0)``, the data's spectrum is

    H(k) = sum_e d_e exp(-i K.(r_e - r0)),   K = (p, q, -conj(kz)),

``kz = sqrt(k^2 - p^2 - q^2)`` (a transceiver's round trip: ``2k``), a non-uniform
Fourier sum evaluated exactly at every grid wavenumber (:func:`sum_to_plane`). With
element coordinates ``(x'_j, y'_i)`` on the aperture's own axes ``u``, ``v`` it
factors: ``H(k) = exp(-i K.(c - r0)) sum_i exp(-i y'_i K.v) sum_j d_ij exp(-i x'_j
K.u)``: two small matrix products (the "direct" route), or a type-2 non-uniform FFT
(the "nufft" route, :mod:`.oblique_nufft`); :func:`choose_route` takes the faster, as
measured. :func:`sum_to_elements` is the exact adjoint (the field of a grid's plane
waves at the elements, times ``My Mx``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...._validate import uniform_step
from ....data.hologram import Hologram
from ....physics.propagation import TRANSFER_CACHE, spectral_axes
from .oblique_nufft import elements_nufft, spectrum_nufft

#: Components evanescent in the air damped below this over the air gap are left out.
EVANESCENT_FLOOR = 1e-8


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
    reach = -np.log(EVANESCENT_FLOOR) / max(gap, 1e-12)   # largest Im(kz) kept
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
    reach = -np.log(EVANESCENT_FLOOR) / max(gap, 1e-12)
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
    return preferred_route(geometry, grid) if route == "auto" else route


def uniform_elements(geometry: Hologram) -> bool:
    """Whether the elements lie on a uniform grid (finufft's modes need one)."""
    return _uniform(geometry.x) and _uniform(geometry.y)


def preferred_route(geometry: Hologram, grid: tuple[int, int]) -> str:
    """The route ``"auto"`` takes, decided here only (the ground-frame backends ask it
    too): finufft where the elements are on a uniform grid and the measured costs
    favour it (:func:`choose_route`), else the direct sums."""
    if not uniform_elements(geometry):
        return "direct"
    return choose_route(grid, geometry.pose, geometry.data.shape[-2:])


def _remap(geometry: Hologram, kk: float, grid: tuple[int, int], pitch: tuple[float, float],
           origin: tuple[float, float, float], work: np.dtype, reach: float) -> _Remap:
    key = ("ground-basis", grid, pitch, origin, kk, geometry.pose, geometry.x.tobytes(),
           geometry.y.tobytes(), work.str, round(reach, 6))
    return TRANSFER_CACHE.get(key, lambda: _Remap.build(grid, pitch, origin, kk, geometry.pose,
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
