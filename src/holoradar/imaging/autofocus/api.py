"""The public :func:`autofocus`: its arguments checked, the model chosen, the search run.

The search's course is in :mod:`.steps`; here the call's set-up: the checks (in
the order they have always been made, so the first fault is the one named), the
glare's estimate, the model (a point's or a line's response), the progress bar and
the BLAS held to one thread.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from typing import Any, Literal

import numpy as np

from ...data.hologram import Hologram
from ...physics.medium import Medium
from ..point_response import PointResponse
from .checks import (
    check_confidence,
    check_fit,
    check_hologram,
    check_line_radius,
    check_range,
    check_target,
    medium_factory,
)
from .glare_estimate import glare_input
from .result import AutofocusResult
from .search import Search
from .sphere_fit import sphere_instead
from .steps import COARSE, NoHandleError, Run, estimate

__all__ = ["autofocus"]


def _one_blas_thread(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Run ``fn`` with the BLAS on one thread. autofocus's matrix products are small
    (tens of ranges x a thousand nodes): threads gain nothing on a quiet machine (5.1 s
    against 5.4 s for a 4-frequency 16 x 16 search) and, on a busy one, spin waiting for
    a core (8.0 s against 15.0 s with two other busy processes on two cores)."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            return fn(*args, **kwargs)

    return wrapper


@_one_blas_thread
def autofocus(hologram: Hologram, *, medium_model: Medium | Callable[[float], Medium],
              eps_range: tuple[float, float] = (1.5, 16.0),
              depth_range: tuple[float, float] | None = None,
              position: tuple[float, float] | None = None,
              glare: bool | tuple[float, float] | None = None,
              fit: Literal["field", "phase"] = "field", confidence: float = 0.95,
              target: Literal["point", "line", "sphere"] = "point",
              line_radius: float = 0.006, sphere_radius: float | None = None,
              progress: bool = False) -> AutofocusResult:
    """Find the ground permittivity eps' (and the object's range) that focuses best.

    Fits one compact buried object: the exact field of a point scatterer in a
    ground of trial permittivity (the model's Sommerfeld integral) is matched to
    the hologram, its position and complex amplitude fitted, and eps' chosen to
    maximise the focus fraction ``F = |<h, g>|^2 / (||g||^2 ||h||^2)`` (the
    maximum-likelihood fit of one scatterer; see the module notes for why not
    an image-sharpness metric). At one frequency only the wave front's shape
    across the aperture carries eps' (a weak handle: the paraxial curvature
    fixes ``z0 + depth/n`` alone, and the rest comes from the wider angles);
    several frequencies add the two-way delay, ``z0 + n*depth`` (a strong one).

    Parameters
    ----------
    hologram : Hologram
        One frame, one or several frequencies, glare removed (or see ``glare``).
        Across frequencies the data must be phase-calibrated, and a receiver
        array needs its ``source`` (without it each frequency is fitted with its
        own amplitude: the delay is lost). Tilted apertures are supported (slower).
    medium_model : Medium or callable
        The ground with eps' unknown: a half-space ``Medium`` (its surface range is
        kept, and its loss tangent ``eps''/eps'``), or a function ``eps' ->
        Medium`` for any other model (e.g. a known top layer over an unknown
        ground).
    eps_range : (float, float)
        Range of eps' searched, default 1.5 .. 16.
    depth_range : (float, float), optional
        Depths below the surface to look for the object, metres; default from
        half a wavelength in the ground to 1.5 aperture widths (at least 0.5 m).
    position : (float, float), optional
        Lateral (x, y) of the object to fit, metres; default the brightest one.
    glare : bool or (float, float), optional
        ``True``: the hologram still holds the surface glare; estimate eps' from it
        (:func:`~holoradar.estimate_permittivity`), remove it and combine both
        estimates by their inverse variances. ``(eps', sigma)``: combine with an
        estimate made elsewhere. Default: no glare estimate.
    confidence : float
        Confidence of the interval, default 0.95.
    target : {"point", "line", "sphere"}
        The object: ``"point"`` (default), a compact scatterer (an isotropic induced
        dipole in the vector model), fitted as a conducting sphere instead where the
        point leaves a smooth residual that a sphere of fitted radius at least halves
        (``result.sphere_radius``, ``result.model_note``); ``"sphere"``, a perfectly
        conducting sphere centred at the fitted position, its Mie far field
        towards each element (:mod:`holoradar.imaging.sphere_response`: where
        ``k a`` in the ground is 1 or more the point model misreads the sphere's
        echo, which comes from the side facing the rays' bisector; on a T-matrix
        solution of a 15 mm ball 10 cm deep in sand the point leaves 1e-3 of the
        data unexplained at any eps', the sphere 4e-5 at the true one only); it
        needs the vector model on an untilted grid, lit by a plane wave, a point
        source or a dipole (or a transceiver); ``"line"``, a horizontal cylinder (rebar, pipe)
        whose centre, range, azimuth and length are fitted with eps'
        (``result.line_azimuth_deg``, ``result.line_length``), modelled as the
        simulation's :class:`~holoradar.LineTarget`. Lines need the vector model
        (a hologram with a ``polarization`` and a polarised source) on an untilted
        grid. The search runs on the line's asymptotic (ray) field on part of the
        data, the exact finite line corrects it once on all of it (seconds: 8-10 s
        on a 41 x 41 x 21 hologram); further lines are fitted with the first while
        each explains 2 % of the data (a rebar mat).
    line_radius : float
        The cylinder's radius in metres for ``target="line"`` (default 0.006, a 12 mm
        bar; a perfect conductor). A thick bar echoes from its near side: a wrong
        radius biases eps' by about ``(a_true - a)/depth``.
    sphere_radius : float, optional
        The sphere's radius in metres, for ``target="sphere"`` (and only for it);
        default: fitted (scanned at the point fit's eps', then refitted at every trial
        eps'). At one frequency the radius trades with eps' almost perfectly: a known
        radius narrows the interval many times.
    progress : bool
        Show a progress bar over all the work: locating the object, then every trial
        permittivity (its total grows when the refinement needs more).

    Returns
    -------
    AutofocusResult
        ``eps`` with ``eps_interval``, the object's ``position`` and
        ``range_interval``; or ``determinable=False`` and ``eps=None`` with the
        ``reason`` when the scene gives no handle: no object above the noise, an
        object at the surface or too shallow for the aperture, a best focus at the
        edge of ``eps_range``, an interval that reaches it, or two permittivities that
        focus equally well ("ambiguous": aliases of the delay left by the frequency
        step).

    Examples
    --------
    >>> import numpy as np, holoradar as hr
    >>> truth = hr.Medium.half_space(0.30, 4.0)
    >>> scene = hr.Scene(truth, hr.PlaneWave(), [hr.PointTarget((0.01, 0.0, 0.45))])
    >>> h = hr.simulate(scene, hr.Aperture.paper(), 9.9e9, include_surface=False,
    ...                 snr_db=40, seed=0)
    >>> res = hr.autofocus(h, medium_model=hr.Medium.half_space(0.30, 3.0))
    >>> res.determinable, res.eps_interval[0] < 4.0 < res.eps_interval[1]
    (True, True)
    >>> print(f"{res.eps:.1f}, {100 * res.depth:.0f} cm deep")
    4.1, 15 cm deep
    >>> noise = np.random.default_rng(1).standard_normal((16, 16, 2)) @ [1, 1j]
    >>> res = hr.autofocus(hr.Hologram(noise, h.x, h.y, 9.9e9), medium_model=truth)
    >>> print(res.eps, "-", res.reason.split(" (")[0])
    None - no compact object stands out of the noise
    """
    t_start = time.perf_counter()
    check_hologram(hologram)
    lo, hi = check_range(eps_range)
    make = medium_factory(medium_model, lo, hi)
    confidence = check_confidence(confidence)
    hologram, glare_est = glare_input(glare, hologram, medium_model, make, lo, hi)
    coherent = hologram.monostatic or hologram.nf == 1 or hologram.source is not None
    handle = ("one frequency: the wave front's shape" if hologram.nf == 1 else
              "several frequencies: the wave front's shape and the delay" if coherent else
              "several frequencies without the illumination: the wave front's shape only")
    # A sphere of unknown radius: located and fitted as a point first, its radius then
    # scanned at the point's eps' (sphere_fit.py).
    fit_radius = target == "sphere" and sphere_radius is None
    first = "point" if fit_radius else target
    if fit_radius:   # the sphere model must apply to these data: say so now if not
        _response(hologram, make, coherent, fit, "sphere", line_radius, 0.01)
    pr = _response(hologram, make, coherent, fit, first, line_radius,
                   None if fit_radius else sphere_radius)
    search = Search(pr, make, lo, hi, hologram, _progress_bar(target, progress))
    run = Run(search, make, lo, hi, z0=make(lo).z_interfaces[0], confidence=confidence,
              glare=glare_est, t_start=t_start,
              base=dict(confidence=confidence, handle=handle,
                        eps_glare=None if glare_est is None else glare_est[0],
                        eps_glare_std=None if glare_est is None else glare_est[1]))
    try:
        fields = estimate(run, depth_range, position, first)
    except NoHandleError as stop:
        fields = stop.fields
    if first == "sphere" and fields.get("position") is not None:
        fields["sphere_radius"] = pr.radius
    # A point found (or found but ambiguous between rivals: a sphere's better fit may
    # settle it) may turn out to be a sphere whose size shows.
    found = fields.get("position") is not None and fields.get("detection", 0.0) >= fields.get(
        "detection_threshold", np.inf) and bool(run.search.best) and (
        fields.get("determinable") or str(fields.get("reason", "")).startswith("ambiguous"))
    if first == "point" and found:
        best = run.search.best
        e0 = max(best, key=lambda e: best[e][0])
        as_sphere = sphere_instead(run, hologram, coherent, fit, depth_range, fields, e0,
                                   forced=fit_radius)
        if as_sphere is not None:
            run, fields = as_sphere
    return run.finish(**fields)


def _response(hologram: Hologram, make: Callable[[float], Medium], coherent: bool, fit: Any,
              target: Any, line_radius: Any, sphere_radius: Any = None) -> PointResponse:
    """The model fitted: a point's response, a line's (``target="line"``) or a
    sphere's (``target="sphere"``)."""
    check_fit(fit)
    check_target(target)
    if target == "sphere":
        from ..sphere_response import SphereResponse, check_sphere_radius

        r = check_sphere_radius(sphere_radius)
        return SphereResponse(hologram, make, coherent=coherent, phase_only=fit == "phase",
                              radius=r)
    if sphere_radius is not None:
        raise ValueError("sphere_radius is for target='sphere' only, got target="
                         f"{target!r}")
    if target == "line":
        from ..line_response import LineResponse

        r = check_line_radius(line_radius)
        return LineResponse(hologram, make, coherent=coherent, phase_only=fit == "phase",
                            radius=r)
    return PointResponse(hologram, make, coherent=coherent, phase_only=fit == "phase")


def _progress_bar(target: Any, progress: bool) -> Any:
    """A tqdm bar over the trials, hidden unless ``progress``."""
    # Locating, the middle trial, the sweep, about 8 refinements and 6 for the interval
    # (a line: the sweep twice).
    expected = 2 + COARSE * (2 if target == "line" else 1) + 14
    from tqdm.auto import tqdm

    return tqdm(total=expected, desc="autofocus", unit="step", disable=not progress,
                delay=1.0)
