"""Receiver noise of a hologram, estimated from the part of its spectrum no scene fills.

A scene at range z or beyond reaches the aperture only through the components it
can radiate: those with ``kappa^2 = p^2 + q^2 > k^2`` are evanescent in the air and
arrive damped by ``exp(-sqrt(kappa^2 - k^2) z)``. Where the element pitch samples
such components (pitch below half a wavelength), the bins beyond
``sqrt(k^2 + (ln(1000)/z)^2)`` (signal damped 60 dB) hold receiver noise only: white
noise of variance sigma^2 per element puts ``sigma^2 sum(w^2)`` into every bin of
the unnormalised FFT of the hologram tapered by a window w (Hann, so that the
aperture's truncated edges leak no signal there).
"""

from __future__ import annotations

import numpy as np

from .._lazy import lazy_module
from .hologram import Hologram

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

__all__ = ["estimate_snr", "smooth_residual_energy"]

_DAMPING = np.log(1000.0)  # 60 dB: the scene's evanescent share left in the noise bins
_MIN_BINS = 16


def estimate_snr(hologram: Hologram, z_min: float) -> float | None:
    """Signal-to-noise ratio of a hologram, dB, or None where it cannot be estimated.

    Parameters
    ----------
    hologram : Hologram
        One frame or a stack (..., ny, nx); the estimate pools all frames.
    z_min : float
        Range in metres beyond which all sources of the field lie (the nearest
        object, or the ground surface). Components evanescent in the air and damped
        by 60 dB over it are taken as noise.

    Returns
    -------
    float or None
        ``10*log10(mean |signal|^2 / sigma^2)`` per element (the window's leakage
        limits it to about 55 dB); None when fewer than 16 spectral bins lie
        beyond the damped band (pitch not fine enough, or ``z_min`` too small).

    Examples
    --------
    >>> import holoradar as hr
    >>> scene = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))], source=hr.PlaneWave())
    >>> h = hr.simulate(scene, hr.Aperture.grid(64, 0.005), 9.9e9, snr_db=25, seed=1)
    >>> round(estimate_snr(h, 0.3))
    25
    >>> estimate_snr(hr.simulate(scene, hr.Aperture.grid(16, 0.025), 9.9e9), 0.3) is None
    True
    """
    if not np.isfinite(z_min) or z_min <= 0:
        return None
    ny, nx = hologram.data.shape[-2:]
    dx, dy = hologram.pitch
    p = 2 * np.pi * sfft.fftfreq(nx, dx)
    q = 2 * np.pi * sfft.fftfreq(ny, dy)
    # The largest wavenumber any frequency carries (twice it for a transceiver's round trip).
    k = float(hologram.wavenumbers.max()) * (2 if hologram.monostatic else 1)
    noise_bins = (q[:, None] ** 2 + p[None, :] ** 2) > k * k + (_DAMPING / z_min) ** 2
    if noise_bins.sum() < _MIN_BINS:
        return None
    # A Hann window keeps the aperture's truncated edges from leaking the scene's
    # spectrum into the noise bins; white noise then puts sigma^2 * sum(w^2) there.
    w = np.outer(np.hanning(ny + 2)[1:-1], np.hanning(nx + 2)[1:-1])
    H = sfft.fft2(hologram.data * w, axes=(-2, -1))
    sigma2 = float(np.mean(np.abs(H[..., noise_bins]) ** 2)) / float(np.sum(w * w))
    total = float(np.mean(np.abs(hologram.data) ** 2))
    if sigma2 <= 0:
        return np.inf
    signal = max(total - sigma2, 1e-3 * sigma2)  # below the noise: report -30 dB
    return float(10 * np.log10(signal / sigma2))


def smooth_residual_energy(r: np.ndarray) -> float:
    """Energy of the part of a residual that is smooth from element to element.

    Receiver noise is white: neighbouring elements' residuals are uncorrelated. A
    model error (an object that is not a point, a vector field, an inexact ground)
    varies smoothly across the aperture, so the lag-one autocovariance ``C1`` of
    the residual measures its power: the energy ``sum |r|^2 * |C1|/C0``, counted
    only when ``|C1|/C0`` exceeds three times its spread for white noise
    (``1/sqrt(pairs)``). ``r`` is (..., ny, nx): neighbours along the last two axes.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> smooth_residual_energy(rng.standard_normal((32, 32)))     # white: no model error
    0.0
    >>> x = np.linspace(0, 1, 32)
    >>> round(float(smooth_residual_energy(np.outer(x, x)) / np.sum(np.outer(x, x) ** 2)), 2)
    0.98
    """
    c0 = float(np.mean(np.abs(r) ** 2))
    if c0 == 0:
        return 0.0
    pairs = [(r[..., :, 1:], r[..., :, :-1]), (r[..., 1:, :], r[..., :-1, :])]
    n = sum(a.size for a, _ in pairs)
    c1 = sum(np.vdot(b, a) for a, b in pairs) / n
    rho = min(1.0, abs(c1) / c0)
    if rho < 3 / np.sqrt(n):
        return 0.0
    return float(rho * np.sum(np.abs(r) ** 2))
