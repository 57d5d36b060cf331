"""Noise, detection and the sandwich factor of a fit: what its interval and test need.

At a fit (eps', range, lateral position) the residual gives the noise level; the
matched filter's output over it tests the object against noise alone, and the
sandwich factor ``phi`` weighs the residual's power where a change of eps' acts
(the package's notes).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..._lazy import lazy_module
from ...data.noise import smooth_residual_energy

if TYPE_CHECKING:
    from .search import Search

sfft = lazy_module("scipy.fft")
_special = lazy_module("scipy.special")

__all__ = ["fit_statistics", "no_object_reason"]

_FALSE_ALARM = 1e-3   # detection: chance that noise alone passes
_MODEL_PRECISION = 1e-4  # relative amplitude accuracy of the model (quadrature, splines)


def fit_statistics(search: Search, eps: float, z: float, xy: np.ndarray) -> dict[str, float]:
    """Noise variance, detection statistic and sandwich factor at a fit.

    Parameters
    ----------
    search : Search
        The search (its model, number of trials, wavelength and hologram).
    eps, z : float
        The fit's eps' and range (metres).
    xy : ndarray
        Its lateral position (x, y) in metres (a line's azimuth and length after).

    Returns
    -------
    dict
        ``s2`` the residual's variance per real component, ``detection`` the matched
        filter's output over the noise level and ``threshold`` the level noise alone
        exceeds with chance 1e-3 over all the trials, ``phi`` the sandwich factor
        (>= 1), ``residual_scale`` (2 for a phase-only fit, else 1),
        ``model_error`` the energy of the residual's smooth part and ``unmodelled``
        the energy of what the model knowingly leaves out (a sphere's second bounce
        off the surface; 0 for a point or a line).
    """
    pr = search.pr
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
    threshold = float(_special.gammainccinv(n_amp, _FALSE_ALARM / search.trials))
    # Residual variance per real component: a phase-only residual has one real
    # component per sample (along the phase), a field residual two.
    r, g, a = pr.residual(eps, z, xy)
    R = float(np.vdot(r, r).real)
    dof = (n_complex if pr.phase_only else 2 * n_complex) - 4 - (1 if pr.phase_only else 2) \
        * n_amp
    s2 = max(R / max(dof, 1), floor)
    phi = _sandwich(search, eps, z, xy, g, a, r, s2)
    return dict(s2=s2, detection=float(detection), threshold=threshold,
                phi=max(1.0, phi), residual_scale=2.0 if pr.phase_only else 1.0,
                model_error=smooth_residual_energy(r.reshape(search.hologram.data.shape)),
                unmodelled=float(pr.unmodelled_energy(eps, z, xy, g, a)))


def no_object_reason(stats: dict[str, float]) -> str:
    """Why eps' is not determinable when the detection is below its threshold."""
    return (f"no compact object stands out of the noise (matched filter "
            f"{stats['detection']:.3g} x the noise level; noise alone reaches "
            f"{stats['threshold']:.3g})")


def _sandwich(search: Search, eps: float, z: float, xy: np.ndarray, g: np.ndarray,
              a: np.ndarray, r: np.ndarray, s2: float) -> float:
    """The sandwich factor phi (before its floor of 1): the residual ``r``'s power where
    the model's derivative in eps' (orthogonal to those in amplitude and position) lies,
    over white noise's of variance ``s2``; ``g`` and ``a`` the fit's response and
    amplitude."""
    pr = search.pr

    def model(e: float, zz: float, p: np.ndarray) -> np.ndarray:
        return pr.model(pr.response(e, zz, p), a)

    # Sandwich: tangent vectors of the model in (amplitude, x, y, z) and eps'.
    de, dz, dx = 1e-3 * eps, search.lam / np.sqrt(eps) / 40, search.lam / 400
    m0 = pr.model(g, a)
    d_eps = (model(eps + de, z, xy) - model(eps - de, z, xy)) / (2 * de)
    groups = [np.ones(m0.shape[0], bool)] if pr.coherent else \
        [np.arange(m0.shape[0]) == f for f in range(m0.shape[0])]
    tangents = []
    for sel in groups:  # each amplitude: its phase, and for a field fit its modulus
        t = np.where(sel[:, None], m0, 0)
        tangents += [1j * t] if pr.phase_only else [t, 1j * t]
    # x, y, and a line's azimuth (1e-3 rad) and length, or a sphere's radius (xy of
    # three: 1e-3 of it, at most 1 mm, so that a small sphere's radius stays > 0).
    third = min(1e-3, 1e-3 * abs(float(xy[2]))) if len(xy) == 3 and xy[2] != 0 else 1e-3
    steps = [dx, dx, third, dx][:len(xy)]
    for i, step in enumerate(steps):
        dv = np.zeros(len(xy))
        dv[i] = step
        try:
            tangents.append((model(eps, z, xy + dv) - model(eps, z, xy - dv)) / (2 * step))
        except ValueError:
            # Out of the model's domain on one side (a radius at 0): one-sided.
            tangents.append((model(eps, z, xy + dv) - m0) / step)
    tangents.append((model(eps, z + dz, xy) - model(eps, z - dz, xy)) / (2 * dz))
    T = np.stack([np.concatenate([t.real.ravel(), t.imag.ravel()]) for t in tangents], 1)
    d = np.concatenate([d_eps.real.ravel(), d_eps.imag.ravel()])
    coef, *_ = np.linalg.lstsq(T, d, rcond=None)
    dp = d - T @ coef
    d_perp = (dp[:d.size // 2] + 1j * dp[d.size // 2:]).reshape(search.hologram.data.shape)
    D = np.abs(sfft.fftn(d_perp, norm="ortho")) ** 2
    Rk = np.abs(sfft.fftn(r.reshape(search.hologram.data.shape), norm="ortho")) ** 2
    # White residual: E|R_k|^2 = (real components per sample) * s^2.
    per = 1 if pr.phase_only else 2
    return float(np.sum(D * Rk) / (per * s2 * np.sum(D))) if np.sum(D) > 0 else 1.0
