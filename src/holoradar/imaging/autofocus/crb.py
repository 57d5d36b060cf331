"""The Cramér-Rao bound of eps' at the autofocus estimate, and why an interval exceeds it.

The data are the model's samples ``m(theta)`` (every element and frequency) plus complex
circular Gaussian noise of variance ``sigma^2`` per sample. The Fisher information of
the real parameters ``theta`` is

    I = (2 / sigma^2) Re(J^H J),    J = dm/dtheta,

and the bound on eps' is ``sqrt([I^-1]_{eps', eps'})``. ``theta`` holds every parameter
the fit fits: eps', the object's x, y and range (a line's azimuth and length too), and
its complex amplitude as two real parameters (its log-modulus and phase: the same span
as its real and imaginary parts, so the same bound), one amplitude per frequency when
each frequency keeps its own. A phase-only fit's model is ``a |h| g/|g|``: its
derivatives lie along the phase, and its amplitude has a phase only.

``J`` comes from central differences of the fit's own model, with ``a`` held at the fit.
The steps: eps' by ``1e-4 eps'`` (less where that would move the two-way phase in the
ground by more than 6 mrad: deep objects), the positions and a line's length by
``lambda/400`` in the ground at the highest frequency (30 mrad of two-way phase), a
line's azimuth by as much at its ends. A central difference's truncation error is about
(phase per step)^2 / 6 of the derivative, 6e-6 for eps' and 2e-4 for the positions; the
model's interpolation noise (3e-8 of the field) over the change a step makes (6e-3 and
3e-2 of it) is 5e-6 and 1e-6. Measured: steps ten times shorter change the bound by
3e-5 at most; an eps' step ten times longer by 2e-3, position steps of 1 mm (26 times
longer) by 1e-2. The cost: ten point responses and the tables of Green's functions at
eps' +- its step (5 ms at one frequency, 18 ms at four, for the paper's 16 x 16 array).

Noise: ``sigma^2 = 2 s_w^2``, ``s_w^2 = s^2 (1 - E_err/R)`` the white part of the
residual's variance per real component (``s^2 = R / dof``, the interval's, less the
share ``E_err/R`` of its smooth part, model error): the noise's own level. The sandwich
factor phi is left out. With it the bound would be the variance of the white-noise fit
under the residual's colour, not a bound; and phi, like ``E_err``, measures how far the
fit is from the bound's assumptions (the right model, white noise). Left out, they show
as an interval wider than the bound, which :func:`crb_note` then explains.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...data.hologram import C0

if TYPE_CHECKING:
    from .search import Search

__all__ = ["Bound", "crb_note", "eps_bound", "fd_steps", "jacobian"]

# Widths: the interval is noted when wider than this times the bound's (1.5 x 3.92 sigma).
NOTE_RATIO = 1.5
# Lack of fit: the smooth (model-error) share of the residual, or phi, above these.
_LACK_SHARE = 0.1
_LACK_PHI = 1.5


@dataclass(frozen=True)
class Bound:
    """The Cramér-Rao bound of eps' and how eps' trades with the nuisance parameters.

    Attributes
    ----------
    std : float
        ``sqrt([I^-1]_{eps', eps'})``: the bound's standard deviation of eps'.
    names : tuple of str
        The nuisance parameters, in the order of ``correlation``.
    correlation : ndarray
        The correlation coefficient of eps' with each nuisance parameter (from ``I^-1``).
    noise_share : float
        The share of the residual's energy that is white noise (1 - E_err / R).
    """

    std: float
    names: tuple[str, ...]
    correlation: np.ndarray
    noise_share: float = 1.0

    def trades(self, at_least: float = 0.9) -> list[tuple[str, float]]:
        """The nuisance parameters eps' trades with: the most correlated one, and up to
        two more whose correlations' moduli are ``at_least`` too, by modulus."""
        order = np.argsort(-np.abs(self.correlation))
        return [(self.names[i], float(self.correlation[i])) for j, i in enumerate(order[:3])
                if j == 0 or abs(self.correlation[i]) >= at_least]


def fd_steps(search: Search, eps: float, z: float) -> tuple[float, float]:
    """The central differences' steps: eps' (relative) and positions (metres).

    Parameters
    ----------
    search : Search
        The search (its hologram and the ground's surface range ``z0``).
    eps, z : float
        The estimate's eps' and range (metres).

    Returns
    -------
    (float, float)
        The relative step of eps' (1e-4, less for deep objects: 6 mrad of two-way phase
        in the ground) and the position step, ``lambda/400`` in the ground at the
        highest frequency (metres).
    """
    lam_m = C0 / float(np.max(search.hologram.frequencies)) / np.sqrt(eps)
    depth = max(z - search.z0, lam_m)
    # Two-way phase 2 k_m depth, k_m ~ sqrt(eps'): d phase = k_m depth d(eps')/eps'.
    rel = min(1e-4, 0.006 / (2 * np.pi / lam_m * depth))
    return rel, lam_m / 400


def jacobian(search: Search, eps: float, z: float, xy: np.ndarray, *,
             rel_eps: float | None = None,
             dpos: float | None = None) -> tuple[np.ndarray, tuple[str, ...]]:
    """The model's derivatives at a fit: eps' first, then the nuisance parameters.

    Parameters
    ----------
    search : Search
        The search (its model ``search.pr``).
    eps, z : float
        The fit's eps' and range (metres).
    xy : ndarray
        Its lateral position (x, y), metres (a line's azimuth in radians and length in
        metres after).
    rel_eps, dpos : float, optional
        The steps of eps' (relative) and of the positions (metres); default
        :func:`fd_steps`.

    Returns
    -------
    J : ndarray
        Complex, (samples, parameters): the derivative of every sample of the fitted
        model with respect to eps' (per unit eps'), x, y, range (per metre), a line's
        azimuth (per radian) and length (per metre), and each amplitude's log-modulus
        and phase.
    names : tuple of str
        The nuisance parameters' names (columns 1...).
    """
    pr = search.pr
    xy = np.asarray(xy, float)
    r0, d0 = fd_steps(search, eps, z)
    de = (r0 if rel_eps is None else rel_eps) * eps
    dp = d0 if dpos is None else dpos
    _, g, a = pr.residual(eps, z, xy)

    def model(e: float, zz: float, p: np.ndarray) -> np.ndarray:
        return pr.model(pr.response(e, zz, p), a).ravel()

    cols = [(model(eps + de, z, xy) - model(eps - de, z, xy)) / (2 * de)]
    names = ["x", "y", *getattr(pr, "shape_names", ("the line's azimuth",
                                                     "the line's length"))][:len(xy)]
    # A line's azimuth: its ends move by dp; a sphere's radius by dp.
    steps = [dp, dp, dp / (xy[3] / 2), dp] if len(xy) > 3 else [dp] * len(xy)
    for i, step in enumerate(steps):
        dv = np.zeros(len(xy))
        dv[i] = step
        cols.append((model(eps, z, xy + dv) - model(eps, z, xy - dv)) / (2 * step))
    cols.append((model(eps, z + dp, xy) - model(eps, z - dp, xy)) / (2 * dp))
    names.append("the range")
    m0 = pr.model(g, a)
    nf = m0.shape[0]
    groups = [np.ones(nf, bool)] if pr.coherent else [np.arange(nf) == f for f in range(nf)]
    freqs = search.hologram.frequencies
    for f, sel in enumerate(groups):
        t = np.where(sel[:, None], m0, 0).ravel()
        at = "" if pr.coherent else f" at {freqs[f] / 1e9:.4g} GHz"
        if not pr.phase_only:
            cols.append(t)                       # d m / d log|a|
            names.append(f"the amplitude's modulus{at}")
        cols.append(1j * t)                      # d m / d arg a
        names.append(f"the amplitude's phase{at}")
    return np.stack(cols, axis=1), tuple(names)


def eps_bound(search: Search, eps: float, z: float, xy: np.ndarray,
              stats: dict[str, float], *, rel_eps: float | None = None,
              dpos: float | None = None, nuisance: bool = True) -> Bound:
    """The Cramér-Rao bound of eps' at a fit, with the noise the fit leaves.

    Parameters
    ----------
    search : Search
        The search (its model ``search.pr``).
    eps, z, xy
        The fit (as :func:`jacobian`).
    stats : dict
        :func:`~.fit_statistics.fit_statistics` at the fit: ``s2`` (the residual's
        variance per real component) and ``model_error`` (its smooth part's energy).
    rel_eps, dpos : float, optional
        The finite differences' steps (:func:`jacobian`).
    nuisance : bool
        Fit the nuisance parameters too (True, the bound of the fit); False gives the
        bound with them known (only to show what they cost).

    Returns
    -------
    Bound
        ``std`` the bound's standard deviation of eps', and eps' 's correlations.
    """
    J, names = jacobian(search, eps, z, xy, rel_eps=rel_eps, dpos=dpos)
    r, _, _ = search.pr.residual(eps, z, xy)
    R = float(np.vdot(r, r).real)
    share = 1.0 if R <= 0 else float(np.clip(1 - stats["model_error"] / R, 1e-6, 1.0))
    # Complex noise of variance sigma^2 per sample: s^2 per real component, its white part.
    sigma2 = 2 * stats["s2"] * share
    info = 2 / sigma2 * (J.conj().T @ J).real
    if not nuisance:
        return Bound(float(np.sqrt(1 / info[0, 0])), (), np.zeros(0), share)
    # Inverted with the columns scaled to unit norm (their units differ by 1e4).
    d = 1 / np.sqrt(np.diag(info))
    cov = np.linalg.pinv(info * np.outer(d, d), rcond=1e-12, hermitian=True) * np.outer(d, d)
    sd = np.sqrt(np.diag(cov))
    return Bound(float(sd[0]), names, cov[0, 1:] / (sd[0] * sd[1:]), share)


def crb_note(bound: Bound, interval: tuple[float, float], confidence_q: float,
             stats: dict[str, float], focus_fraction: float) -> str:
    """Why the interval is wider than ``NOTE_RATIO`` times the bound's; ``""`` when not.

    Parameters
    ----------
    bound : Bound
        The bound at the estimate.
    interval : (float, float)
        The focus's interval of eps'.
    confidence_q : float
        The normal quantile of its confidence (1.96 for 0.95).
    stats : dict
        :func:`~.fit_statistics.fit_statistics` at the estimate (``phi``).
    focus_fraction : float
        The focus fraction at the estimate.

    Returns
    -------
    str
        Lack of fit (a residual with a smooth part, or one that looks like a change of
        eps') and the nuisance parameters eps' trades with most, with their correlation
        coefficients.

    Examples
    --------
    >>> b = Bound(0.01, ("x", "the range"), np.array([0.1, -0.97]))
    >>> print(crb_note(b, (3.9, 4.1), 1.96, {"phi": 1.0}, 0.99))
    interval 5.1 x the bound's width (2 x 1.96 x 0.01): eps' trades with the range (-0.97)
    """
    ratio = (interval[1] - interval[0]) / (2 * confidence_q * bound.std)
    if not ratio > NOTE_RATIO:
        return ""
    parts = []
    smooth = 1 - bound.noise_share
    if smooth > _LACK_SHARE or stats["phi"] > _LACK_PHI:
        # A perfect model would leave the noise alone: the white share of the residual.
        left = 1 - focus_fraction
        parts.append(f"lack of fit (the object leaves {left:.2g} of the energy unexplained, "
                     f"the noise {left * bound.noise_share:.2g}: {100 * smooth:.0f}% of the "
                     f"residual is smooth across the aperture; sandwich factor "
                     f"{stats['phi']:.2g})")
    trades = ", ".join(f"{name} ({rho:.{2 if abs(rho) < 0.99 else 4}f})"
                          for name, rho in bound.trades())
    parts.append(f"eps' trades with {trades}")
    return (f"interval {ratio:.3g} x the bound's width (2 x {confidence_q:.3g} x "
            f"{bound.std:.2g}): " + "; ".join(parts))
