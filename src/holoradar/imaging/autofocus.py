"""Autofocus: the ground permittivity that focuses a buried object best.

The sharpness measure is the *focus fraction*: the share of the hologram's
energy that one compact scatterer explains, the exact field of a point at
``r`` in a ground of permittivity eps' (:mod:`.point_response`), fitted with its
complex amplitude,

    F(eps', r) = |<h, g>|^2 / (||g||^2 ||h||^2).

It is the peak of the matched-filter image normalised, pixel by pixel, by the
energy its point response leaves on the finite aperture. Image-domain measures
(the peak, the normalised fourth moment, the entropy of a migrated image) are
not normalised that way: a point's image through a finite aperture brightens
and narrows as eps' grows (refraction squeezes more of its wave front onto the
array), so they drift to high eps' (4.5 for a true 4.0 with the 16 x 16
array). ``max F`` is the maximum-likelihood fit of one object in white noise,
without that drift.

Confidence interval: the profile likelihood. With ``R(eps') = ||h||^2 (1 -
max_r F)`` the residual energy, the interval holds the eps' with
``R - R_min <= (z s sqrt(phi) + sqrt(E_err))^2``: ``z`` the normal quantile of the confidence,
``s^2 = R_min / (2N - 6)`` the residual's variance per real component (N complex
samples, six real parameters), and ``phi >= 1`` a sandwich correction for a
residual that is not white (model error: a sphere is not a point, a vector field
not a scalar one): ``phi = sum_k |D_k|^2 |R_k|^2 / (sigma^2 sum_k |D_k|^2)``, with
``R_k`` the residual's spectrum and ``D_k`` that of the model's derivative with
respect to eps' (made orthogonal to the derivatives in amplitude and position).
It weighs the residual's power at the spatial frequencies (and delays) where
eps' acts: 1 for white noise, more when the residual looks like a change of eps'.
``E_err`` is the energy of the residual's smooth part (model error), which could
shift the estimate by at most ``sqrt(E_err)/||D||``.
"""

from __future__ import annotations

import functools
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .._lazy import lazy_module
from .._validate import AliasingWarning
from ..data.hologram import C0, Hologram
from ..data.noise import smooth_residual_energy
from ..physics.medium import Medium
from .migrate import migrate
from .point_response import PointResponse

# Imported on first use (holoradar._lazy): `import holoradar` should cost little more
# than numpy. The two quantiles below come from scipy.special, not scipy.stats, whose
# import alone (0.4 s) would double a first single-frequency search.
sfft = lazy_module("scipy.fft")
_opt = lazy_module("scipy.optimize")
_special = lazy_module("scipy.special")

__all__ = ["AutofocusResult", "autofocus"]

_COARSE = 10          # eps' values of the first sweep (geometric)
_FALSE_ALARM = 1e-3   # detection: chance that noise alone passes
_MODEL_PRECISION = 1e-4  # relative amplitude accuracy of the model (quadrature, splines)
# The position fit's stopping rule. Gauss-Newton converges quadratically, so a step that
# lowers the residual by less than _FTOL of itself leaves an error far below that; the
# interval's drop is >= 1e-4 of the residual (noise), so 1e-8 is ample. _XTOL: metres.
_FTOL = 1e-8
_XTOL = 1e-9


@dataclass(frozen=True)
class AutofocusResult:
    """What :func:`autofocus` found.

    Attributes
    ----------
    eps : float or None
        Estimated real relative permittivity eps' of the ground (combined with the
        glare's estimate when one was used); ``None`` when not determinable.
    eps_interval : tuple of float or None
        Its confidence interval (``confidence``).
    determinable : bool
        False when the data give no handle on eps' (then ``reason`` says why).
    reason : str
        Why not determinable, or how the estimate was made.
    confidence : float
    position : tuple of float or None
        The object (x, y, z) at the estimate, metres (z the range from the
        aperture).
    range_interval : tuple of float or None
        The object's range over ``eps_interval``, metres.
    depth : float or None
        The object's depth below the ground surface, metres.
    eps_focus, eps_focus_interval
        The focus's own estimate and interval (also when a glare was combined).
    eps_glare, eps_glare_std
        The glare's estimate and 1-sigma, when used.
    focus_fraction : float
        The share of the hologram's energy the object explains at the estimate.
    detection : float
        The object's matched-filter output over the residual noise level, and
        ``detection_threshold`` the level noise alone exceeds with 1e-3 chance.
    noise_inflation : float
        The sandwich factor phi (1 for white residuals).
    handle : str
        What fixes eps': the wave front's shape (one frequency) or the delays too.
    eps_grid, profile : ndarray
        The eps' tried and the best focus fraction at each (sorted by eps').
    evaluations : int
        Point responses evaluated (the field of one trial object at every element
        and frequency: the work of one trial).
    integrals : int
        Sommerfeld integrals computed (one per frequency, trial eps' and range;
        each serves many trials).
    seconds : float
    medium : Medium or None
        The ground model at the estimate.
    """

    eps: float | None
    eps_interval: tuple[float, float] | None
    determinable: bool
    reason: str
    confidence: float
    position: tuple[float, float, float] | None = None
    range_interval: tuple[float, float] | None = None
    depth: float | None = None
    eps_focus: float | None = None
    eps_focus_interval: tuple[float, float] | None = None
    eps_glare: float | None = None
    eps_glare_std: float | None = None
    focus_fraction: float = 0.0
    detection: float = 0.0
    detection_threshold: float = 0.0
    noise_inflation: float = 1.0
    handle: str = ""
    eps_grid: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False,
                                 compare=False)
    profile: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False, compare=False)
    evaluations: int = 0
    integrals: int = 0
    seconds: float = 0.0
    medium: Medium | None = field(default=None, repr=False)
    line_azimuth_deg: float | None = None
    line_length: float | None = None

    @property
    def std(self) -> float | None:
        """Equivalent 1-sigma of eps' (half the interval over the normal quantile)."""
        if self.eps_interval is None:
            return None
        return (self.eps_interval[1] - self.eps_interval[0]) / (2 * _quantile(self.confidence))

    def __str__(self) -> str:
        if not self.determinable:
            return f"eps' not determinable: {self.reason}"
        lo, hi = self.eps_interval
        # Enough decimals that the interval's width shows (2 at least).
        d = max(2, 1 - int(np.floor(np.log10(max(hi - lo, 1e-12)))))
        text = (f"eps' = {self.eps:.{d}f} ({100 * self.confidence:.0f}% interval {lo:.{d}f} .. "
                f"{hi:.{d}f})")
        if self.position is not None and self.depth is not None:
            text += (f"; object at range {self.position[2]:.4g} m, {self.depth:.4g} m below the "
                     "surface")
        return f"{text} ({self.handle if self.eps_focus is not None else self.reason})"


def _quantile(confidence: float) -> float:
    return float(_special.ndtri(0.5 + confidence / 2))   # the normal quantile


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
              target: Literal["point", "line"] = "point", line_radius: float = 0.006,
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
    target : {"point", "line"}
        The object: ``"point"`` (default), a compact scatterer (an isotropic induced
        dipole in the vector model); ``"line"``, a horizontal cylinder (rebar, pipe)
        whose centre, range, azimuth and length are fitted with eps'
        (``result.line_azimuth_deg``, ``result.line_length``), modelled as the
        simulation's :class:`~holoradar.LineTarget`. Lines need the vector model
        (a hologram with a ``polarization`` and a polarised source) on an untilted
        grid, and are slow (every trial line costs nodes x elements x frequencies
        interpolations).
    line_radius : float
        The cylinder's radius in metres for ``target="line"`` (default 0.006, a 12 mm
        bar; a perfect conductor). A thick bar echoes from its near side: a wrong
        radius biases eps' by about ``(a_true - a)/depth``.
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
    if not isinstance(hologram, Hologram):
        raise ValueError(f"hologram must be a holoradar.Hologram, got {type(hologram).__name__}")
    if hologram.data.ndim != (3 if hologram.is_wideband else 2):
        raise ValueError("hologram: autofocus takes one frame (data (ny, nx) or (nf, ny, nx)), "
                         f"got data of shape {hologram.data.shape}; pass one frame at a time")
    if not np.any(hologram.data):
        raise ValueError("hologram: every sample is zero; there is nothing to focus")
    lo, hi = _check_range(eps_range)
    make = _medium_factory(medium_model, lo, hi)
    confidence = float(confidence)
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must lie between 0 and 1 (e.g. 0.95), got {confidence}")
    glare_est = None
    if glare is True:
        start = medium_model if isinstance(medium_model, Medium) else make(float(np.sqrt(lo * hi)))
        hologram, glare_est = _glare_estimate(hologram, start)
    elif glare not in (None, False):
        glare_est = _check_glare(glare)
    coherent = hologram.monostatic or hologram.nf == 1 or hologram.source is not None
    handle = ("one frequency: the wave front's shape" if hologram.nf == 1 else
              "several frequencies: the wave front's shape and the delay" if coherent else
              "several frequencies without the illumination: the wave front's shape only")
    if fit not in ("phase", "field"):
        raise ValueError(f"fit must be 'phase' or 'field', got {fit!r}")
    if target not in ("point", "line"):
        raise ValueError(f"target must be 'point' (a compact object) or 'line' (rebar, pipe), "
                         f"got {target!r}")
    if target == "line":
        from .line_response import LineResponse

        r = float(line_radius) if np.isscalar(line_radius) else np.nan
        if not (np.isfinite(r) and r > 0):
            raise ValueError(f"line_radius must be the bar's radius in metres (> 0), got "
                             f"{line_radius!r}")
        pr = LineResponse(hologram, make, coherent=coherent, phase_only=fit == "phase",
                          radius=r)
    else:
        pr = PointResponse(hologram, make, coherent=coherent, phase_only=fit == "phase")
    # Locating, the middle trial, the sweep, about 8 refinements and 6 for the interval
    # (a line: the sweep twice).
    expected = 2 + _COARSE * (2 if target == "line" else 1) + 14
    from tqdm.auto import tqdm

    bar = tqdm(total=expected, desc="autofocus", unit="trial", disable=not progress,
               delay=1.0)
    search = _Search(pr, make, lo, hi, hologram, bar)
    z0 = make(lo).z_interfaces[0]
    base = dict(confidence=confidence, handle=handle, eps_glare=None if glare_est is None
                else glare_est[0], eps_glare_std=None if glare_est is None else glare_est[1])

    def finish(**kw: Any) -> AutofocusResult:
        grid = np.array(sorted(search.best))
        prof = np.array([search.best[e][0] for e in grid])
        kw = {**base, **kw}
        if not kw.get("determinable", True) and glare_est is not None:
            g, s = glare_est
            q = _quantile(confidence)
            kw.update(eps=g, eps_interval=(g - q * s, g + q * s), determinable=True,
                      reason=f"from the glare alone (the focus gave no handle: {kw['reason']})",
                      medium=make(g))
        bar.total = bar.n
        bar.refresh()
        bar.close()
        return AutofocusResult(eps_grid=grid, profile=prof, evaluations=pr.responses,
                               integrals=pr.integrals,
                               seconds=time.perf_counter() - t_start, **kw)

    # 1. Where is the object? Laterally the brightest column of a migrated image; its
    #    range, curvature and delay from the point fit along that column.
    located = search.locate(depth_range, position, z0)
    bar.update()
    if located is None:
        return finish(eps=None, eps_interval=None, determinable=False,
                      reason="the brightest focus lies at the ground surface or above it, not "
                             "in the ground")
    # 2. Is there an object at all? Fit one at a middle eps' and test it against noise.
    grid = np.geomspace(lo, hi, _COARSE)
    mid = float(grid[len(grid) // 2])
    _, z_mid, xy_mid = search.evaluate(mid)
    pre = search.statistics(mid, z_mid, xy_mid)
    if pre["detection"] < pre["threshold"]:
        return finish(eps=None, eps_interval=None, determinable=False,
                      reason=_no_object(pre), position=(float(xy_mid[0]), float(xy_mid[1]),
                                                        float(z_mid)),
                      detection=pre["detection"], detection_threshold=pre["threshold"])
    # 3. Coarse sweep of eps' outwards from there, each with its best range and position.
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
    # Local maxima of the sweep, and (several frequencies) every eps' where curvature and
    # an alias of the delay agree: each refined, the best kept, the others checked below.
    F_grid = [search.best[float(e)][0] for e in grid]
    seeds = [(float(grid[j - 1]) if j else lo, float(grid[j]),
              float(grid[j + 1]) if j < len(grid) - 1 else hi)
             for j in range(len(grid)) if (j == 0 or F_grid[j] >= F_grid[j - 1])
             and (j == len(grid) - 1 or F_grid[j] >= F_grid[j + 1])]
    seeds += [(max(lo, c / 1.03), c, min(hi, c * 1.03)) for c in search.candidates()]
    # Now the work left is known better: about 8 trials a refined seed, 7 for the interval.
    bar.total = max(bar.total, bar.n + 8 * len(seeds) + 7)
    bar.refresh()
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
    e_hat = max(search.best, key=lambda e: search.best[e][0])
    F_max, z_hat, xy_hat = search.best[e_hat]
    # 4. Noise level, detection and the sandwich factor at the optimum.
    stats = search.statistics(e_hat, z_hat, xy_hat)
    pos = (float(xy_hat[0]), float(xy_hat[1]), float(z_hat))
    line = {} if len(xy_hat) < 4 else dict(
        line_azimuth_deg=float(np.degrees(xy_hat[2]) % 180.0), line_length=float(xy_hat[3]))
    common = dict(position=pos, depth=float(z_hat - z0), focus_fraction=F_max, **line,
                  detection=stats["detection"], detection_threshold=stats["threshold"],
                  noise_inflation=stats["phi"])
    if stats["detection"] < stats["threshold"]:
        return finish(eps=None, eps_interval=None, determinable=False,
                      reason=_no_object(stats), **common)
    if e_hat <= lo * (1 + 1e-9) or e_hat >= hi * (1 - 1e-9):
        return finish(eps=None, eps_interval=None, determinable=False,
                      reason=f"the sharpest focus lies at the edge of eps_range ({lo:g} .. "
                             f"{hi:g}): widen it, or the scene gives no handle", **common)
    # 5. Profile-likelihood interval, R(eps) - R_min <= (q s sqrt(phi) + sqrt(E_err))^2, in
    #    focus-fraction units.
    # The statistical part (noise, q s sqrt(phi)) and a bound on the bias a smooth model
    # error of energy E_err can cause, were it aligned with the change of eps' (profile
    # residual rises as ||d||^2 delta^2, the bias is at most sqrt(E_err)/||d||): the
    # deviations add, so their square roots do.
    q = _quantile(confidence)
    drop = (q * np.sqrt(stats["s2"] * stats["phi"]) + np.sqrt(stats["model_error"])) ** 2 \
        / (stats["residual_scale"] * pr.energy)
    ends = []
    for side in (-1, 1):
        end = search.crossing(e_hat, F_max - drop, side)
        if end is None:
            return finish(eps=None, eps_interval=None, determinable=False,
                          reason=f"the focus hardly changes with eps': its {100 * confidence:.0f}%"
                                 f" interval reaches the edge of eps_range ({lo:g} .. {hi:g}) "
                                 "(object too shallow, or too small an aperture for one "
                                 "frequency)", **common)
        ends.append(end)
    interval = (ends[0], ends[1])
    rivals = sorted({round(e, 3) for e in modes if not interval[0] <= e <= interval[1]
                     and search.best[e][0] >= F_max - drop})
    if rivals:
        note = ""
        if search.wideband:
            df = float(np.min(np.diff(hologram.frequencies)))
            note = (f"; the frequency step {df / 1e6:.0f} MHz leaves the delay ambiguous by "
                    f"c/(2 df) = {100 * C0 / (2 * df):.1f} cm of optical path: use finer steps")
        return finish(eps=None, eps_interval=None, determinable=False,
                      reason=f"ambiguous: eps' = {e_hat:.3g} and "
                             f"{', '.join(f'{e:.3g}' for e in rivals)} focus equally well{note}",
                      **common)
    r_int = tuple(sorted((search.best[ends[0]][1], search.best[ends[1]][1])))
    est, est_int = e_hat, interval
    reason = "from the focus"
    if glare_est is not None:
        est, est_int, reason = _combine(e_hat, interval, glare_est, q)
    return finish(eps=float(est), eps_interval=est_int, determinable=True, reason=reason,
                  range_interval=(float(r_int[0]), float(r_int[1])), eps_focus=e_hat,
                  eps_focus_interval=interval, medium=make(float(est)), **common)


class _Search:
    """The best focus for each trial eps': the range from a scan (around the paraxially
    equivalent range and every alias of the delay), then range and lateral position by
    bounded Gauss-Newton."""

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

    def locate(self, depth_range: tuple[float, float] | None, position: Any,
               z0: float) -> bool | None:
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
        combine = "coherent" if self.pr.coherent else "incoherent"
        with warnings.catch_warnings():  # only the brightest voxel is wanted here
            warnings.simplefilter("ignore", AliasingWarning)
            # A moved or tilted aperture: image on the ground's own (world) planes.
            frame = "aperture" if h.pose.is_identity else "ground"
            img = migrate(h, zs, medium=m, combine=combine, progress=False, frame=frame)
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
        self.xy = np.array([img.x[ix], img.y[iy]], float)
        if getattr(self.pr, "max_length", None) is not None:
            self.xy = _line_from_image(a, img.x, img.y, iy, ix, self.pr.max_length, lam_m)
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
            res = C0 / (2 * self.band * np.sqrt(e_mid))
            zp, _ = self.pr.scan(e_mid, top, bottom, self.xy,
                                 samples=int(np.clip((d1 - d0) / (res / 3), 24, 240)))
        self.P = m.optical_path(zp).real
        self.depths = (top, bottom)
        if zp <= z0 + lam_m / 4 or z_a <= z0 + lam_m / 4:
            return None
        return True

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
                self.bar.total = self.bar.n + 4   # more than expected: keep room
            self.bar.update()
        pr = self.pr
        floor = self.z0 + pr.spacing(eps) / 4
        offset, xy0, close = 0.0, self.xy, False
        if self.best:  # start from the fit at the nearest eps' tried (a continuous path)
            near = min(self.best, key=lambda e: abs(np.log(e / eps)))
            _, z_near, xy0 = self.best[near]
            offset = z_near - self.paraxial_range(near)
            close = abs(np.log(eps / near)) < 0.05
        # The object's range for this eps': near the range of the same paraxial curvature
        # (one frequency) or between it and the range of the same delay (several).
        z_c = self.paraxial_range(eps) + offset
        lam_m = self.lam / np.sqrt(eps)
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
        shape0 = np.asarray(xy0[2:], float)          # a line's azimuth and length
        if shape0.size and self.best and not refine_shape:
            # A line's shape hardly depends on eps': fitted once (the first trial, and
            # at the optimum), held during the sweep.
            return self._evaluate_fixed_shape(eps, floor, xy0, z_start, lam_m)
        p0 = np.array([xy0[0], xy0[1], z_start, *shape0])

        def params(p: np.ndarray) -> np.ndarray:
            return np.r_[p[:2], p[3:]]

        def resid(p: np.ndarray) -> np.ndarray:
            r, _, _ = pr.residual(eps, max(p[2], floor), params(p))
            return np.concatenate([r.real.ravel(), r.imag.ravel()])

        # Bounded to the scanned peak's basin: an unbounded first step may jump to another
        # alias of the delay.
        reach = C0 / (4 * self.band * np.sqrt(eps)) if self.wideband else 2 * lam_m
        p0[:2] = np.clip(p0[:2], *pr.bounds)
        lo_b = np.array([*np.maximum(p0[:2] - 2 * lam_m, pr.bounds[0]), max(p0[2] - reach,
                                                                            floor)])
        hi_b = np.array([*np.minimum(p0[:2] + 2 * lam_m, pr.bounds[1]), p0[2] + reach])
        lo_b[:2] = np.minimum(lo_b[:2], p0[:2] - 1e-9)  # a non-empty box at the edge
        hi_b[:2] = np.maximum(hi_b[:2], p0[:2] + 1e-9)
        scale = np.full(3, self.lam / 10)
        if shape0.size:  # azimuth within 20 degrees, length within a factor 2 of the start
            L0 = float(shape0[1])
            lo_b = np.r_[lo_b, shape0[0] - 0.35, max(lam_m, 0.5 * L0)]
            hi_b = np.r_[hi_b, shape0[0] + 0.35, max(min(pr.max_length, 2 * L0), lam_m * 1.01)]
            p0[3:] = np.clip(p0[3:], lo_b[3:] + 1e-9, hi_b[3:] - 1e-9)
            scale = np.r_[scale, 0.02, self.lam / 10]
        sol = _opt.least_squares(resid, p0, method="trf", bounds=(lo_b, hi_b), xtol=_XTOL,
                            ftol=_FTOL, gtol=_FTOL, x_scale=scale)
        p = sol.x
        z = max(float(p[2]), floor)
        xy = np.r_[np.clip(p[:2], *pr.bounds), p[3:]]
        F = pr.focus(eps, z, xy)
        self.best[eps] = (F, z, xy)
        return self.best[eps]

    def _evaluate_fixed_shape(self, eps: float, floor: float, xy0: np.ndarray, z_start: float,
                              lam_m: float) -> tuple[float, float, np.ndarray]:
        pr = self.pr
        shape = np.asarray(xy0[2:], float)
        p0 = np.array([xy0[0], xy0[1], z_start])

        def resid(p: np.ndarray) -> np.ndarray:
            r, _, _ = pr.residual(eps, max(p[2], floor), np.r_[p[:2], shape])
            return np.concatenate([r.real.ravel(), r.imag.ravel()])

        reach = C0 / (4 * self.band * np.sqrt(eps)) if self.wideband else 2 * lam_m
        p0[:2] = np.clip(p0[:2], *pr.bounds)
        lo_b = np.array([*np.maximum(p0[:2] - 2 * lam_m, pr.bounds[0]),
                         max(p0[2] - reach, floor)])
        hi_b = np.array([*np.minimum(p0[:2] + 2 * lam_m, pr.bounds[1]), p0[2] + reach])
        lo_b[:2] = np.minimum(lo_b[:2], p0[:2] - 1e-9)
        hi_b[:2] = np.maximum(hi_b[:2], p0[:2] + 1e-9)
        sol = _opt.least_squares(resid, p0, method="trf", bounds=(lo_b, hi_b), xtol=_XTOL,
                            ftol=_FTOL, gtol=_FTOL, x_scale=np.full(3, self.lam / 10))
        z = max(float(sol.x[2]), floor)
        xy = np.r_[np.clip(sol.x[:2], *pr.bounds), shape]
        self.best[eps] = (pr.focus(eps, z, xy), z, xy)
        return self.best[eps]

    def crossing(self, e_hat: float, level: float, side: int) -> float | None:
        """eps' on ``side`` of ``e_hat`` where the best focus fraction falls to ``level``."""
        inside = e_hat
        for e in sorted(self.best, reverse=side < 0):
            if (e - e_hat) * side > 0 and self.best[e][0] < level:
                outside = e
                break
            if (e - e_hat) * side > 0:
                inside = e
        else:
            edge = self.lo if side < 0 else self.hi
            if self.evaluate(edge)[0] >= level:
                return None
            outside = edge

        def f(e: float) -> float:
            return self.evaluate(float(e))[0] - level

        return float(_opt.brentq(f, inside, outside, rtol=1e-3))

    def statistics(self, eps: float, z: float, xy: np.ndarray) -> dict[str, float]:
        """Noise variance, detection statistic and sandwich factor at the optimum."""
        pr = self.pr
        n_amp = 1 if pr.coherent else pr.h.shape[0]
        n_complex = pr.h.size
        floor = (_MODEL_PRECISION ** 2) * pr.energy / (2 * n_complex)
        # Detection, from the complex-field fit: the matched filter's output over the
        # complex noise variance 2 s^2 is exponential for noise alone (per amplitude); the
        # threshold is its level exceeded with chance _FALSE_ALARM over all the trials.
        rf, gf, _ = pr.residual(eps, z, xy, phase=False)
        s2f = max(float(np.vdot(rf, rf).real) / max(2 * n_complex - 4 - 2 * n_amp, 1), floor)
        detection = pr.energy * pr.match(gf, phase=False)[0] / (2 * s2f)
        # With one amplitude per frequency the output sums n_amp such variables (Gamma).
        # Gamma(n_amp, 1)'s upper quantile: Q(n_amp, x) = p, Q the regularised upper
        # incomplete gamma function.
        threshold = float(_special.gammainccinv(n_amp, _FALSE_ALARM / self.trials))
        # Residual variance per real component: a phase-only residual has one real
        # component per sample (along the phase), a field residual two.
        r, g, a = pr.residual(eps, z, xy)
        R = float(np.vdot(r, r).real)
        dof = (n_complex if pr.phase_only else 2 * n_complex) - 4 - (1 if pr.phase_only else 2) \
            * n_amp
        s2 = max(R / max(dof, 1), floor)

        def model(e: float, zz: float, p: np.ndarray) -> np.ndarray:
            return pr.model(pr.response(e, zz, p), a)

        # Sandwich: tangent vectors of the model in (amplitude, x, y, z) and eps'.
        de, dz, dx = 1e-3 * eps, self.lam / np.sqrt(eps) / 40, self.lam / 400
        m0 = pr.model(g, a)
        d_eps = (model(eps + de, z, xy) - model(eps - de, z, xy)) / (2 * de)
        groups = [np.ones(m0.shape[0], bool)] if pr.coherent else \
            [np.arange(m0.shape[0]) == f for f in range(m0.shape[0])]
        tangents = []
        for sel in groups:  # each amplitude: its phase, and for a field fit its modulus
            t = np.where(sel[:, None], m0, 0)
            tangents += [1j * t] if pr.phase_only else [t, 1j * t]
        steps = [dx, dx, 1e-3, dx][:len(xy)]  # x, y (and a line's azimuth, length)
        for i, step in enumerate(steps):
            dv = np.zeros(len(xy))
            dv[i] = step
            tangents.append((model(eps, z, xy + dv) - model(eps, z, xy - dv)) / (2 * step))
        tangents.append((model(eps, z + dz, xy) - model(eps, z - dz, xy)) / (2 * dz))
        T = np.stack([np.concatenate([t.real.ravel(), t.imag.ravel()]) for t in tangents], 1)
        d = np.concatenate([d_eps.real.ravel(), d_eps.imag.ravel()])
        coef, *_ = np.linalg.lstsq(T, d, rcond=None)
        dp = d - T @ coef
        d_perp = (dp[:d.size // 2] + 1j * dp[d.size // 2:]).reshape(self.hologram.data.shape)
        D = np.abs(sfft.fftn(d_perp, norm="ortho")) ** 2
        Rk = np.abs(sfft.fftn(r.reshape(self.hologram.data.shape), norm="ortho")) ** 2
        # White residual: E|R_k|^2 = (real components per sample) * s^2.
        per = 1 if pr.phase_only else 2
        phi = float(np.sum(D * Rk) / (per * s2 * np.sum(D))) if np.sum(D) > 0 else 1.0
        return dict(s2=s2, detection=float(detection), threshold=threshold,
                    phi=max(1.0, phi), residual_scale=2.0 if pr.phase_only else 1.0,
                    model_error=smooth_residual_energy(r.reshape(self.hologram.data.shape)))


def _line_from_image(a: np.ndarray, x: np.ndarray, y: np.ndarray, iy: int, ix: int,
                     max_length: float, lam_m: float) -> np.ndarray:
    """A line's start (x, y, azimuth, length) from a migrated image's plane that holds the
    brightest pixel: the pixels above half of it that connect to it, their
    intensity-weighted centre and principal axis, and their extent along it."""
    from scipy import ndimage

    plane = a.reshape((-1, *a.shape[-3:])).max(axis=0)
    iz = int(np.argmax(plane[:, iy, ix]))
    p = plane[iz]
    labels, _ = ndimage.label(p >= 0.5 * p[iy, ix])
    sel = labels == labels[iy, ix]
    X, Y = np.meshgrid(x, y)
    w = p[sel] ** 2
    cx, cy = float(np.average(X[sel], weights=w)), float(np.average(Y[sel], weights=w))
    dx, dy = X[sel] - cx, Y[sel] - cy
    cov = np.cov(np.stack([dx, dy]), aweights=w) if sel.sum() > 2 else np.eye(2)
    _, vecs = np.linalg.eigh(cov)
    t = vecs[:, -1]
    along = dx * t[0] + dy * t[1]
    length = float(np.clip(np.ptp(along) + 2 * float(abs(x[1] - x[0])), 2 * lam_m,
                           max_length))
    return np.array([cx, cy, float(np.arctan2(t[1], t[0])), length])


def _no_object(stats: dict[str, float]) -> str:
    return (f"no compact object stands out of the noise (matched filter "
            f"{stats['detection']:.3g} x the noise level; noise alone reaches "
            f"{stats['threshold']:.3g})")


def _check_range(eps_range: Any) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in eps_range)
    except (TypeError, ValueError):
        raise ValueError(f"eps_range must be (min, max) real permittivities, got "
                         f"{eps_range!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 1 <= lo < hi):
        raise ValueError(f"eps_range must satisfy 1 <= min < max (real eps'), got {eps_range!r}")
    return lo, hi


def _medium_factory(model: Any, lo: float, hi: float) -> Callable[[float], Medium]:
    if isinstance(model, Medium):
        if model.n_regions != 2:
            raise ValueError("medium_model: a Medium must be a half-space (its ground's eps' is "
                             f"what autofocus finds); this one has {model.n_regions - 1} ground "
                             "layers: pass a function eps' -> Medium that says which one varies")
        z0, e = model.z_interfaces[0], complex(model.eps[1])
        tan = e.imag / e.real if e.real > 0 else 0.0

        def make(eps: float) -> Medium:
            return Medium((z0,), (1.0, complex(eps, eps * tan)), model.polarization)

        return make
    if not callable(model):
        raise ValueError("medium_model must be a half-space Medium or a function eps' -> Medium, "
                         f"got {type(model).__name__}")

    def checked(eps: float) -> Medium:
        m = model(eps)
        if not isinstance(m, Medium) or m.is_free_space:
            raise ValueError(f"medium_model({eps:g}) must return a Medium with a ground, got "
                             f"{m!r}")
        return m

    surfaces = {checked(lo).z_interfaces[0], checked(hi).z_interfaces[0]}
    if len(surfaces) != 1:
        raise ValueError("medium_model must keep the ground surface at one range for every eps' "
                         f"(got {sorted(surfaces)} m)")
    return checked


def _check_glare(glare: Any) -> tuple[float, float]:
    try:
        g, s = (float(v) for v in glare)
    except (TypeError, ValueError):
        raise ValueError("glare must be True, None, or (eps', sigma) of an independent "
                         f"estimate, got {glare!r}") from None
    if not (np.isfinite(g) and g >= 1 and np.isfinite(s) and s > 0):
        raise ValueError(f"glare = (eps', sigma) needs eps' >= 1 and sigma > 0, got {glare!r}")
    return g, s


def _glare_estimate(hologram: Hologram, medium: Medium) -> tuple[Hologram, tuple[float, float]]:
    from .glare import suppress_surface

    if hologram.monostatic or hologram.source is None or hologram.is_wideband:
        raise ValueError("glare=True needs a single-frequency receiver-array hologram with its "
                         "source (the glare is the source's reflection); remove the glare "
                         "yourself and pass glare=(eps', sigma), or glare=None")
    clean, rep = suppress_surface(hologram, medium, None, "image_source")
    return clean, (float(rep.eps.real), float(rep.eps_std[0]))


def _combine(e_f: float, interval: tuple[float, float], glare: tuple[float, float],
             q: float) -> tuple[float, tuple[float, float], str]:
    s_f = (interval[1] - interval[0]) / (2 * q)
    e_g, s_g = glare
    w_f, w_g = 1 / s_f**2, 1 / s_g**2
    est = (w_f * e_f + w_g * e_g) / (w_f + w_g)
    s = 1 / np.sqrt(w_f + w_g)
    gap = abs(e_f - e_g) / np.hypot(s_f, s_g)
    note = ("focus and glare combined by inverse variance" if gap < 3 else
            f"focus and glare combined, but they disagree by {gap:.1f} sigma: the glare sees the "
            "top of the ground, the focus the path down to the object (layered ground?)")
    return float(est), (float(est - q * s), float(est + q * s)), note
