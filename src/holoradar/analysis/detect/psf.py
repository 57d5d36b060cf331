"""The image of a point without its hologram: the aperture's own point response.

An image migrated from a level receiver array at one frequency is linear in the
hologram and, on the aperture's grid (``migrate(..., fov="aperture",
upsample=u)``), shift-invariant by whole element pitches: the image of element
data ``h_n`` is ``I(j) = sum_n h_n K(j - u n)``, ``K`` the migration of one
element's unit sample (periodic over the padded FFT grid, computed once by
``migrate(..., fov="full")``). A point at ``(x0, y0, z)`` sends the elements its
exact field ``g_n(x0, y0, z)`` (the layered Green's function,
:class:`~holoradar.imaging.point_response.PointResponse`), so its image is

    P(x0, y0) = sum_n g_n(x0, y0, z) K(. - u n):

the rectangular N x N aperture of pitch ``d`` at range ``z`` with everything the
analytic ``sinc`` leaves out (the chirp ``exp(-i k r^2 / 2L)`` across the
focus, the discrete aperture's Dirichlet kernel, the amplitude taper across the
aperture, aliasing of a pitch above lambda/2). Its first sidelobes are what the
analytic window got wrong by tens of percent (a 16 x 16 plane with two points
gave 25 "objects").

The aperture is not stored in an image: its elements are the image's grid at a
pitch ``d = u dx`` (``fov="aperture"``: the first and last pixels are the first
and last elements), ``u`` a common divisor of ``nx - 1`` and ``ny - 1``. ``u`` is
fitted to the data: the first (brightest) object is fitted with every candidate
pitch up to 2 lambda and the pitch whose response explains the
most of it is kept for the image.

Each object's position ``(x0, y0)`` maximises the normalised matched filter
``|<R, P>|^2 / ||P||^2`` over its main lobe (a box of one resolution cell
``lambda L/A`` each way, ``L`` the apparent distance); the amplitude is the
least-squares fit over the main lobe and first sidelobes (two cells each way),
where CLEAN then measures what the model leaves. The range is the plane's.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..._validate import AliasingWarning
from ...data.hologram import C0, Hologram
from ...physics.medium import Medium
from .grid import Volume

__all__ = ["ApertureModel", "pad_variants", "pitch_candidates"]

SIDELOBE = 10 ** (13.26 / 10)
"""Peak over first sidelobe of a uniform aperture's image, in intensity (13.26 dB: the
``sinc``'s first maximum, 0.2172): an object weaker than this times the threshold has
no sidelobe that could pass it, and its pitch need not be chosen yet."""

FIT_CELLS = 2.0
"""Half-width of the fit box in resolution cells: the main lobe (one cell to its first
null) and the first sidelobes (from one to two cells)."""


def pitch_candidates(nx: int, ny: int, dx: float, dy: float, wavelength: float
                     ) -> list[int]:
    """Upsampling factors ``u`` an image of ``nx x ny`` pixels may have been made with.

    ``u`` divides ``nx - 1`` and ``ny - 1`` (at least 2 elements along each axis)
    and puts the pitch ``u dx`` at most at 2 lambda (coarser arrays are not imaging
    arrays). Of the pitches up to lambda/2 only the coarsest is kept: an array
    sampled at lambda/2 or finer images a point as the continuous aperture does
    (no aliasing), whatever its pitch.

    Examples
    --------
    >>> pitch_candidates(61, 61, 0.00625, 0.00625, 0.0303)
    [2, 3, 4, 5, 6]
    """
    g = math.gcd(nx - 1, ny - 1)
    step = max(dx, dy)
    us = [u for u in range(1, g + 1) if g % u == 0 and u * step <= 2 * wavelength]
    fine = [u for u in us if u * step <= wavelength / 2]
    return fine[-1:] + [u for u in us if u * step > wavelength / 2]


class _Aperture:
    """One candidate aperture: its elements, kernel and point responses."""

    def __init__(self, vol: Volume, u: int, frequency: float, medium: Medium | None,
                 pr_medium: Medium, pad: Any = True) -> None:
        from ...imaging.migrate import migrate
        from ...imaging.point_response import PointResponse

        ny, nx = vol.data.shape[1:]
        self.u = u
        self.nx, self.ny = (nx - 1) // u + 1, (ny - 1) // u + 1
        xe = vol.x[0] + np.arange(self.nx) * u * vol.dx
        ye = vol.y[0] + np.arange(self.ny) * u * vol.dy
        self.size = (self.nx * u * vol.dx, self.ny * u * vol.dy)
        self.holo = Hologram(np.zeros((self.ny, self.nx), complex), xe, ye, frequency)
        self.z = float(vol.z[0])
        self.medium = medium
        self.pad = pad
        self.opts = {"medium": medium, "upsample": u, "snr_db": 40.0, "pad": pad}
        delta = np.zeros((self.ny, self.nx), complex)
        delta[0, 0] = 1.0
        with warnings.catch_warnings():   # the image's migration warned of aliasing
            warnings.simplefilter("ignore", AliasingWarning)
            full = migrate(self.holo.with_data(delta), self.z, fov="full", **self.opts)
        self.K = np.asarray(full.data)
        self.sx = int(np.argmin(np.abs(full.x - vol.x[0])))
        self.sy = int(np.argmin(np.abs(full.y - vol.y[0])))
        self.pr = PointResponse(self.holo, lambda e: pr_medium, coherent=True)
        self.pr_medium = pr_medium
        self.eps = float(np.real(pr_medium.eps[int(pr_medium.region_of(self.z))]))

    def matrix(self, by: np.ndarray, bx: np.ndarray) -> np.ndarray:
        """The image operator on the pixel box ``by x bx``: (len(by) len(bx), n_elements)."""
        My, Mx = self.K.shape
        iy = (by[:, None] - self.u * np.arange(self.ny)[None, :] + self.sy) % My
        ix = (bx[:, None] - self.u * np.arange(self.nx)[None, :] + self.sx) % Mx
        M = self.K[iy[:, None, :, None], ix[None, :, None, :]]
        return M.reshape(by.size * bx.size, self.ny * self.nx)

    def g(self, x0: float, y0: float, z0: float | None = None) -> np.ndarray:
        """Field of a unit point at (x0, y0, z0) at the elements, (N,) (z0: the plane's)."""
        z = self.z if z0 is None else float(z0)
        eps = self.eps if z0 is None else float(np.real(
            self.pr_medium.eps[int(self.pr_medium.region_of(z))]))
        return self.pr.response(eps, z, (float(x0), float(y0)))[0]

    def z_bounds(self) -> tuple[float, float]:
        """Ranges a point imaged on this plane may take: the plane's layer (1 mm inside)."""
        zi = (-np.inf, *self.pr_medium.z_interfaces, np.inf)
        i = int(self.pr_medium.region_of(self.z))
        return max(zi[i] + 1e-3, 1e-3), zi[i + 1] - 1e-3

    def image(self, g: np.ndarray) -> np.ndarray:
        """The migration of element data ``g`` on the image's plane, (ny, nx)."""
        from ...imaging.migrate import migrate

        h = self.holo.with_data(g.reshape(self.ny, self.nx))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", AliasingWarning)
            return np.asarray(migrate(h, self.z, **self.opts).data)


def pad_variants(shape: tuple[int, int], pitch: tuple[float, float], wavelength: float,
                 z: float) -> list[Any]:
    """``migrate``'s ``pad`` arguments for the FFT grids the image may have had.

    ``pad=True`` sizes the grid by ``ceil(lambda z / (d d_edge))``, which an exact
    ratio puts on either side of a whole number by the last bit of the pitch (the
    hologram's and the one read off the image differ there): a different periodic
    grid, a response 0.5 % different. Both grids (as exact pad factors) when they
    differ, else ``[True]``.

    Examples
    --------
    >>> pad_variants((24, 24), (0.0125, 0.0125), 0.0303, 0.43)
    [True]
    >>> len(pad_variants((24, 24), (0.0125, 0.0125), 0.0303, 0.5))   # 2 z/d = 80
    2
    """
    from ...physics.propagation import padded_shape

    shapes = []
    for f in (1 - 1e-9, 1.0, 1 + 1e-9):
        sh = padded_shape(shape, True, pitch=(pitch[0] * f, pitch[1] * f),
                          wavelength=wavelength, z_max=z)
        if sh not in shapes:
            shapes.append(sh)
    if len(shapes) == 1:
        return [True]
    out: list[Any] = []
    for sh in shapes:
        # A factor that gives exactly this grid along both axes, if one does.
        for factor in ((sh[1] - 0.5) / shape[1], (sh[0] - 0.5) / shape[0]):
            if padded_shape(shape, float(factor)) == sh:
                out.append(float(factor))
                break
    return out or [True]


TRANSFER_CACHE: dict[tuple, _Aperture] = {}
_CACHE_SIZE = 16


def _aperture(vol: Volume, u: int, frequency: float, medium: Medium | None,
              pr_medium: Medium, pad: Any = True) -> _Aperture:
    """A candidate aperture, kept for images on the same grid (a batch of planes, a
    noise study: the kernel and the Green's function tables are built once)."""
    key = (vol.data.shape[1:], round(float(vol.x[0]), 9), round(float(vol.y[0]), 9),
           round(vol.dx, 12), round(vol.dy, 12), float(frequency), round(float(vol.z[0]), 9),
           medium, u, pad)
    ap = TRANSFER_CACHE.get(key)
    if ap is None:
        if len(TRANSFER_CACHE) >= _CACHE_SIZE:
            TRANSFER_CACHE.pop(next(iter(TRANSFER_CACHE)))
        ap = TRANSFER_CACHE[key] = _Aperture(vol, u, frequency, medium, pr_medium, pad)
    return ap


class ApertureModel:
    """Point response of a plane image made by a level receiver array at one frequency.

    Parameters
    ----------
    volume : Volume
        One plane (``fov="aperture"``), one frequency.
    medium : Medium, optional
        The ground the image was formed through.
    """

    kind = "aperture"

    def __init__(self, volume: Volume, medium: Medium | None = None) -> None:
        f = np.atleast_1d(volume.frequency) if volume.frequency is not None else np.array([])
        if f.size != 1 or not np.isfinite(f[0]) or f[0] <= 0:
            raise ValueError("ApertureModel needs one frequency (Hz) in image.frequency")
        self.f = float(f[0])
        self.k = 2 * np.pi * self.f / C0
        self.vol = volume
        self.medium = medium
        z = float(volume.z[0])
        # As HologramModel: free space as a ground of eps 1 + 1e-6 below half the range
        # (eps exactly 1 puts a quadrature node on the Green integral's branch point).
        self.pr_medium = medium if medium is not None and not medium.is_free_space else \
            Medium.half_space(0.5 * z, 1.0 + 1e-6)
        ny, nx = volume.data.shape[1:]
        lam = 2 * np.pi / self.k
        self.candidates = [(u, pad) for u in pitch_candidates(nx, ny, volume.dx, volume.dy, lam)
                           for pad in pad_variants(((ny - 1) // u + 1, (nx - 1) // u + 1),
                                                   (u * volume.dx, u * volume.dy), lam, z)]
        if not self.candidates:
            raise ValueError("image: no element pitch up to 2 lambda fits its grid "
                             )
        self.ap: _Aperture | None = None
        self.detection: tuple[float, float] = (np.inf, 0.0)  # set by CLEAN before a fit

    @staticmethod
    def applies(volume: Volume) -> bool:
        """One plane at one frequency on a grid some aperture's pitch divides, imaged
        from a level array (not a tilted array's ground frame: its elements are not on
        the image's grid)."""
        if volume.method.endswith(":ground"):
            return False
        f = np.atleast_1d(volume.frequency) if volume.frequency is not None else np.array([])
        if volume.z.size != 1 or f.size != 1 or not np.isfinite(f[0]) or f[0] <= 0:
            return False
        ny, nx = volume.data.shape[1:]
        return bool(pitch_candidates(nx, ny, volume.dx, volume.dy, C0 / float(f[0])))

    def start(self) -> np.ndarray:
        """The residual to begin with: the image itself."""
        return self.vol.data.copy()

    def _candidate(self, i: int) -> _Aperture:
        u, pad = self.candidates[i]
        return _aperture(self.vol, u, self.f, self.medium, self.pr_medium, pad)

    def cell(self, ap: _Aperture | None = None) -> tuple[float, float]:
        """Lateral resolution ``lambda L / A`` along x and y at the plane, metres."""
        ap = ap or self.ap or self._candidate(0)
        A, B = ap.size
        z = float(self.vol.z[0])
        L = self.medium.apparent_distance(z) if self.medium is not None else z
        lam = 2 * np.pi / self.k
        return lam * L / A, lam * L / B

    def widths(self, z: float) -> tuple[float, float]:
        """``(mu, nu) = pi / cell`` (rad/m): the spectral half-widths of the aperture."""
        cx, cy = self.cell()
        return np.pi / cx, np.pi / cy

    def _box(self, ap: _Aperture, center: Any, cells: float) -> tuple[np.ndarray, np.ndarray]:
        """Pixel rows and columns within ``cells`` resolution cells of ``center``."""
        cx, cy = self.cell(ap)
        bx = np.flatnonzero(np.abs(self.vol.x - center[0]) <= cells * cx)
        by = np.flatnonzero(np.abs(self.vol.y - center[1]) <= cells * cy)
        return by, bx

    def _fit(self, ap: _Aperture, plane: np.ndarray, start: Any, *, with_range: bool
             ) -> tuple[np.ndarray, complex, float, np.ndarray]:
        """Position, amplitude, the share of the fit box it explains, and that box.

        Laterally only (``with_range=False``) the position maximises the matched filter
        over the main lobe (to the first nulls, one cell each way: the sidelobes add
        little lateral information and cost four times the pixels). With the range
        (a bright object, whose sidelobes stand above the threshold), over the fit
        box of :data:`FIT_CELLS` cells: a point off the plane images defocused, its
        sidelobes filled in and its phase curved, which the in-focus response would
        leave behind. Amplitude and share are taken over the fit box.
        """
        from scipy.optimize import minimize

        cx, cy = self.cell(ap)
        by, bx = self._box(ap, start, FIT_CELLS if with_range else 1.0)
        # Every (u/2)-th pixel: the image is band-limited to the elements' band
        # |p| <= pi/d, which two samples per pitch hold (the upsampled pixels add none).
        stride = max(ap.u // 2, 1)
        by, bx = by[::stride], bx[::stride]
        M = ap.matrix(by, bx)
        d = plane[np.ix_(by, bx)].ravel()
        d = d / (np.sqrt(float(np.vdot(d, d).real)) or 1.0)
        z_lo, z_hi = ap.z_bounds()

        def cost(v: np.ndarray) -> float:
            if len(v) == 3 and not z_lo <= v[2] <= z_hi:
                return 1.0 + min(abs(v[2] - z_lo), abs(v[2] - z_hi))
            # The object stays within a cell of its peak (its fit box is there).
            off = np.hypot((v[0] - start[0]) / cx, (v[1] - start[1]) / cy)
            if off > 1.0:
                return float(off)
            p = np.einsum("pe,e->p", M, ap.g(*v))  # (BLAS's zgemv: 10x slower here)
            n = float(np.vdot(p, p).real)
            return -abs(np.vdot(p, d)) ** 2 / n if n > 0 else 0.0

        x0 = np.array(start[:2], float)
        steps = [cx / 4, cy / 4]
        if with_range:
            x0 = np.append(x0, start[2] if len(start) > 2 else ap.z)
            steps.append(max(cx, cy))  # the focus is several cells long along range
        simplex = np.vstack([x0, x0 + np.diag(steps)])
        res = minimize(cost, x0, method="Nelder-Mead",
                       options={"initial_simplex": simplex, "xatol": 1e-3 * min(cx, cy),
                                "fatol": 1e-7, "maxiter": 300})
        r = np.asarray(res.x, float)
        a, box, share = self._share(ap, plane, r)
        return r, a, share, box

    def _share(self, ap: _Aperture, plane: np.ndarray, r: np.ndarray
               ) -> tuple[complex, np.ndarray, float]:
        """Amplitude of a point at ``r``, the fit box, and the share of its energy the
        point explains there."""
        by, bx = self._box(ap, r, FIT_CELLS)
        p = np.einsum("pe,e->p", ap.matrix(by, bx), ap.g(*r))
        d = plane[np.ix_(by, bx)].ravel()
        c = complex(np.vdot(p, d))
        n = float(np.vdot(p, p).real)
        share = abs(c) ** 2 / (n * (float(np.vdot(d, d).real) or 1.0)) if n > 0 else 0.0
        box = np.zeros(plane.shape, bool)
        box[np.ix_(by, bx)] = True
        return c / n if n > 0 else 0j, box, share

    def fit(self, residual: np.ndarray, index: tuple[int, int, int],
            position: tuple[float, float, float]
            ) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        """The model of an object found at pixel ``index`` near ``position``.

        Returns
        -------
        model : ndarray, (1, ny, nx)
            The fitted point's image.
        lobe : ndarray of bool, (ny, nx)
            Its main lobe (within 6 dB of its maximum).
        info : dict
            ``position`` (the fit's, range the plane's) and ``error_region`` (the fit
            box: main lobe and first sidelobes, where CLEAN measures the model's error).
        """
        plane = residual[0]
        stat, t = self.detection
        if stat < SIDELOBE * t:
            # Its sidelobes cannot reach the threshold: a lateral fit in the plane with
            # the pitch chosen so far (any, while none has been).
            ap = self.ap or self._candidate(0)
            r, a, _, box = self._fit(ap, plane, position[:2], with_range=False)
            return self._result(ap, r, a, box)
        if self.ap is None:
            # The pitch: the candidate whose response explains the most of the brightest
            # object's main lobe and first sidelobes, at the position fitted with the
            # first candidate (the main lobe hardly depends on the pitch), the chosen one
            # refitted.
            aps = [self._candidate(i) for i in range(len(self.candidates))]
            r0 = self._fit(aps[0], plane, position[:2], with_range=False)[0]
            shares = [self._share(aps[i], plane, r0)[2] for i in range(len(aps))]
            self.ap = aps[int(np.argmax(shares))]
            position = (float(r0[0]), float(r0[1]), position[2])
        r, a, _, box = self._fit(self.ap, plane, position[:2], with_range=False)
        # A point off the plane images defocused: fit its range too, and keep that fit
        # if it explains the fit box down to the noise (the residual's energy at most
        # twice the noise's there). A piece of a longer object (a bar) also fits
        # better with a range, by a broader defocused spot, but never down to the
        # noise: it stays in the plane and CLEAN strings it along the object.
        r3, a3, share3, box3 = self._fit(self.ap, plane, (*r[:2], self.ap.z),
                                         with_range=True)
        e_box = float(np.sum(np.abs(plane[box3]) ** 2))
        noise_box = float(np.median(np.abs(plane) ** 2)) / np.log(2) * int(box3.sum())
        if (1.0 - share3) * e_box <= 2.0 * noise_box:
            r, a, box = r3, a3, box3
        return self._result(self.ap, r, a, box)

    def _result(self, ap: _Aperture, r: np.ndarray, a: complex, box: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        m = a * ap.image(ap.g(*r))
        am = np.abs(m)
        lobe = am >= 0.5 * am.max()
        pos = (float(r[0]), float(r[1]), float(r[2]) if len(r) > 2 else ap.z)
        return m[None], lobe, {"position": pos, "error_region": box, "pitch_upsample": ap.u}
