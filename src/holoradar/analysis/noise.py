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
import scipy.fft as sfft

from ..data.hologram import Hologram

__all__ = ["estimate_snr"]

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
