"""The two inversions: damped least squares stopped at the noise, and L1-sparse.

Least squares (``"lsqr"``): PyLops's LSQR on ``min |A r - d|^2 + damp^2 |r|^2``, the
maximum a posteriori reflectivity for receiver noise of standard deviation ``sigma``
per sample and a white prior of variance ``s^2`` per voxel, ``damp = sigma / s``;
``s^2`` is what the data's energy above the noise, ``|d|^2 - M sigma^2``, asks of the
columns' energy ``sum_j c_j^2``. It stops at the discrepancy principle: once the
residual ``|A r - d|`` has fallen to the noise's norm ``sigma sqrt(M)`` (going on
fits the noise); else after ``max_iter`` steps.

Sparse (``"sparse"``): PyLops's FISTA on ``min |B u - d|^2 / 2 + eps |u|_1`` with the
columns normalised, ``B = A diag(1/c)``, ``u = c r``: then every voxel's correlation
with pure noise, ``B^H n``, has the same spread ``sigma``, and its largest magnitude
over ``N`` voxels stays below ``sigma sqrt(log N + log(1/p))`` with probability
``1 - p`` (each ``|B^H n|^2 / sigma^2`` is exponential): ``eps`` takes ``p = 1 %``, so
noise alone leaves no voxel. Neighbouring voxels of a grid finer than the resolution
have nearly parallel columns, so FISTA needs hundreds of steps (two points 0.6 of the
Rayleigh spacing apart: about a thousand); after a thousand a single point on a
grid of half its cell is still spread over its cell (its sum and centroid right).
Lowering the threshold from high to ``eps`` (continuation) gathers a single point
into a voxel but lets the first voxel chosen fall between two close points, so it
is not used. The L1 penalty shrinks what it keeps by
``eps``; one scale for the whole solution, the least-squares fit of its data to the
data, undoes that on average (a refit of every kept voxel apart was tried: along a
single frequency's line of sight the kept voxels' columns are nearly parallel, and
the refit threw values to the grid's corners). Stops when a step changes the model by
less than ``TOL`` of the first step, or after ``max_iter`` steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Solution", "least_squares", "noise_threshold", "sparse"]

FALSE_ALARM = 0.01   # the chance that noise alone leaves a voxel in the sparse solution
TOL = 1e-5           # the sparse solver stops once a step changes the model by less than
#                      this fraction of its first step


@dataclass(frozen=True)
class Solution:
    """A reflectivity and how it was reached."""

    r: np.ndarray
    iterations: int
    residual: float       # |A r - d|
    noise_norm: float     # sigma sqrt(M)
    stop: str
    extra: dict
    warm: Any = None      # what a rerun with another noise keeps (sparse: its step)


def _bar(progress: Any, total: int, desc: str) -> Any:
    """A bar over the solver's steps, shown once the work has lasted a second: with
    ``progress=None`` on a terminal only (in a pipe or a log a bar is lines of noise),
    never with ``progress=False``."""
    import sys

    from tqdm.auto import tqdm  # here, not at import: holoradar._lazy

    hidden = progress is False or (progress is None and not sys.stderr.isatty())
    return tqdm(total=total, desc=desc, unit="step", disable=hidden, delay=1.0)


def least_squares(A: Any, d: np.ndarray, sigma: float, c: np.ndarray, max_iter: int,
                  progress: Any = None) -> Solution:
    """Damped LSQR stopped at the discrepancy (module docstring)."""
    from pylops.optimization.cls_basic import LSQR

    M = d.size
    target = sigma * math.sqrt(M)
    signal = max(float(np.vdot(d, d).real) - M * sigma**2, 0.0)
    s2 = signal / float(np.sum(c**2))
    damp = sigma / math.sqrt(s2) if s2 > 0 else 0.0
    solver = LSQR(A)
    # atol 0, btol at the noise: LSQR's own test |r| <= btol |d| is the discrepancy.
    btol = min(target / max(float(np.linalg.norm(d)), 1e-300), 1.0)
    x = solver.setup(d, damp=damp, atol=0.0, btol=btol, conlim=1e12, niter=max_iter,
                     calc_var=False)
    bar = _bar(progress, max_iter, "invert (lsqr)")
    try:
        while solver.iiter < max_iter and solver.istop == 0 and solver.r1norm > target:
            x = solver.step(x, False)
            bar.update(1)
            bar.set_postfix_str(f"residual/noise {solver.r1norm / target:.3f}")
    finally:
        bar.close()
    residual = float(np.linalg.norm(A @ x - d))
    stop = ("the residual reached the noise (discrepancy principle)" if residual <= target
            * (1 + 1e-6) else f"max_iter ({max_iter}) steps" if solver.iiter >= max_iter
            else f"LSQR: {solver.msg[solver.istop]}")
    return Solution(x, int(solver.iiter), residual, target, stop, {"damp": damp})


def sparse(A: Any, d: np.ndarray, sigma: float, c: np.ndarray, max_iter: int,
           progress: Any = None, false_alarm: float = FALSE_ALARM,
           warm: Any = None) -> Solution:
    """Column-normalised FISTA with the noise's threshold, then the kept voxels'
    least-squares refit (module docstring). ``warm``: a previous solution's
    ``Solution.warm`` on the same operator (its step size kept; a model to start from,
    if it carries one: a start from a solution at another threshold changes where 300
    steps end, so the rerun in ``detect`` starts from zero)."""
    import pylops

    from .fista import OnePairFISTA

    N, M = A.shape[1], d.size
    cf = c.ravel()
    B = pylops.aslinearoperator(A) * pylops.Diagonal((1.0 / cf).astype(A.dtype))
    eps = noise_threshold(sigma, N, false_alarm)
    # The step 1/L, L the largest eigenvalue of B^H B (power iterations).
    L, first, u0 = warm if warm is not None else (_largest_eigenvalue(B, progress), None, None)
    if first is None:
        first = float(np.abs(B.rmatvec(d)).max()) / L   # the size of the first step
    # PyLops's FISTA soft-thresholds at eps * alpha / 2 (its objective is
    # |d - B u|^2 + eps |u|_1): 2 eps for a threshold of eps on ``B^H d``.
    solver = OnePairFISTA(B)
    u = solver.setup(d, x0=u0, niter=max_iter, eps=2 * eps, alpha=1.0 / L,
                     tol=TOL * first)
    z = u.copy()
    bar = _bar(progress, max_iter, "invert (sparse)")
    iters = 0
    try:
        while iters < max_iter:
            u, z, change = solver.step(u, z)
            iters += 1
            bar.update(1)
            if change < TOL * first:
                break
    finally:
        bar.close()
    support = np.abs(u) > 0
    r = (u / cf).astype(A.dtype)
    if support.any():   # one least-squares scale: the L1 shrinkage undone on average
        m = A @ r
        r = r * (np.vdot(m, d) / max(float(np.vdot(m, m).real), 1e-300))
    residual = float(np.linalg.norm(A @ r - d))
    stop = (f"a step changed the model by less than {TOL:g} of the first" if iters < max_iter
            else f"max_iter ({max_iter}) steps")
    return Solution(r, int(iters), residual, sigma * math.sqrt(M), stop,
                    {"threshold": eps, "voxels_kept": int(support.sum())}, (L, first, None))


def noise_threshold(sigma: float, n: int, false_alarm: float) -> float:
    """``sigma sqrt(log n + log(1/p))``: what the largest of ``n`` correlations with pure
    noise (each ``|.|^2 / sigma^2`` exponential) exceeds with probability ``p``.

    Examples
    --------
    >>> round(noise_threshold(1.0, 1000, 0.01), 3)
    3.393
    """
    return sigma * math.sqrt(math.log(n) + math.log(1 / false_alarm))


def _largest_eigenvalue(B: Any, progress: Any, steps: int = 30) -> float:
    rng = np.random.default_rng(0)
    v = rng.standard_normal(B.shape[1]) + 1j * rng.standard_normal(B.shape[1])
    v = v / np.linalg.norm(v)
    lam = 0.0
    # Seconds on a large grid before the solver's own bar: said on a terminal too.
    bar = _bar(progress, steps, "invert (step size)")
    try:
        for _ in range(steps):
            w = B.rmatvec(B.matvec(v))
            new = float(np.linalg.norm(w))
            v = w / max(new, 1e-300)
            bar.update(1)
            if lam and abs(new - lam) < 1e-3 * new:
                lam = new
                break
            lam = new
    finally:
        bar.close()
    return 1.01 * lam   # a little above: FISTA's step must stay below 1/L
