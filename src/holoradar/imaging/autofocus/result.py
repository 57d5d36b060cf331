"""What :func:`~holoradar.autofocus` returns: the estimate, its interval, and how it was made."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...physics.medium import Medium
from .interval import quantile

__all__ = ["AutofocusResult"]


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
    eps_crb : float or None
        The Cramér-Rao bound's standard deviation of eps' at the focus's estimate: the
        fitted model's Fisher information (eps', position, range and amplitude all
        unknown) with the noise the fit leaves (:mod:`.crb`). ``None`` when the focus
        gives no estimate (also when eps' is the glare's alone).
    crb_note : str
        Why the focus's interval is more than 1.5 times the bound's width
        (``2 q eps_crb``): lack of fit, and the parameters eps' trades with most;
        ``""`` when it is not.
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
    sphere_radius : float or None
        The radius of the conducting sphere fitted (``target="sphere"``, or a point fit
        that a sphere explained far better), metres; None for a point or a line.
    model_note : str
        Why the object was fitted as a sphere when a point was asked for (the
        share of the energy each left unexplained); ``""`` otherwise.

    Examples
    --------
    >>> from holoradar.imaging.autofocus import AutofocusResult
    >>> res = AutofocusResult(4.02, (3.76, 4.32), True, "from the focus", 0.95,
    ...                       eps_focus=4.02, handle="one frequency: the wave front's shape")
    >>> print(res)
    eps' = 4.02 (95% interval 3.76 .. 4.32) (one frequency: the wave front's shape)
    >>> round(res.std, 3)
    0.143
    >>> print(AutofocusResult(None, None, False, "no object", 0.95))
    eps' not determinable: no object
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
    eps_crb: float | None = None
    crb_note: str = ""
    sphere_radius: float | None = None
    model_note: str = ""

    @property
    def std(self) -> float | None:
        """Equivalent 1-sigma of eps' (half the interval over the normal quantile)."""
        if self.eps_interval is None:
            return None
        return (self.eps_interval[1] - self.eps_interval[0]) / (2 * quantile(self.confidence))

    def __str__(self) -> str:
        if not self.determinable:
            return f"eps' not determinable: {self.reason}"
        lo, hi = self.eps_interval
        # Enough decimals that the interval's width shows (2 at least).
        d = max(2, 1 - int(np.floor(np.log10(max(hi - lo, 1e-12)))))
        text = (f"eps' = {self.eps:.{d}f} ({100 * self.confidence:.0f}% interval {lo:.{d}f} .. "
                f"{hi:.{d}f}")
        if self.eps_crb is not None:   # what the data could tell at best, beside it
            text += f"; Cramér-Rao bound's sigma {self.eps_crb:.2g}"
        text += ")"
        if self.position is not None and self.depth is not None:
            what = ("object" if self.sphere_radius is None else
                    f"a conducting sphere of radius {1e3 * self.sphere_radius:.1f} mm")
            text += (f"; {what} at range {self.position[2]:.4g} m, {self.depth:.4g} m below "
                     "the surface")
        return f"{text} ({self.handle if self.eps_focus is not None else self.reason})"
