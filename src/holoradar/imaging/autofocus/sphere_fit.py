"""A sphere's radius from the data, and when a point fit should become a sphere fit.

The point model fits a compact object; a conducting sphere whose size matters
(``k a`` of 1 or more in the ground) leaves a smooth residual it cannot explain,
at every eps' alike. :func:`radius_scan` finds the radius that explains the data
best at the point fit's eps' and position: the sphere's echo turns its phase by
``2 k_g a`` and its angular pattern with the radius, so the focus ripples with a
period of ``pi / k_g`` in ``a``; the scan steps ``pi / (8 k_g)`` (``k_g`` at the
highest frequency) from ``k_g a`` = 0.3 to 15, refits the centre at each, and
refines the best by a bounded scalar search between its neighbours.

:func:`worth_a_sphere` says when the default point fit turns to it: the point's
residual shows lack of fit (its smooth share, or the sandwich factor, above what
the Cramér-Rao note calls lack of fit), the data support the sphere model (a
vector hologram on an untilted grid, lit by a plane wave, a point source or a
dipole, or a transceiver) and the best sphere at least halves the point's
residual energy, a change far beyond what one more parameter buys from noise
(``chi^2_1`` at 1e-6 is 24 noise variances; the halving is asked on top).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..._lazy import lazy_module
from ...data.hologram import C0, Hologram
from ...physics.medium import Medium
from ..sphere_response import SphereResponse
from .crb import _LACK_PHI, _LACK_SHARE
from .fit_statistics import fit_statistics
from .search import Search, _least_squares
from .steps import NoHandleError, Run, estimate

_opt = lazy_module("scipy.optimize")

__all__ = ["radius_scan", "sphere_instead", "worth_a_sphere"]

_KA = (0.3, 15.0)     # the radii scanned, as k_g a at the highest frequency
_STEPS_PER_WRAP = 8   # scan steps per pi / k_g (the focus's ripple in a)
_GAIN = 0.5           # a sphere replaces the point where it leaves at most this share
_CHI2 = 24.0          # and gains this many noise variances at least (chi^2_1, 1e-6)


def sphere_model(hologram: Hologram, make: Callable[[float], Medium], coherent: bool,
                 phase_only: bool, radius: float) -> SphereResponse | None:
    """The sphere's response for these data, or None where the model does not apply."""
    try:
        return SphereResponse(hologram, make, coherent=coherent, phase_only=phase_only,
                              radius=radius)
    except ValueError:
        return None


def radius_scan(pr: SphereResponse, eps: float, z: float, xy: Any,
                lam: float) -> tuple[float, float, float, np.ndarray]:
    """The radius (metres) that focuses best at ``eps``, with its focus fraction, range
    and lateral position; ``pr.radius`` is left at it.

    Parameters
    ----------
    pr : SphereResponse
        The model (its radius is changed: the tables of the trial ground are shared).
    eps, z : float
        The trial eps' and the start of the centre's range, metres.
    xy : array_like
        The start of its lateral position, metres.
    lam : float
        The shortest free-space wavelength, metres.

    Returns
    -------
    radius, focus fraction, range, lateral position (x, y)
    """
    k_g = 2 * np.pi / lam * np.sqrt(eps)
    step = np.pi / (_STEPS_PER_WRAP * k_g)
    radii = np.arange(_KA[0] / k_g, _KA[1] / k_g + step / 2, step)
    floor = z - 0.5 * lam / np.sqrt(eps)

    def best_at(a: float, start: np.ndarray, deeper: float = 0.0) -> tuple[float, np.ndarray]:
        """The best centre for radius ``a``: the point fit's range marks the sphere's echo,
        which comes from its near side (the centre up to ``a`` deeper: ``deeper``)."""
        pr.radius = float(a)

        def resid(p: np.ndarray) -> np.ndarray:
            r, _, _ = pr.residual(eps, p[2], p[:2])
            return np.concatenate([r.real.ravel(), r.imag.ravel()])

        reach = lam / (4 * np.sqrt(eps))
        lo_b = np.array([start[0] - reach, start[1] - reach, max(start[2] - reach, floor)])
        hi_b = np.array([start[0] + reach, start[1] + reach, start[2] + deeper + reach])
        p0 = start + np.array([0.0, 0.0, deeper / 2])
        p = _least_squares(resid, np.clip(p0, lo_b + 1e-9, hi_b - 1e-9), lo_b, hi_b,
                           np.full(3, lam / 10), 1e-8, 40)
        return pr.focus(eps, p[2], p[:2]), p

    start = np.array([xy[0], xy[1], z], float)
    fits = [best_at(a, start, a) for a in radii]
    i = int(np.argmax([f for f, _ in fits]))
    lo_a = radii[max(i - 1, 0)]
    hi_a = radii[min(i + 1, radii.size - 1)]
    res = _opt.minimize_scalar(lambda a: -best_at(a, fits[i][1])[0], bounds=(lo_a, hi_a),
                               method="bounded", options={"xatol": step / 50})
    a = float(res.x) if -res.fun > fits[i][0] else float(radii[i])
    F, p = best_at(a, fits[i][1])
    return a, float(F), float(p[2]), p[:2]


def worth_a_sphere(search: Search, eps: float, z: float, xy: Any) -> dict[str, float] | None:
    """The point fit's statistics at (``eps``, ``z``, ``xy``) where it shows lack of fit
    (the residual's smooth share or the sandwich factor above the Cramér-Rao note's
    levels), else None."""
    xy = np.asarray(xy, float)
    stats = fit_statistics(search, eps, z, xy)
    r, _, _ = search.pr.residual(eps, z, xy)
    R = float(np.vdot(r, r).real)
    smooth = stats["model_error"] / R if R > 0 else 0.0
    return stats if smooth > _LACK_SHARE or stats["phi"] > _LACK_PHI else None


def sphere_gain(point_F: float, sphere_F: float, energy: float, s2: float) -> bool:
    """Whether the sphere's fit (focus fraction ``sphere_F``) replaces the point's: at
    most half the point's residual, and a gain of at least ``_CHI2`` noise variances
    (``s2`` per real component: 2 s2 per complex sample)."""
    left_p, left_s = energy * (1 - point_F), energy * (1 - sphere_F)
    return bool(left_s <= _GAIN * left_p and (left_p - left_s) >= _CHI2 * 2 * s2)


def shortest_wavelength(hologram: Hologram) -> float:
    """The free-space wavelength of the highest frequency, metres."""
    return C0 / float(np.max(hologram.frequencies))


def sphere_instead(run: Run, hologram: Hologram, coherent: bool, fit: str, depth_range: Any,
                   fields: dict[str, Any], eps: float, *,
                   forced: bool) -> tuple[Run, dict[str, Any]] | None:
    """The sphere's search after a point's: its radius scanned at the point's estimate
    (the ripple's every period: a fit alone stops on the nearest), then eps' searched
    with the radius refitted at every trial (the interval profiles it). ``forced``: the
    sphere was asked for (a radius to fit); else only where :func:`worth_a_sphere` and
    :func:`sphere_gain` say so. Returns the sphere's run and result fields, or None to
    keep the point's. ``eps``: the point's best eps' (its estimate, or the best of
    rivals it could not tell apart)."""
    e = float(eps)
    x, y, z = fields["position"]
    point = run.search
    lam = shortest_wavelength(hologram)
    pr = sphere_model(hologram, run.make, coherent, fit == "phase", lam / 10)
    stats = None if pr is None or forced else worth_a_sphere(point, e, z, (x, y))
    if pr is None or (not forced and stats is None):
        return None
    a, F_s, _, xy_s = radius_scan(pr, e, z, (x, y), lam)
    if stats is not None and not sphere_gain(float(fields["focus_fraction"]), F_s,
                                             point.pr.energy, stats["s2"]):
        return None
    pr.radius, pr.fit_radius = a, True
    search = Search(pr, run.make, run.lo, run.hi, hologram, point.bar)
    sphere_run = Run(search, run.make, run.lo, run.hi, run.z0, run.confidence, run.glare,
                     run.t_start, run.base)
    try:
        out = estimate(sphere_run, depth_range, tuple(xy_s), "sphere")
    except NoHandleError as stop:
        out = stop.fields
    pr.responses += point.pr.responses
    pr.integrals += point.pr.integrals
    if not forced:
        out["model_note"] = (
            f"fitted as a conducting sphere: the point model left "
            f"{1 - float(fields['focus_fraction']):.2g} of the energy unexplained, the "
            f"sphere {1 - float(out.get('focus_fraction') or F_s):.2g}")
    return sphere_run, out
