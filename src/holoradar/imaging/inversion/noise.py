"""The receiver noise an inversion stops at and thresholds by.

Given: the standard deviation of the complex noise per sample, in the data's own
units (``E|n|^2 = sigma^2``). Otherwise estimated from the hologram's spectrum beyond
what any scene at the planes' range can send through the air gap (evanescent waves
damped 60 dB: :func:`holoradar.data.noise.estimate_snr`), which needs a pitch below
half a wavelength. Where that cannot be done (the paper's 16 x 16 array at 2.5 cm,
say) 40 dB below the data's mean power is assumed, and a warning says so and asks for
``noise=``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._validate import outside_stacklevel
from ...data.hologram import Hologram
from ...data.noise import estimate_snr
from ...physics.propagation import DEFAULT_SNR_DB

__all__ = ["NoiseLevel", "NoiseWarning", "nearest_source", "noise_std"]


class NoiseWarning(UserWarning):
    """The receiver noise could not be estimated from the data and was assumed."""


@dataclass(frozen=True)
class NoiseLevel:
    """A noise already found (:func:`noise_std`'s answer), passed on as ``noise=`` so
    that one call estimates it once.

    Examples
    --------
    >>> noise_std(None, 0.1, NoiseLevel(0.5, "assumed"))
    (0.5, 'assumed')
    """

    sigma: float
    how: str


def nearest_source(zs: Any, medium: Any) -> float:
    """The range, metres, beyond which every source of the field lies: the nearest
    plane, or the ground's surface where that is nearer.

    Examples
    --------
    >>> import holoradar as hr
    >>> nearest_source([0.3, 0.4], hr.Medium.half_space(0.2, 4.0))
    0.2
    """
    surface = medium.z_interfaces[0] if medium is not None and not medium.is_free_space \
        else math.inf
    return min(float(np.min(zs)), surface)


def noise_std(hologram: Hologram, z_min: float, noise: Any) -> tuple[float, str]:
    """``(sigma, how)``: the noise's standard deviation per complex sample and how it
    was found ("given", "estimated from the evanescent band (SNR x dB)", "assumed").

    Parameters
    ----------
    hologram : Hologram
        The data (one frame).
    z_min : float
        Range, metres, beyond which every source of the field lies (the nearest plane
        or the ground surface).
    noise : float, NoiseLevel or None
        The given standard deviation (> 0), a level found before (returned as it
        is), or None to estimate it.

    Raises
    ------
    ValueError
        ``noise`` not a positive finite number.

    Examples
    --------
    >>> import holoradar as hr
    >>> scene = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))], source=hr.PlaneWave())
    >>> h = hr.simulate(scene, hr.Aperture.grid(64, 0.005), 9.9e9, snr_db=25, seed=1)
    >>> sigma, how = noise_std(h, 0.3, None)
    >>> how.startswith("estimated"), round(10 * np.log10(np.mean(abs(h.data)**2) / sigma**2))
    (True, 25)
    """
    if isinstance(noise, NoiseLevel):
        return noise.sigma, noise.how
    if noise is not None:
        try:
            sigma = float(noise)
        except (TypeError, ValueError):
            sigma = math.nan
        if not math.isfinite(sigma) or sigma <= 0:
            raise ValueError("noise must be the receiver noise's standard deviation per "
                             f"sample, a positive number in the data's units, got {noise!r}")
        return sigma, "given"
    power = float(np.mean(np.abs(hologram.data) ** 2))
    snr = estimate_snr(hologram, z_min)
    if snr is not None:
        return math.sqrt(power / (10 ** (snr / 10) + 1)), \
            f"estimated from the evanescent band (SNR {snr:.1f} dB)"
    warnings.warn(f"the receiver noise cannot be estimated from this hologram (its pitch is "
                  f"not below half a wavelength): {DEFAULT_SNR_DB:.0f} dB below the data's "
                  "mean power assumed; give the noise (noise=, or --noise on the command "
                  "line: its standard deviation per sample) for "
                  "the inversion's stop and threshold", NoiseWarning,
                  stacklevel=outside_stacklevel())
    return math.sqrt(power / 10 ** (DEFAULT_SNR_DB / 10)), \
        f"assumed ({DEFAULT_SNR_DB:.0f} dB below the data's power)"
