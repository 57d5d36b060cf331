"""CLEAN: explain the brightest object by its response, subtract it, look again.

Each pass takes the maximum of ``|R|^2 / (sigma^2 + V)`` over the residual image
``R`` (the image less the models of the objects found). ``sigma^2(r)`` is the
local noise estimated from ``R`` outside the objects' main lobes and ``t`` the
threshold of the stated false-alarm rate (:mod:`.noise`); ``V`` is the variance of
the models' own error, taken proportional to each model,

    V(r) = sum_i eps_i^2 |m_i(r)|^2,
    eps_i^2 = max(0, sum_E |R_i|^2 - n_E s_i^2) / sum_E |m_i|^2,

measured right after its subtraction on its main lobe and first sidelobes ``E`` (the
model's ``error_region``; its main lobe where a model gives none): the energy the
model leaves there beyond the noise, relative to the model's. The first
sidelobes belong in that measure: a rectangular aperture's are only 13 dB down,
and a model right on the main lobe and wrong on them (the analytic ``sinc``
without the focus's chirp) leaves them as "objects". So a sidelobe or a ringing
that a model reproduces to within ``eps`` is never an object, and a weak object
next to a strong one must stand out of the strong one's model error as well as
out of the noise. ``s_i^2`` is the noise of the plane once object ``i`` is
subtracted, the median of ``|R_i|^2`` over ``ln 2`` (an exponential's median;
the local estimate made before the subtraction holds the object itself), and
``n_E`` the number of pixels of the region ``E``.

Stopping rule: the pass stops when that maximum falls below ``t`` (or after
``max_objects``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .grid import Volume, refine_peak
from .noise import NoiseModel, candidate_noise, local_noise, threshold_resels

__all__ = ["CleanResult", "Component", "clean"]


@dataclass
class Component:
    """One object found by CLEAN (image coordinates, metres)."""

    peak: tuple[float, float, float]          # sub-pixel maximum of the residual
    position: tuple[float, float, float]      # the model's fitted position
    peak_index: tuple[int, int, int]
    amplitude: complex                        # the model's value at its maximum
    statistic: float                          # |R|^2/(sigma^2 + V) at the peak
    model_error: float                        # eps (relative), after subtraction
    std: tuple[float, float, float] = (np.nan, np.nan, np.nan)
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass
class CleanResult:
    components: list[Component]
    residual: np.ndarray
    noise: NoiseModel
    model_variance: np.ndarray


def clean(volume: Volume, model: Any, false_alarm: float, *, max_objects: int = 100
          ) -> CleanResult:
    """Find objects one by one (module notes).

    ``model.start()`` gives the residual image to begin with and
    ``model.fit(residual, index, position)`` the model image of one object, its
    main lobe and a dict (optionally ``position``, ``std`` and ``error_region``, the
    pixels of the object's plane where its error is measured).
    """
    R = model.start()
    V = np.zeros(R.shape)
    mask = np.zeros(R.shape[1:], bool)
    comps: list[Component] = []
    while True:
        noise = local_noise(R, mask, volume.x, volume.y, volume.z, false_alarm)
        # The candidate: the brightest against each plane's typical noise and the models'
        # error (the local estimate would favour the quiet surroundings of a strong
        # object, e.g. its range sidelobes, over the object itself).
        # Each plane's noise for the choice: the median of |R|^2 over ln 2 (an
        # exponential's median), robust to the objects not yet found.
        s2 = np.median(np.abs(R) ** 2, axis=(1, 2))[:, None, None] / np.log(2) + V
        stat = np.abs(R) ** 2 / np.where(s2 > 0, s2, np.inf)
        idx = tuple(int(i) for i in np.unravel_index(int(np.argmax(stat)), stat.shape))
        frac, value = refine_peak(stat, idx)  # type: ignore[arg-type]
        bright = value   # over the plane's typical noise (its own sidelobes left out)
        # The decision: the candidate's own reference, its guard cells left out.
        s2c, n_ref = candidate_noise(R, mask, idx, volume.x, volume.y, noise.cell)
        t = threshold_resels(false_alarm * max(noise.n_cells, 1.0), noise.resels, n_ref)
        value = value * s2[idx] / (s2c + V[idx])
        if not value >= t:
            break
        if len(comps) >= max_objects:
            warnings.warn(f"detect stopped after max_objects={max_objects} objects; more lie "
                          "above the threshold", RuntimeWarning, stacklevel=3)
            break
        peak = volume.coords(*frac)
        if hasattr(model, "detection"):
            model.detection = (float(bright), float(t))   # how far above the threshold
        m, lobe, info = model.fit(R, idx, peak)
        R = R - m
        iz = idx[0]
        region = info.get("error_region", lobe)
        e_model = float(np.sum(np.abs(m[iz][region]) ** 2))
        # The noise there: the plane's median of |R|^2 over ln 2 once the object is
        # subtracted (the local estimate, made before, holds the object itself).
        s2_after = float(np.median(np.abs(R[iz]) ** 2)) / np.log(2)
        e_left = float(np.sum(np.abs(R[iz][region]) ** 2)) - s2_after * int(np.sum(region))
        eps2 = min(max(e_left, 0.0) / e_model, 1.0) if e_model > 0 else 1.0
        V = V + eps2 * np.abs(m) ** 2
        mask |= lobe
        am = np.abs(m)
        j = np.unravel_index(int(np.argmax(am)), am.shape)
        comps.append(Component(peak=peak, position=info.get("position", peak),
                               peak_index=idx, amplitude=complex(m[j]), statistic=value,
                               model_error=float(np.sqrt(eps2)),
                               std=info.get("std", (np.nan, np.nan, np.nan)), extra=info))
    return CleanResult(comps, R, noise, V)
