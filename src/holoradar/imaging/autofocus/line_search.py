"""A line's steps 1-3 (locate, detect, sweep and refine eps'): fast, then exact.

The exact finite line (:class:`~holoradar.imaging.line_response.LineResponse`, nodes x
elements x frequencies interpolations a trial) is far too slow for the thousands of
trial lines a search makes. So:

1. The search runs on its asymptotic twin
   (:class:`~holoradar.imaging.line_response.LineRayResponse`: rays through the layers,
   stationary phase along the line, elements x frequencies a trial), on part of the
   data (:func:`search_subset`: every few elements and frequencies, the aperture and the
   band kept, so the same curvature and delay fix eps'). It finds the mode of eps', the
   line's range, position, azimuth and length.
2. The exact model is evaluated once, on all the data, at that fit; the asymptotic
   model on all the data is multiplied by the ratio of the two there (one complex
   factor per element and frequency, :meth:`LineRayResponse.correct_to`). At that
   fit the corrected model *is* the exact one; nearby it keeps the exact model's
   value and the asymptotic one's variation, whose error is the change of the
   asymptotic model's relative error (``O(1/(k rho))`` of the rays, the quadratic
   phase's cubic term) over the step: small against the correction itself, which is
   small (the two models' holograms correlate to 0.999 on the tests' rods).
3. On all the data, with the corrected model, the line's shape is fitted again and
   each mode of the search refitted from its fit (no range scans: each eps' starts
   from the nearest fitted one, its range moved along the same delay); the best one
   is refined by successive parabolas. The interval, the noise statistics and the
   check for rivals then follow on this search (:mod:`.steps`).

A source the asymptotic model does not know (a Gaussian beam) keeps the exact model
throughout (slow).
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any

import numpy as np

from ..._lazy import lazy_module
from ..._validate import AliasingWarning
from ...data.hologram import C0, Hologram
from ...physics.sources import PlaneWave
from ..line_response import LineRayResponse, LineResponse, LineSetResponse, ray_source
from ..migrate import migrate
from .fit_statistics import fit_statistics
from .interval import focus_drop, quantile
from .progress import make_room
from .search import Search, _least_squares

_opt = lazy_module("scipy.optimize")

__all__ = ["FirstSearch", "SetSearch", "WarmSearch", "line_steps", "search_subset"]

_SEARCH_FREQUENCIES = 11   # frequencies the search sees at most (uniform steps kept)
_SEARCH_ELEMENTS = 600     # elements it sees at most ...
_SEARCH_PITCH = 0.75       # ... at a pitch of at most this many shortest wavelengths
_PARABOLA_STEP = 0.02      # relative eps' step of the first parabola around the mode
_PARABOLAS = 4             # parabolas at most
_SEARCH_FTOL = 1e-6        # the search's position fits stop here (the finish's at 1e-8) ...
_SEARCH_STEPS = 12         # ... or after this many steps (a poor fit far from the mode)
_MIN_LINE_SHARE = 0.02     # a further line must explain this share of the data's energy
_MAX_LINES = 8             # lines fitted together at most
_SET_SWEEPS = 2            # rounds of refitting every line in turn at each eps'


def search_subset(h: Hologram) -> Hologram:
    """The search's part of the data: at most 11 frequencies (denser towards the band's
    ends, the first two and the last two kept) and every few elements (at most about
    600, at a pitch of at most 0.75 of the shortest wavelength), so the band, the
    smallest frequency step and the aperture, hence the delay, its alias and the wave
    front's curvature that fix eps', are the data's.

    Examples
    --------
    >>> import holoradar as hr
    >>> x = np.arange(41) * 0.01
    >>> h = hr.Hologram(np.ones((21, 41, 41)), x, x, np.linspace(9e9, 11e9, 21))
    >>> s = search_subset(h)
    >>> s.data.shape, float(s.frequencies[-1]), float(s.x[-1])
    ((9, 21, 21), 11000000000.0, 0.4)
    >>> np.round(np.diff(s.frequencies) / 1e8).astype(int).tolist()
    [1, 2, 3, 4, 4, 3, 2, 1]
    """
    f = h.frequencies
    fi = np.arange(f.size)
    if f.size > _SEARCH_FREQUENCIES:
        # Denser towards the band's ends (1 - cos), the two end steps kept: the band (the
        # delay's resolution) and the smallest step (its alias, c/(2 df)) are the data's.
        j = np.arange(_SEARCH_FREQUENCIES - 2)
        inner = np.rint((f.size - 1) * (1 - np.cos(np.pi * j / j[-1])) / 2).astype(int)
        fi = np.unique(np.r_[inner, 1, f.size - 2])
    pitch = float(max(h.pitch)) if h.x.size > 1 and h.y.size > 1 else np.inf
    lam = C0 / float(f.max())
    stride = 1
    while (h.x.size / (stride + 1)) * (h.y.size / (stride + 1)) >= 0.25 * _SEARCH_ELEMENTS \
            and h.x.size * h.y.size / stride**2 > _SEARCH_ELEMENTS \
            and (stride + 1) * pitch <= _SEARCH_PITCH * lam:
        stride += 1
    data = h.data if h.is_wideband else h.data[None]
    sub = data[fi][:, ::stride, ::stride]
    freq = f[fi] if h.is_wideband else h.frequency
    return h.replace(data=sub if h.is_wideband else sub[0], x=h.x[::stride],
                     y=h.y[::stride], frequency=freq)


class FirstSearch(Search):
    """The search on part of the data. Its object is located in a source-free image, each
    frequency imaged on its own and their intensities summed: :meth:`Search.locate`
    takes only the brightest column and the line's shape from the image (the ranges
    come from the model), and a coherent image of a dipole-lit hologram needs the
    dipole's field on every plane at every frequency (a Sommerfeld integral each,
    tens of seconds) where this one needs none. A plane wave's coherent image costs no
    more, and is focused in range too: it is used."""

    def __init__(self, *args: Any, **kw: Any) -> None:
        super().__init__(*args, **kw)
        self.ftol, self.max_nfev = _SEARCH_FTOL, _SEARCH_STEPS

    def _image(self, zs: np.ndarray, medium: Any) -> Any:
        h = self.hologram
        with warnings.catch_warnings():  # only the brightest voxel is wanted here
            warnings.simplefilter("ignore", AliasingWarning)
            if isinstance(h.source, PlaneWave) and self.pr.coherent:
                # A plane wave's field on a plane is closed-form: the coherent image,
                # focused in range too, costs no more.
                return migrate(h, zs, medium=medium, combine="coherent", progress=False)
            h = h.replace(source=None, polarization=None)
            return migrate(h, zs, medium=medium, combine="incoherent", progress=False)


class WarmSearch(Search):
    """A :class:`~.search.Search` whose every trial starts from the nearest eps' already
    fitted (its own, or the ``first`` search's on part of the data), the range moved
    along the same delay (several frequencies) or the same paraxial curvature (one):
    no range scans. The located object (``A``, ``P``, depths, the trials' count) is the
    first search's.

    Parameters
    ----------
    pr, make, lo, hi, hologram, bar
        As :class:`~.search.Search`.
    first : Search
        The search whose fits start this one's.
    """

    def __init__(self, pr: Any, make: Any, lo: float, hi: float, hologram: Hologram,
                 bar: Any, first: Search) -> None:
        super().__init__(pr, make, lo, hi, hologram, bar)
        self.A, self.P, self.depths, self.z0 = first.A, first.P, first.depths, first.z0
        self.xy = first.xy
        # Positions looked at: the first search's image, on this grid.
        ratio = hologram.data[..., :, :].shape[-1] * hologram.data.shape[-2] / (
            first.hologram.data.shape[-1] * first.hologram.data.shape[-2])
        self.trials = round(first.trials * ratio)
        self.starts = {e: (b[1], b[2]) for e, b in first.best.items()}
        self.scan_length = False    # the first search's length is the start

    def _start(self, eps: float, floor: float, lam_m: float) -> tuple[np.ndarray, float]:
        own = {e: (b[1], b[2]) for e, b in self.best.items()}
        pool = own or self.starts
        below = [e for e in own if e < eps]
        above = [e for e in own if e > eps]
        if below and above:
            # Between two of its own fits: their ranges (moved along the same delay) and
            # positions interpolated in log eps'.
            a, b = max(below), min(above)
            w = np.log(eps / a) / np.log(b / a)
            z = (1 - w) * self._moved(own[a][0], a, eps) + w * self._moved(own[b][0], b, eps)
            xy = (1 - w) * np.asarray(own[a][1], float) + w * np.asarray(own[b][1], float)
        else:
            near = min(pool, key=lambda e: abs(np.log(e / eps)))
            z, xy = self._moved(pool[near][0], near, eps), np.array(pool[near][1], float)
        if self.best:   # the line's shape: fitted at the first trial, then held
            top = max(self.best, key=lambda e: self.best[e][0])
            xy[2:] = self.best[top][2][2:]
        # The best of the carrier's fringes (half a wavelength apart in range) nearby.
        z, _ = self.pr.scan(eps, max(z - lam_m / 4, floor), max(z + lam_m / 4, floor + lam_m),
                            xy)
        return xy, z


    def _moved(self, z: float, e_from: float, e_to: float) -> float:
        """The range at ``e_to`` of the same delay (or paraxial curvature) as ``z`` at
        ``e_from``."""
        if e_from == e_to:
            return z
        if not self.wideband:
            return self.paraxial_range(e_to) + z - self.paraxial_range(e_from)
        m_to = self.make(e_to)
        path = self.make(e_from).optical_path(z).real
        top = self.z0 + (path - self.z0) * 2 + 1e-3
        if m_to.optical_path(top).real < path:
            return z
        return float(_opt.brentq(lambda zz: m_to.optical_path(zz).real - path, self.z0, top))


def line_steps(run: Any, depth_range: Any, position: Any, stages: Any) -> list[float]:
    """Steps 1-3 for a line (the module notes); leaves ``run.search`` the search on all
    the data with the exact-corrected model, and returns the modes of eps'.

    ``run`` is the autofocus's run (:class:`.steps.Run`); ``stages`` the point search's
    steps it reuses (``COARSE``, ``locate``, ``detect``, ``sweep``, ``refine``,
    ``seeds``), handed over by :func:`.steps.estimate` (this module does not import it).
    """
    COARSE = stages.COARSE
    _detect, _locate, _refine = stages.detect, stages.locate, stages.refine
    _seeds, _sweep = stages.seeds, stages.sweep

    exact = run.search.pr
    full = run.search.hologram
    if not isinstance(exact, LineResponse):
        raise TypeError("line_steps needs the exact line model (LineResponse)")
    grid = np.geomspace(run.lo, run.hi, COARSE)
    mid = float(grid[len(grid) // 2])
    try:
        ray_source(full.source)
    except ValueError:                 # no asymptotic model of this source: the exact one
        _locate(run, depth_range, position)
        _detect(run, mid)
        _sweep(run.search, grid, mid, "line")
        return _refine(run.search, _seeds(run.search, grid, run.lo, run.hi), run.lo, run.hi)
    # 1-3 on part of the data with the asymptotic model: locate, detect (the first fit:
    # the line's shape, its length scanned), one sweep with that shape held, every mode's
    # centre, the best refined by parabolas and the shape fitted again there.
    sub = search_subset(full)
    kw = dict(coherent=exact.coherent, radius=exact.radius, eps_line=exact.eps_line,
              phase_only=exact.phase_only)
    first = FirstSearch(LineRayResponse(sub, run.make, **kw), run.make, run.lo, run.hi, sub,
                        run.search.bar)
    run_first = dataclasses.replace(run, search=first)
    _locate(run_first, depth_range, position)
    _detect(run_first, mid)
    for e in sorted(grid, key=lambda e: abs(np.log(e / mid))):
        first.evaluate(float(e))
    modes = [c for _, c, _ in _seeds(first, grid, run.lo, run.hi)]
    for e in modes:
        first.evaluate(e)
    e_s = _parabolas(first, max(first.best, key=lambda e: first.best[e][0]), 0.05)
    # Only a mode whose residual is within twice the best's could rival it (the
    # interval's drop is about the residual's share): the others are not refitted.
    F_s = first.best[e_s][0]
    modes = [e for e in modes if 1 - first.best[e][0] <= 2 * (1 - F_s)]
    _, z_s, xy_s = first.evaluate(e_s, refine_shape=True)
    # Further lines (a mat's other bars) while each explains a share of the data.
    lines, together = _peel(first, e_s, [(z_s, np.asarray(xy_s, float))], depth_range, kw)
    if together is not None:
        # Several lines: their joint best eps' on this part of the data first, and the
        # modes that could rival it jointly.
        e_s = _parabolas(together, e_s, 0.05)
        lines = list(together.pr.held[e_s])
        F_s = together.best[e_s][0]
        modes = [e for e in modes if 1 - together.evaluate(e)[0] <= 2 * (1 - F_s)]
    # The exact model at each line's fit corrects the asymptotic one on all the data; on
    # all the data (one line: its shape fitted again) every mode is refitted and the best
    # refined.
    models = [LineRayResponse(full, run.make, **kw) for _ in lines]
    for m, (z, xy) in zip(models, lines, strict=True):
        m.correct_to(exact, e_s, z, xy)
    if len(lines) == 1:
        model: Any = models[0]
        second: Search = WarmSearch(model, run.make, run.lo, run.hi, full, run.search.bar,
                                    first)
    else:
        model = LineSetResponse(full, models, coherent=exact.coherent,
                                phase_only=exact.phase_only)
        model.held[e_s] = list(lines)
        second = SetSearch(model, run.make, run.lo, run.hi, full, run.search.bar, first)
    model.responses += first.pr.responses
    model.integrals = sum(m.integrals for m in models)
    second.evaluate(e_s)
    for e in modes:
        second.evaluate(e)
    e_hat = _parabolas(second, e_s, _PARABOLA_STEP)
    _bracket_interval(second, e_hat, run.confidence)
    run.search = second
    return sorted({*modes, e_hat})


def _peel(first: Search, e_s: float, lines: list[tuple[float, np.ndarray]], depth_range: Any,
          kw: dict[str, Any]) -> tuple[list[tuple[float, np.ndarray]], SetSearch | None]:
    """More lines at ``e_s`` on the first search's data: each located and fitted in what
    the lines so far leave (:class:`FirstSearch` on the residual), kept while it explains
    at least ``_MIN_LINE_SHARE`` of the data's energy, then every line refitted
    together (:class:`SetSearch`); at most ``_MAX_LINES``. Returns the lines and, when
    there are several, their joint search on that data."""
    h = first.hologram
    joint = LineSetResponse(h, [first.pr], coherent=first.pr.coherent,
                            phase_only=first.pr.phase_only)
    joint.held[e_s] = list(lines)
    together = SetSearch(joint, first.make, first.lo, first.hi, h, None, first)
    together.ftol, together.max_nfev = first.ftol, first.max_nfev
    while len(lines) < _MAX_LINES:
        joint.active = 0
        r, _, _ = joint.residual(e_s, *lines[0])
        share = float(np.vdot(r, r).real) / joint.energy
        if share < 2 * _MIN_LINE_SHARE:
            break
        rest = h.with_data(r.reshape(h.data.shape))
        more = FirstSearch(LineRayResponse(rest, first.make, **kw), first.make, first.lo,
                           first.hi, rest)
        if more.locate(depth_range, None, first.z0) is None:
            break
        F, z, xy = more.evaluate(e_s)
        first.pr.responses += more.pr.responses
        if F * share < _MIN_LINE_SHARE:
            break
        joint.models.append(first.pr)
        joint.held[e_s] = [*lines, (z, np.asarray(xy, float))]
        together.fit_lines(e_s)
        lines = list(joint.held[e_s])
    return lines, (together if len(lines) > 1 else None)


class SetSearch(WarmSearch):
    """The search of several lines together (:class:`LineSetResponse`): at each eps' every
    line's position and range refitted in turn, the others held, ``_SET_SWEEPS`` times;
    each line starts from its own fits at the nearest eps' (interpolated between two,
    moved along the same delay), the best fringe of a short range scan. The shapes are
    held. ``best`` holds the first line's fit and the focus fraction of all of them."""

    def evaluate(self, eps: float, refine_shape: bool = False) -> tuple[float, float, Any]:
        eps = float(eps)
        if eps in self.best:
            return self.best[eps]
        if self.bar is not None:
            if self.bar.n + 1 >= self.bar.total:
                make_room(self.bar, 4)
            self.bar.update()
        self.fit_lines(eps)
        pr = self.pr
        pr.active = 0
        z, xy = pr.held[eps][0]
        self.best[eps] = (pr.focus(eps, z, xy), z, xy)
        return self.best[eps]

    def fit_lines(self, eps: float) -> None:
        """Every line's (x, y, range) at ``eps``, in turn, into ``pr.held[eps]``."""
        pr = self.pr
        floor = self.z0 + pr.spacing(eps) / 4
        lam_m = self.lam / np.sqrt(eps)
        sweeps = _SET_SWEEPS
        if eps not in pr.held:
            between = min(pr.held) < eps < max(pr.held)
            pr.held[eps] = [self._moved_line(k, eps) for k in range(len(pr.models))]
            # Interpolated between two fits: close, one round and no range scan.
            sweeps = 1 if between else _SET_SWEEPS
            for k in range(0 if between else len(pr.models)):
                pr.active = k
                z, xy = pr.held[eps][k]
                z, _ = pr.scan(eps, max(z - lam_m / 4, floor),
                               max(z + lam_m / 4, floor + lam_m), xy)
                pr.held[eps][k] = (z, xy)
        for _ in range(sweeps):
            for k in range(len(pr.models)):
                pr.active = k
                z, xy = pr.held[eps][k]
                shape = np.asarray(xy[2:], float)

                def resid(p: np.ndarray, shape: np.ndarray = shape) -> np.ndarray:
                    r, _, _ = pr.residual(eps, max(p[2], floor), np.r_[p[:2], shape])
                    return np.concatenate([r.real.ravel(), r.imag.ravel()])

                p0 = np.array([xy[0], xy[1], z])
                lo_b, hi_b = self._box(p0, eps, floor, lam_m)
                p = _least_squares(resid, p0, lo_b, hi_b, np.full(3, self.lam / 10),
                                   self.ftol, self.max_nfev)
                pr.held[eps][k] = (max(float(p[2]), floor),
                                   np.r_[np.clip(p[:2], *pr.bounds), shape])
        pr.active = 0

    def _moved_line(self, k: int, eps: float) -> tuple[float, np.ndarray]:
        """Line ``k``'s start at ``eps`` from its fits at the eps' held."""
        held = self.pr.held
        below = [e for e in held if e < eps]
        above = [e for e in held if e > eps]
        if below and above:
            a, b = max(below), min(above)
            w = np.log(eps / a) / np.log(b / a)
            za, xa = held[a][k]
            zb, xb = held[b][k]
            return ((1 - w) * self._moved(za, a, eps) + w * self._moved(zb, b, eps),
                    (1 - w) * np.asarray(xa, float) + w * np.asarray(xb, float))
        near = min(held, key=lambda e: abs(np.log(e / eps)))
        z, xy = held[near][k]
        return self._moved(z, near, eps), np.array(xy, float)


def _parabolas(search: Search, e0: float, step: float) -> float:
    """The maximum of the focus over eps' near ``e0`` by successive parabolas through
    the three best trials (in log eps') within 20% of it, the first two a relative
    ``step`` either side; each move at most 5% beyond the trials."""
    for e in (e0, e0 / (1 + step), e0 * (1 + step)):
        search.evaluate(float(np.clip(e, search.lo, search.hi)))
    for _ in range(_PARABOLAS):
        near = [e for e in search.best if abs(np.log(e / e0)) < 0.2]
        top3 = sorted(sorted(near, key=lambda e: -search.best[e][0])[:3])
        if len(top3) < 3:
            break
        x = np.log(top3)
        y = np.array([search.best[e][0] for e in top3])
        c2, c1, _ = np.polyfit(x - x[1], y, 2)
        if c2 >= 0:
            break
        e_new = float(np.exp(np.clip(x[1] - c1 / (2 * c2), x[0] - 0.05, x[2] + 0.05)))
        e_new = float(np.clip(e_new, search.lo, search.hi))
        if min(abs(np.log(e_new / e)) for e in search.best) < 1e-3:
            break
        search.evaluate(e_new)
    return max(search.best, key=lambda e: search.best[e][0])


def _bracket_interval(search: Search, e_hat: float, confidence: float) -> None:
    """Trials either side of ``e_hat`` just inside and just beyond where the parabola
    through the three best trials meets the interval's level (:mod:`.interval`): the
    interval's root finding then starts from a tight bracket on each side instead of
    the eps' range's edges."""
    top3 = sorted(sorted(search.best, key=lambda e: -search.best[e][0])[:3])
    if len(top3) < 3:
        return
    x = np.log(top3)
    c2 = np.polyfit(x - x[1], [search.best[e][0] for e in top3], 2)[0]
    _, z, xy = search.best[e_hat]
    if c2 >= 0:
        return
    drop = focus_drop(fit_statistics(search, e_hat, z, xy), quantile(confidence),
                      search.pr.energy)
    w = float(np.sqrt(drop / -c2))
    for side in (-1, 1):
        for f in (0.9, 1.15):
            search.evaluate(float(np.clip(e_hat * np.exp(side * f * w), search.lo, search.hi)))
