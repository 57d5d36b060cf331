"""The course of :func:`~holoradar.autofocus`'s search, step by step.

Locate the object (laterally from a migrated image, its range from the point fit),
test it against noise at a middle eps', sweep eps' coarsely, refine every local
maximum (and, across frequencies, every eps' where curvature and an alias of the
delay agree), then at the best one the noise statistics, the interval, the check
for rivals and the Cramér-Rao bound. A step that finds the scene gives no handle on
eps' raises :class:`NoHandleError` with the reason; :meth:`Run.finish` makes the result
either way (falling back on the glare's estimate where there is one).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._lazy import lazy_module
from ...data.hologram import C0
from ...physics.medium import Medium
from .crb import crb_note, eps_bound
from .fit_statistics import fit_statistics, no_object_reason
from .glare_estimate import combine, glare_alone
from .interval import crossing, focus_drop, quantile
from .progress import finish_bar, make_room
from .result import AutofocusResult
from .search import Search

_opt = lazy_module("scipy.optimize")

__all__ = ["COARSE", "NoHandleError", "Run", "estimate"]

COARSE = 10          # eps' values of the first sweep (geometric)


class NoHandleError(Exception):
    """A step found that the scene gives no handle on eps': the result's fields say why."""

    def __init__(self, reason: str, **fields: Any) -> None:
        super().__init__(reason)
        self.fields = dict(eps=None, eps_interval=None, determinable=False, reason=reason,
                           **fields)


@dataclass
class Run:
    """One call's search and what every step and its result need."""

    search: Search
    make: Callable[[float], Medium]
    lo: float
    hi: float
    z0: float                                # the ground surface's range, metres
    confidence: float
    glare: tuple[float, float] | None        # the glare's eps' and 1-sigma
    t_start: float
    base: dict[str, Any]                     # the result's fields known from the start

    def finish(self, **kw: Any) -> AutofocusResult:
        """The result from the step's ``kw``: with the trials made, the work done and the
        time taken; the glare's estimate alone when the focus gave no handle."""
        search, bar = self.search, self.search.bar
        grid = np.array(sorted(search.best))
        prof = np.array([search.best[e][0] for e in grid])
        kw = {**self.base, **kw}
        if not kw.get("determinable", True) and self.glare is not None:
            kw.update(glare_alone(self.glare, self.confidence, self.make, kw["reason"]))
        finish_bar(bar)   # the total never shrinks; the steps not needed count as done
        return AutofocusResult(eps_grid=grid, profile=prof, evaluations=search.pr.responses,
                               integrals=search.pr.integrals,
                               seconds=time.perf_counter() - self.t_start, **kw)


def estimate(run: Run, depth_range: Any, position: Any, target: Any) -> dict[str, Any]:
    """The steps, each raising ``NoHandleError`` where the scene gives no handle on eps';
    the result's fields when it does."""
    search = run.search
    if target == "line":
        # 1-3 for a line: a fast model on part of the data, then the exact one on all of
        # it (line_search.py); run.search becomes the search on all the data.
        from types import SimpleNamespace

        from .line_search import line_steps

        stages = SimpleNamespace(COARSE=COARSE, locate=_locate, detect=_detect,
                                 sweep=_sweep, refine=_refine, seeds=_seeds)
        modes = line_steps(run, depth_range, position, stages)
        search = run.search
    else:
        # 1. Where is the object? Laterally the brightest column of a migrated image; its
        #    range, curvature and delay from the point fit along that column.
        _locate(run, depth_range, position)
        # 2. Is there an object at all? Fit one at a middle eps' and test it against noise.
        grid = np.geomspace(run.lo, run.hi, COARSE)
        mid = float(grid[len(grid) // 2])
        _detect(run, mid)
        # 3. Coarse sweep of eps' outwards from there, each with its best range and
        #    position; every local maximum refined.
        _sweep(search, grid, mid, target)
        modes = _refine(search, _seeds(search, grid, run.lo, run.hi), run.lo, run.hi)
    # 4. Noise level, detection and the sandwich factor at the optimum.
    e_hat, F_max, stats, common = _optimum(run)
    # 5. Profile-likelihood interval, R(eps) - R_min <= (q s sqrt(phi) + sqrt(E_err))^2, in
    #    focus-fraction units.
    q = quantile(run.confidence)
    level = F_max - focus_drop(stats, q, search.pr.energy)
    ends = [_interval_end(run, e_hat, level, side, common) for side in (-1, 1)]
    interval = (ends[0], ends[1])
    _check_rivals(search, e_hat, interval, level, modes, common)
    r_int = tuple(sorted((search.best[ends[0]][1], search.best[ends[1]][1])))
    # 7. The Cramér-Rao bound at the estimate, and why the interval exceeds it.
    _, z_hat, xy_hat = search.best[e_hat]
    bound = eps_bound(search, e_hat, z_hat, xy_hat, stats)
    est, est_int = e_hat, interval
    reason = "from the focus"
    if run.glare is not None:
        est, est_int, reason = combine(e_hat, interval, run.glare, q)
    return dict(eps=float(est), eps_interval=est_int, determinable=True, reason=reason,
                range_interval=(float(r_int[0]), float(r_int[1])), eps_focus=e_hat,
                eps_focus_interval=interval, medium=run.make(float(est)), eps_crb=bound.std,
                crb_note=crb_note(bound, interval, q, stats, F_max), **common)


def _locate(run: Run, depth_range: Any, position: Any) -> None:
    """Step 1: the object's lateral position and range (``Search.locate``)."""
    located = run.search.locate(depth_range, position, run.z0)
    run.search.bar.update()
    if located is None:
        raise NoHandleError("the brightest focus lies at the ground surface or above it, not "
                            "in the ground")


def _detect(run: Run, mid: float) -> None:
    """Step 2: the object fitted at eps' = ``mid``, tested against noise alone."""
    _, z_mid, xy_mid = run.search.evaluate(mid)
    pre = fit_statistics(run.search, mid, z_mid, xy_mid)
    if pre["detection"] < pre["threshold"]:
        raise NoHandleError(no_object_reason(pre),
                            position=(float(xy_mid[0]), float(xy_mid[1]), float(z_mid)),
                            detection=pre["detection"], detection_threshold=pre["threshold"])


def _sweep(search: Search, grid: np.ndarray, mid: float, target: Any) -> None:
    """Step 3a: every eps' of ``grid``, outwards from ``mid`` (a continuous path)."""
    order = sorted(grid, key=lambda e: abs(np.log(e / mid)))
    for e in order:
        search.evaluate(float(e))
    if target == "line":
        # The line's azimuth and length again at the sweep's best eps', then the sweep
        # once more with that shape held: every eps' compared with one shape.
        e_best = max(search.best, key=lambda e: search.best[e][0])
        search.evaluate(e_best, refine_shape=True)
        search.best = {e_best: search.best[e_best]}
        for e in order:
            search.evaluate(float(e))


def _seeds(search: Search, grid: np.ndarray, lo: float,
           hi: float) -> list[tuple[float, float, float]]:
    """Step 3b: brackets (a, c, b) to refine: the sweep's local maxima and (several
    frequencies) every eps' where curvature and an alias of the delay agree."""
    F_grid = [search.best[float(e)][0] for e in grid]
    seeds = [(float(grid[j - 1]) if j else lo, float(grid[j]),
              float(grid[j + 1]) if j < len(grid) - 1 else hi)
             for j in range(len(grid)) if (j == 0 or F_grid[j] >= F_grid[j - 1])
             and (j == len(grid) - 1 or F_grid[j] >= F_grid[j + 1])]
    seeds += [(max(lo, c / 1.03), c, min(hi, c * 1.03)) for c in search.candidates()]
    return seeds


def _refine(search: Search, seeds: list[tuple[float, float, float]], lo: float,
            hi: float) -> list[float]:
    """Step 3c: each seed that could rival the best refined to its maximum; the modes
    (refined or not), checked for rivals once the interval is known."""
    bar = search.bar
    # Now the work left is known better: about 8 trials a refined seed, 7 for the interval.
    make_room(bar, 8 * len(seeds) + 7)
    modes = []
    for a, c, b in seeds:
        F_c = search.evaluate(c)[0]
        best_so_far = max(f for f, _, _ in search.best.values())
        # Refine only what could rival the best: a residual within twice the best's.
        if c in (lo, hi) or not a < c < b or 1 - F_c > 2 * (1 - best_so_far):
            modes.append(c)
            continue
        _opt.minimize_scalar(lambda le: -search.evaluate(float(np.exp(le)))[0],
                             bounds=(np.log(a), np.log(b)), method="bounded",
                             options={"xatol": 1e-3})
        modes.append(max((e for e in search.best if a <= e <= b),
                         key=lambda e: search.best[e][0]))
    return modes


def _optimum(run: Run) -> tuple[float, float, dict[str, float], dict[str, Any]]:
    """Step 4: the best eps', its focus fraction, the noise statistics there and the
    result's fields they give; tested against noise and the edges of the eps' range."""
    search, lo, hi = run.search, run.lo, run.hi
    e_hat = max(search.best, key=lambda e: search.best[e][0])
    F_max, z_hat, xy_hat = search.best[e_hat]
    stats = fit_statistics(search, e_hat, z_hat, xy_hat)
    pos = (float(xy_hat[0]), float(xy_hat[1]), float(z_hat))
    line = {} if len(xy_hat) < 4 else dict(
        line_azimuth_deg=float(np.degrees(xy_hat[2]) % 180.0), line_length=float(xy_hat[3]))
    if len(xy_hat) == 3:   # a sphere's fitted radius
        line = dict(sphere_radius=float(xy_hat[2]))
    common = dict(position=pos, depth=float(z_hat - run.z0), focus_fraction=F_max, **line,
                  detection=stats["detection"], detection_threshold=stats["threshold"],
                  noise_inflation=stats["phi"])
    if stats["detection"] < stats["threshold"]:
        raise NoHandleError(no_object_reason(stats), **common)
    if e_hat <= lo * (1 + 1e-9) or e_hat >= hi * (1 - 1e-9):
        raise NoHandleError(f"the sharpest focus lies at the edge of eps_range ({lo:g} .. "
                            f"{hi:g}): widen it, or the scene gives no handle", **common)
    return e_hat, F_max, stats, common


def _interval_end(run: Run, e_hat: float, level: float, side: int,
                  common: dict[str, Any]) -> float:
    """Step 5: the interval's end on ``side`` of ``e_hat``, where the focus falls to
    ``level``; no handle when the edge of the eps' range is reached first."""
    end = crossing(run.search, e_hat, level, side)
    if end is None:
        raise NoHandleError(f"the focus hardly changes with eps': its "
                            f"{100 * run.confidence:.0f}% interval reaches the edge of "
                            f"eps_range ({run.lo:g} .. {run.hi:g}) (object too shallow, or too "
                            "small an aperture for one frequency)", **common)
    return end


def _check_rivals(search: Search, e_hat: float, interval: tuple[float, float], level: float,
                  modes: list[float], common: dict[str, Any]) -> None:
    """Step 6: no other mode outside the interval focuses as well (within ``level``);
    across frequencies, such a rival is an alias of the delay."""
    rivals = sorted({round(e, 3) for e in modes if not interval[0] <= e <= interval[1]
                     and search.best[e][0] >= level})
    if not rivals:
        return
    note = ""
    if search.wideband:
        df = float(np.min(np.diff(search.hologram.frequencies)))
        note = (f"; the frequency step {df / 1e6:.0f} MHz leaves the delay ambiguous by "
                f"c/(2 df) = {100 * C0 / (2 * df):.1f} cm of optical path: use finer steps")
    raise NoHandleError(f"ambiguous: eps' = {e_hat:.3g} and "
                        f"{', '.join(f'{e:.3g}' for e in rivals)} focus equally well{note}",
                        **common)
