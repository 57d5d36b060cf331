"""The search over eps': the best fit of one object at each trial permittivity.

For each trial eps' the object's range is started from a scan around the range of
the same paraxial curvature (and, across frequencies, every alias of the same
delay), then range and lateral position (a line's azimuth and length too) are
fitted by bounded Gauss-Newton; the best focus fraction, range and position are
kept per eps' (``Search.best``), each trial starting from its nearest neighbour's.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from ..._lazy import lazy_module
from ..._validate import AliasingWarning
from ...data.hologram import C0, Hologram
from ...physics.medium import Medium
from ...theory import range_resolution
from ..migrate import migrate
from ..point_response import PointResponse
from .progress import make_room

_opt = lazy_module("scipy.optimize")

__all__ = ["Search", "line_from_image"]

# The position fit's stopping rule. Gauss-Newton converges quadratically, so a step that
# lowers the residual by less than _FTOL of itself leaves an error far below that; the
# interval's drop is >= 1e-4 of the residual (noise), so 1e-8 is ample. _XTOL: metres.
_FTOL = 1e-8
_XTOL = 1e-9


class Search:
    """The best focus for each trial eps': the range from a scan (around the paraxially
    equivalent range and every alias of the delay), then range and lateral position by
    bounded Gauss-Newton.

    Parameters
    ----------
    pr : PointResponse
        The model fitted (a :class:`~holoradar.imaging.line_response.LineResponse` for
        lines).
    make : callable
        eps' -> Medium.
    lo, hi : float
        The eps' range searched.
    hologram : Hologram
        The data (glare removed).
    bar : tqdm, optional
        A progress bar, one step per trial.

    Attributes
    ----------
    best : dict
        eps' -> (focus fraction, range in metres, lateral position (x, y) in metres,
        and a line's azimuth in radians and length in metres), for every eps' tried.
    trials : int
        Positions the object was looked for at (the detection's look-elsewhere count).
    """

    def __init__(self, pr: PointResponse, make: Callable[[float], Medium], lo: float, hi: float,
                 hologram: Hologram, bar: Any = None) -> None:
        self.pr, self.make, self.lo, self.hi = pr, make, lo, hi
        self.bar = bar
        self.hologram = hologram
        self.lam = C0 / float(np.mean(hologram.frequencies))
        self.best: dict[float, tuple[float, float, np.ndarray]] = {}
        self.A = self.P = 0.0
        self.depths = (0.0, 0.0)
        self.xy = np.zeros(2)
        f = hologram.frequencies
        self.wideband = f.size > 1 and pr.coherent
        self.band = float(f.max() - f.min()) if f.size > 1 else 0.0
        # Uniformly stepped frequencies fix the optical path only modulo c/(2 df).
        self.alias = C0 / (2 * float(np.min(np.diff(f)))) if self.wideband else np.inf
        self.z0 = 0.0
        self.trials = 1
        self.scan_length = True   # a line's first fit scans its length (_length_scan)
        self.ftol = _FTOL         # the position fit's stopping rule ...
        self.max_nfev: int | None = None  # ... and its most steps (None: scipy's)

    def locate(self, depth_range: tuple[float, float] | None, position: Any,
               z0: float) -> bool | None:
        """Where the object is: laterally the brightest column of a migrated image (or
        ``position``), its range from the point fit along that column; ``None`` when
        that lies at the ground surface (``z0``) or above it."""
        h = self.hologram
        e_mid = float(np.sqrt(self.lo * self.hi))
        m = self.make(e_mid)
        lam_m = C0 / float(h.frequencies.max()) / np.sqrt(e_mid)
        if depth_range is None:
            size = float(max(np.ptp(h.x), np.ptp(h.y)))
            depth_range = (lam_m / 2, max(0.5, 1.5 * size))
        d0, d1 = (float(v) for v in depth_range)
        if not (np.isfinite(d0) and np.isfinite(d1) and 0 <= d0 < d1):
            raise ValueError(f"depth_range must be (min, max) depths in metres with 0 <= min < "
                             f"max, got {depth_range!r}")
        zs = z0 + np.arange(max(d0, 1e-4), d1 + lam_m / 2, lam_m / 2)
        self.trials = zs.size * h.data.shape[-1] * h.data.shape[-2]
        img = self._image(zs, m)
        a = np.abs(img.data)
        if position is not None:
            try:
                px, py = (float(v) for v in position)
            except (TypeError, ValueError):
                raise ValueError(f"position must be (x, y) in metres, got {position!r}") from None
            ix, iy = int(np.argmin(abs(img.x - px))), int(np.argmin(abs(img.y - py)))
        else:
            _, iy, ix = np.unravel_index(int(np.argmax(a)), a.shape)
        self.z0 = z0
        self.xy = np.array([img.x[ix], img.y[iy], *getattr(self.pr, "shape_start", ())],
                           float)
        if getattr(self.pr, "max_length", None) is not None:
            self.xy = line_from_image(a, img.x, img.y, iy, ix, self.pr.max_length, lam_m)
        self.pr.xy_hint = self.xy[:2]
        # The object's range from the point fit itself along that column: an image's
        # brightest plane may sit far off (a wide depth of focus, aliasing, brighter
        # shallow planes); a point's response matches only near its own range.
        # Curvature (each frequency its own amplitude) and, across frequencies, delay.
        top, bottom = z0 + max(d0, 1e-4), z0 + d1
        z_a, _ = self.pr.scan(e_mid, top, bottom, self.xy, coherent=False,
                              samples=int(np.clip((d1 - d0) / (lam_m / 2), 24, 240)))
        self.A = m.apparent_distance(z_a)
        zp = z_a
        if self.wideband:
            res = range_resolution(self.band, e_mid)
            zp, _ = self.pr.scan(e_mid, top, bottom, self.xy,
                                 samples=int(np.clip((d1 - d0) / (res / 3), 24, 240)))
        self.P = m.optical_path(zp).real
        self.depths = (top, bottom)
        if zp <= z0 + lam_m / 4 or z_a <= z0 + lam_m / 4:
            return None
        return True

    def _image(self, zs: np.ndarray, medium: Medium) -> Any:
        """The migrated image :meth:`locate` takes the object's column from."""
        h = self.hologram
        combine = "coherent" if self.pr.coherent else "incoherent"
        with warnings.catch_warnings():  # only the brightest voxel is wanted here
            warnings.simplefilter("ignore", AliasingWarning)
            # A moved or tilted aperture: image on the ground's own (world) planes.
            frame = "aperture" if h.pose.is_identity else "ground"
            return migrate(h, zs, medium=medium, combine=combine, progress=False, frame=frame)

    def candidates(self) -> list[float]:
        """eps' where curvature and delay agree (half-space, paraxial), for every alias
        of the delay: uniformly spaced frequencies fix the optical path only modulo
        ``c/(2 df)``, so ``n^2 = (P + m c/(2 df) - z0)/(A - z0)`` for each integer m."""
        if not self.wideband or self.A <= self.z0:
            return []
        out = []
        for m in range(-50, 51):
            e = (self.P + m * self.alias - self.z0) / (self.A - self.z0)
            if self.lo < e < self.hi:
                out.append(float(e))
        return out

    def delay_ranges(self, eps: float) -> list[float]:
        """Ranges whose normal-incidence optical path is the located one, or one of its
        aliases ``P + m c/(2 df)`` (uniformly stepped frequencies)."""
        m = self.make(eps)
        out = []
        for k in range(-50, 51):
            P = self.P + k * self.alias
            if P <= self.z0:
                continue
            top = self.z0 + (P - self.z0) * 2 + 1e-3
            if m.optical_path(top).real < P or m.optical_path(self.z0).real > P:
                continue
            z = float(_opt.brentq(lambda z, P=P: m.optical_path(z).real - P, self.z0, top))
            if z > self.depths[1] + self.alias:
                break
            out.append(z)
        return out

    def paraxial_range(self, eps: float) -> float:
        """Range whose paraxial apparent distance is the located one."""
        m = self.make(eps)
        top = self.z0 + (self.A - self.z0) * np.sqrt(max(abs(e) for e in m.eps)) * 2 + 1e-3
        return float(_opt.brentq(lambda z: m.apparent_distance(z) - self.A, self.z0, top))

    def evaluate(self, eps: float, refine_shape: bool = False) -> tuple[float, float, np.ndarray]:
        """Best focus fraction at ``eps`` with its range and lateral position.

        Bounded Gauss-Newton (trust region) on the residual ``h - a g`` with the
        amplitude ``a`` projected out, from the best range of a scan. A line's
        azimuth and length are fitted at the first trial and with ``refine_shape``.
        """
        if eps in self.best and not refine_shape:
            return self.best[eps]
        if self.bar is not None:
            if self.bar.n + 1 >= self.bar.total:
                make_room(self.bar, 4)   # more than expected: keep room
            self.bar.update()
        pr = self.pr
        floor = self.z0 + pr.spacing(eps) / 4
        lam_m = self.lam / np.sqrt(eps)
        xy0, z_start = self._start(eps, floor, lam_m)
        shape0 = np.asarray(xy0[2:], float)          # a line's azimuth and length
        if shape0.size and self.best and not refine_shape and getattr(pr, "hold_shape", True):
            # A line's shape hardly depends on eps': fitted once (the first trial, and
            # at the optimum), held during the sweep.
            return self._evaluate_fixed_shape(eps, floor, xy0, z_start, lam_m)
        p0 = np.array([xy0[0], xy0[1], z_start, *shape0])
        line = getattr(pr, "max_length", None) is not None
        if line and self.scan_length:
            p0 = self._length_scan(eps, p0, lam_m)

        def resid(p: np.ndarray) -> np.ndarray:
            r, _, _ = pr.residual(eps, max(p[2], floor), np.r_[p[:2], p[3:]])
            return np.concatenate([r.real.ravel(), r.imag.ravel()])

        lo_b, hi_b = self._box(p0, eps, floor, lam_m)
        scale = np.full(3, self.lam / 10)
        if shape0.size and not line:   # another model's own (a sphere's radius)
            lo_s, hi_s, sc = pr.shape_box(shape0, eps, self.lam)
            lo_b, hi_b, scale = np.r_[lo_b, lo_s], np.r_[hi_b, hi_s], np.r_[scale, sc]
            p0[3:] = np.clip(p0[3:], lo_b[3:] + 1e-12, hi_b[3:] - 1e-12)
        elif shape0.size:  # azimuth within 20 degrees, length within a factor 2 of the start
            L0 = float(shape0[1])
            lo_b = np.r_[lo_b, shape0[0] - 0.35, max(lam_m, 0.5 * L0)]
            hi_b = np.r_[hi_b, shape0[0] + 0.35, max(min(pr.max_length, 2 * L0), lam_m * 1.01)]
            p0[3:] = np.clip(p0[3:], lo_b[3:] + 1e-9, hi_b[3:] - 1e-9)
            scale = np.r_[scale, 0.02, self.lam / 10]
        p = _least_squares(resid, p0, lo_b, hi_b, scale, self.ftol, self.max_nfev)
        z = max(float(p[2]), floor)
        xy = np.r_[np.clip(p[:2], *pr.bounds), p[3:]]
        F = pr.focus(eps, z, xy)
        self.best[eps] = (F, z, xy)
        return self.best[eps]

    def _length_scan(self, eps: float, p: np.ndarray, lam_m: float) -> np.ndarray:
        """A line's ends with the best focus, one end then the other, every half
        wavelength in the ground within half the longest line of its centre: the focus
        ripples with each end's position (its diffraction interferes with the specular
        echo, a period of a wavelength in the air or more, two to five of these steps),
        so a local fit alone stops on the ripple nearest its start. Returns ``p`` with
        the centre and length moved."""
        x, y, z, phi, length = (float(v) for v in p)
        t = np.array([np.cos(phi), np.sin(phi)])
        ends = [-0.5 * length, 0.5 * length]
        reach = 0.5 * self.pr.max_length
        for j in (1, 0):
            other = ends[1 - j]
            grid = (np.arange(other + lam_m, reach + lam_m / 4, lam_m / 2) if j else
                    np.arange(-reach, other - lam_m + lam_m / 4, lam_m / 2))
            if grid.size == 0:
                continue
            F = [self.pr.focus(eps, z, np.r_[np.array([x, y]) + 0.5 * (e + other) * t, phi,
                                            abs(e - other)]) for e in grid]
            ends[j] = float(grid[int(np.argmax(F))])
        c = np.array([x, y]) + 0.5 * (ends[0] + ends[1]) * t
        return np.array([c[0], c[1], z, phi, ends[1] - ends[0]])

    def _start(self, eps: float, floor: float, lam_m: float) -> tuple[np.ndarray, float]:
        """The fit's start at ``eps``: the lateral position (and a line's shape) of the
        nearest eps' tried, and a range from a scan (or, one frequency and a neighbour
        within 5%, its range moved along the paraxial curve)."""
        pr = self.pr
        offset, xy0, close = 0.0, self.xy, False
        if self.best:  # start from the fit at the nearest eps' tried (a continuous path)
            near = min(self.best, key=lambda e: abs(np.log(e / eps)))
            _, z_near, xy0 = self.best[near]
            offset = z_near - self.paraxial_range(near)
            close = abs(np.log(eps / near)) < 0.05
        # The object's range for this eps': near the range of the same paraxial curvature
        # (one frequency) or between it and the range of the same delay (several).
        z_c = self.paraxial_range(eps) + offset
        if self.wideband:
            # Around the paraxial range and every alias of the delay within the depths
            # searched (the best may be any), finely: the focus peaks over about half the
            # range resolution.
            res = C0 / (2 * self.band * np.sqrt(eps))  # range resolution in the ground
            centres = [z for z in (z_c, *self.delay_ranges(eps))
                       if self.depths[0] - res <= z <= self.depths[1] + res]
            z_start, _ = max((pr.scan(eps, max(c - res, floor), max(c + res, floor + lam_m),
                                      xy0, samples=17) for c in centres),
                             key=lambda t: t[1])
        elif close:
            # One frequency, a neighbour within 5% of eps': its range moved along the
            # paraxial curve is a start well inside the fit's basin (2 wavelengths wide).
            z_start = max(z_c, floor)
        else:
            z_start, _ = pr.scan(eps, max(z_c - lam_m / 2, floor),
                                 max(z_c + lam_m / 2, floor + lam_m), xy0)
        return xy0, z_start

    def _box(self, p0: np.ndarray, eps: float, floor: float,
             lam_m: float) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of (x, y, range) around the start ``p0`` (its x, y clipped to the
        model's bounds in place): bounded to the scanned peak's basin, as an unbounded
        first step may jump to another alias of the delay."""
        pr = self.pr
        reach = C0 / (4 * self.band * np.sqrt(eps)) if self.wideband else 2 * lam_m
        p0[:2] = np.clip(p0[:2], *pr.bounds)
        lo_b = np.array([*np.maximum(p0[:2] - 2 * lam_m, pr.bounds[0]),
                         max(p0[2] - reach, floor)])
        hi_b = np.array([*np.minimum(p0[:2] + 2 * lam_m, pr.bounds[1]), p0[2] + reach])
        lo_b[:2] = np.minimum(lo_b[:2], p0[:2] - 1e-9)  # a non-empty box at the edge
        hi_b[:2] = np.maximum(hi_b[:2], p0[:2] + 1e-9)
        return lo_b, hi_b

    def _evaluate_fixed_shape(self, eps: float, floor: float, xy0: np.ndarray, z_start: float,
                              lam_m: float) -> tuple[float, float, np.ndarray]:
        pr = self.pr
        shape = np.asarray(xy0[2:], float)
        p0 = np.array([xy0[0], xy0[1], z_start])

        def resid(p: np.ndarray) -> np.ndarray:
            r, _, _ = pr.residual(eps, max(p[2], floor), np.r_[p[:2], shape])
            return np.concatenate([r.real.ravel(), r.imag.ravel()])

        lo_b, hi_b = self._box(p0, eps, floor, lam_m)
        p = _least_squares(resid, p0, lo_b, hi_b, np.full(3, self.lam / 10), self.ftol,
                           self.max_nfev)
        z = max(float(p[2]), floor)
        xy = np.r_[np.clip(p[:2], *pr.bounds), shape]
        self.best[eps] = (pr.focus(eps, z, xy), z, xy)
        return self.best[eps]


def _least_squares(resid: Callable[[np.ndarray], np.ndarray], p0: np.ndarray,
                   lo_b: np.ndarray, hi_b: np.ndarray, scale: np.ndarray,
                   ftol: float = _FTOL, max_nfev: int | None = None) -> np.ndarray:
    """The bounded trust-region fit of ``resid`` from ``p0`` (its stopping rule above)."""
    sol = _opt.least_squares(resid, p0, method="trf", bounds=(lo_b, hi_b), xtol=_XTOL,
                             ftol=ftol, gtol=ftol, x_scale=scale, max_nfev=max_nfev)
    return sol.x


def line_from_image(a: np.ndarray, x: np.ndarray, y: np.ndarray, iy: int, ix: int,
                    max_length: float, lam_m: float) -> np.ndarray:
    """A line's start (x, y, azimuth, length) from a migrated image's plane that holds the
    brightest pixel: the straight line through that pixel along which the image is
    brightest (its mean over directions 1 degree apart: a bar that crosses another is
    followed, not merged with it), and the stretch of that line above half the pixel's
    value that holds the pixel (its centre and extent)."""
    from scipy import ndimage

    plane = a.reshape((-1, *a.shape[-3:])).max(axis=0)
    iz = int(np.argmax(plane[:, iy, ix]))
    p = plane[iz]
    dx, dy = float(x[1] - x[0]) if x.size > 1 else 1.0, float(y[1] - y[0]) if y.size > 1 else 1.0
    step = 0.5 * min(abs(dx), abs(dy))
    reach = float(np.hypot(np.ptp(x), np.ptp(y)))
    s = np.arange(-reach, reach + step / 2, step)
    phis = np.radians(np.arange(0.0, 180.0, 1.0))
    cols = ix + s[None, :] * np.cos(phis)[:, None] / dx           # (directions, samples)
    rows = iy + s[None, :] * np.sin(phis)[:, None] / dy
    inside = (cols >= 0) & (cols <= p.shape[1] - 1) & (rows >= 0) & (rows <= p.shape[0] - 1)
    vals = ndimage.map_coordinates(p, [rows.ravel(), cols.ravel()], order=1,
                                   mode="nearest").reshape(rows.shape)
    score = np.where(inside, vals, 0.0).sum(axis=1) / np.maximum(inside.sum(axis=1), 1)
    k = int(np.argmax(score))
    phi = float(phis[k])
    above = inside[k] & (vals[k] >= 0.5 * p[iy, ix])
    i0 = int(np.argmin(np.abs(s)))
    lo = hi = i0
    while lo > 0 and above[lo - 1]:
        lo -= 1
    while hi < s.size - 1 and above[hi + 1]:
        hi += 1
    mid = 0.5 * (s[lo] + s[hi])
    length = float(np.clip(s[hi] - s[lo] + 2 * abs(dx), 2 * lam_m, max_length))
    return np.array([float(x[ix]) + mid * np.cos(phi), float(y[iy]) + mid * np.sin(phi), phi,
                     length])
