"""I/Q gain and phase imbalance of the quadrature demodulator, estimated blind.

Model (per sample, after the DC offset is removed): a signal ``s = A*exp(i*t)``
arrives as

    I = A*cos(t),        Q = g*A*sin(t + phi),

``g`` the Q channel's gain relative to I and ``phi`` its phase error, radians: a
widely linear distortion ``I + iQ = alpha*s + beta*conj(s)`` with
``alpha = (1 + g*exp(i*phi))/2`` and ``beta = (1 - g*exp(-i*phi))/2`` (an image
``|beta/alpha|^2``: -20 dB for g = 1.15, phi = 8 degrees).

Estimate: when the phases t are spread uniformly and independently of the
amplitudes (a *circular* population: random element phases, many scenes or
frequencies, receiver noise), ``E[I^2] = <A^2>/2``, ``E[Q^2] = g^2<A^2>/2`` and
``E[I*Q] = g*sin(phi)<A^2>/2``, so

    g = sqrt(sum Q^2 / sum I^2),    sin(phi) = sum I*Q / sqrt(sum I^2 * sum Q^2).

Standard error. To first order the errors come from the samples' finite
improperness: with ``w = cos(phi)*exp(i*phi)*sum(s^2)/sum(|s|^2)``,

    dg/g = -Re(w),     dphi = Im(w),

so for N independent samples

    SE(g)/g = SE(phi) = cos(phi) * sqrt(kappa/(2N)),   kappa = <A^4>/<A^2>^2

(kappa = 1 for a constant amplitude, 2 for Gaussian noise): 1.6 degrees for the
768 samples of a 16 x 16 array at 3 frequencies, 0.3 degrees for 20000. The
standard errors reported are the sandwich (cluster-robust) estimate of the same
variance from the corrected samples z: ``Var(Re or Im of sum e^{i phi} z^2)``
summed over ``groups`` of samples that may share a phase (an element's samples
at several frequencies or in several references share its gain's phase; repeats
of one static scene share everything and should be averaged first). Each
sample its own group, it is the kappa formula above.

The correction makes ``sum z^2 = 0`` exactly, so each group's corrected sum is,
to first order, ``x_e - h_e*X``: its true sum less its share ``h_e`` of the
samples' power times the true total X. For independent groups of variances v_e
(total V) that gives ``E|x^_e|^2 = (1 - 2 h_e) v_e + h_e^2 V``, solved for V:

    V = sum(|x^_e|^2/(1 - 2 h_e)) / (1 + sum(h_e^2/(1 - 2 h_e))),

``n/(n - 1)`` times the plain sum when the n groups hold equal power, more when
a few hold most of it (an empty scene, whose horn lights the nearest elements:
there the plain sum was 10% low, this one 5%). The variance then rests on few
groups: ``(sum |x^_e|^2)^2 / sum |x^_e|^4``, the *effective* number of groups,
says on how many. When it is small (about 5 for an empty scene and a plate on a
16 x 16 array, against 100 for a plate) the standard error is itself uncertain,
and +-1.96 standard errors covered 91-92% of the errors rather than 95%.

What the standard errors assume: the groups' phases independent and uniform
(random element gains). Other element phases change the actual scatter, and the
data cannot tell (the corrected samples are proper by construction, so the
sandwich sees the independent-phase variance). Measured in
``docs/calibration.md``: phases shared by blocks of 4 x 4 elements (cables) make
the stated errors 1.1-1.85x the scatter (conservative); a linear phase ramp or
a smooth random phase field leave them within 0.97-1.15x. Groups that follow
the structure (``groups`` = the blocks) brought one plate's from 1.33x to 0.98x,
though with only 16 groups the standard error is itself less certain.

The estimate does not see the I/Q sign: a device that delivers ``I - iQ`` looks
like one with phase error ``-phi`` delivering ``I + iQ`` of the conjugate field, so
``phi`` here is the phase error of Q *as delivered*; the sign is found separately
(:mod:`.sign`).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

__all__ = ["IQImbalance", "correct_iq", "iq_imbalance", "iq_residual"]


class IQImbalance(NamedTuple):
    """Estimated Q gain and phase error, their standard errors, and the sample data."""

    gain: float
    """Q channel gain relative to I, g."""
    phase: float
    """Q channel phase error phi, radians."""
    stderr_gain: float
    """Standard error of ``gain`` (about ``g*cos(phi)*sqrt(kappa/(2N))``)."""
    stderr_phase: float
    """Standard error of ``phase``, radians (about ``cos(phi)*sqrt(kappa/(2N))``)."""
    n_samples: int
    """N, the number of samples used."""
    kurtosis: float
    """kappa = <|s|^4>/<|s|^2>^2 of the corrected samples."""
    effective_groups: float = np.nan
    """``(sum |x_e|^2)^2 / sum |x_e|^4`` of the groups' improperness sums x_e: how many
    groups the standard errors rest on (they are themselves uncertain when it is small)."""


def iq_imbalance(i: Any, q: Any, groups: Any = None) -> IQImbalance:
    """Blind estimate of the Q channel's gain and phase error from many samples.

    Parameters
    ----------
    i, q : array_like, real, one shape
        DC-free raw I and Q samples with spread phases (every element of a
        reference, a survey's frames, dark frames of front-end noise); all
        samples are pooled.
    groups : array_like of int, the shape of ``i``, optional
        Labels of samples that may share a phase (e.g. the element index), for
        the standard errors only; default: every sample independent.

    Returns
    -------
    IQImbalance
        ``gain`` g, ``phase`` phi (radians), their standard errors (see the module
        text), the number of samples, their kurtosis and the effective number of
        groups the standard errors rest on.

    Raises
    ------
    ValueError
        Fewer than 2 samples, a dead channel, I and Q (nearly) in phase, or one
        group holding half the samples' power or more.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> s = np.exp(2j * np.pi * rng.random(20000))
    >>> i, q = s.real, 1.15 * np.imag(s * np.exp(1j * np.radians(8)))
    >>> est = iq_imbalance(i, q)
    >>> round(est.gain, 2), round(est.kurtosis, 3), round(float(np.degrees(est.stderr_phase)), 2)
    (1.15, 1.0, 0.28)
    >>> bool(abs(est.phase - np.radians(8)) < 3 * est.stderr_phase)
    True
    """
    ia, qa = np.asarray(i, dtype=float).ravel(), np.asarray(q, dtype=float).ravel()
    if ia.shape != qa.shape or ia.size < 2:
        raise ValueError(f"i and q must hold one number of samples (at least 2), got "
                         f"{np.shape(i)} and {np.shape(q)}")
    if not (np.all(np.isfinite(ia)) and np.all(np.isfinite(qa))):
        raise ValueError("i and q must be finite")
    sii, sqq, siq = float(ia @ ia), float(qa @ qa), float(ia @ qa)
    if sii == 0 or sqq == 0:
        raise ValueError("the I or the Q channel is identically zero: no imbalance can be "
                         "estimated (a dead channel?)")
    g = np.sqrt(sqq / sii)
    sin_phi = siq / np.sqrt(sii * sqq)
    if abs(sin_phi) > 0.99:
        raise ValueError(f"I and Q are nearly in phase (sin(phi) = {sin_phi:.4f}): the samples "
                         "do not spread over phases, or Q is a copy of I")
    phi = float(np.arcsin(sin_phi))
    z = correct_iq(ia, qa, g, phi)
    p2 = np.abs(z) ** 2
    kappa = float(np.mean(p2 * p2) / np.mean(p2) ** 2)
    # Sandwich estimate of Var(w): the corrected samples' improperness per group.
    x = np.exp(1j * phi) * z * z
    if groups is None:
        sums, power, n_groups = x, p2, x.size
    else:
        lab = np.asarray(groups)
        if lab.shape != np.shape(i) or not np.issubdtype(lab.dtype, np.integer):
            raise ValueError(f"groups must be integer labels of shape {np.shape(i)}, got "
                             f"{lab.dtype} {lab.shape}")
        _, inv = np.unique(lab.ravel(), return_inverse=True)
        n_groups = int(inv.max()) + 1
        sums = (np.bincount(inv, x.real, n_groups) + 1j * np.bincount(inv, x.imag, n_groups))
        power = np.bincount(inv, p2, n_groups)
    if n_groups < 2:
        raise ValueError("the samples form a single group: no standard error can be estimated")
    h = power / power.sum()
    if h.max() >= 0.5:
        # The correction then removes most of that group's own improperness: its
        # variance cannot be told from what is left (module text).
        raise ValueError(f"one group holds {h.max():.0%} of the samples' power (half or "
                         "more): the imbalance rests on it alone and no standard error can be "
                         "estimated; use samples that spread the power over many groups")
    # Undo the leverage of the exact correction (module text): sum z^2 = 0 by construction.
    d = 1 - 2 * h
    lev = 1 / (1 + np.sum(h * h / d))
    scale = np.cos(phi) / p2.sum()
    se_gain = float(g * scale * np.sqrt(lev * np.sum(sums.real ** 2 / d)))
    se_phase = float(scale * np.sqrt(lev * np.sum(sums.imag ** 2 / d)))
    a = np.abs(sums) ** 2
    n_eff = float(a.sum() ** 2 / np.sum(a * a)) if a.any() else float(n_groups)
    return IQImbalance(float(g), phi, se_gain, se_phase, int(ia.size), kappa, n_eff)


def correct_iq(i: Any, q: Any, gain: Any, phase: Any) -> np.ndarray:
    """Undo a Q gain and phase error: the complex samples ``I + i*Qc``.

    ``Qc = (Q/g - I*sin(phi))/cos(phi)``, exact inverse of the model in the module
    text (``I = A cos t``, ``Q = g A sin(t + phi)`` gives ``I + i*Qc = A exp(i t)``).

    Parameters
    ----------
    i, q : array_like, real
        DC-free raw channels.
    gain, phase : float or array_like
        g and phi (radians), broadcast against ``i`` (e.g. shape (nf, 1, 1) for
        one pair per frequency).

    Returns
    -------
    ndarray, complex

    Examples
    --------
    >>> t = np.array([0.3, 1.2])
    >>> z = correct_iq(np.cos(t), 1.15 * np.sin(t + 0.1), 1.15, 0.1)
    >>> bool(np.allclose(z, np.exp(1j * t)))
    True
    """
    ia, qa = np.asarray(i, dtype=float), np.asarray(q, dtype=float)
    g, phi = np.asarray(gain, dtype=float), np.asarray(phase, dtype=float)
    return ia + 1j * ((qa / g - ia * np.sin(phi)) / np.cos(phi))


def iq_residual(gain: float, phase: float, gain_used: float, phase_used: float
                ) -> tuple[complex, complex]:
    """What remains after correcting a ``(gain, phase)`` device with ``(gain_used, phase_used)``.

    The corrected sample is ``a*s + b*conj(s)`` for the true signal s; ``|b/a|`` is
    the residual image (0 when the correction is exact).

    Returns
    -------
    (a, b) : complex

    Examples
    --------
    >>> a, b = iq_residual(1.15, np.radians(8), 1.0, 0.0)    # no correction at all
    >>> round(float(20 * np.log10(abs(b / a))), 1)
    -20.1
    >>> iq_residual(1.15, 0.1, 1.15, 0.1)
    ((1+0j), 0j)
    """
    u = gain / gain_used * np.cos(phase) / np.cos(phase_used)
    v = (gain / gain_used * np.sin(phase) - np.sin(phase_used)) / np.cos(phase_used)
    a, b = (1 + u + 1j * v) / 2, (1 - u + 1j * v) / 2
    return complex(a), complex(b)
