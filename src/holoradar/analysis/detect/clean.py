"""CLEAN: explain the brightest object by its response, subtract it, look again.

Each pass takes the maximum of ``|R|^2 / (sigma^2 + V)`` over the residual image
``R`` (the image less the models of the objects found). ``sigma^2(r)`` is the
local noise estimated from ``R`` outside the objects' main lobes and ``t`` the
threshold of the stated false-alarm rate (:mod:`.noise`); ``V`` is the variance of
the models' own error, taken proportional to each model,

    V(r) = sum_i eps_i^2 |m_i(r)|^2,
    eps_i^2 = max(0, sum_E w (|R_i|^2 - s_i^2)) / sum_E w |m_i|^2,   w = |m_i|^2,

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
the weights ``w`` those of the least-squares estimate of an error proportional
to the model (what lies where the model is faint, the next piece of a bar or
another object, weighs little). Once CLEAN stops, every model's error is
measured again on the residual of all of them (a neighbour that stood in one's
region is explained by then) and the search goes on with that ``V``.

Stopping rule: the pass stops when that maximum falls below ``t`` (or after
``max_objects``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .grid import Volume, refine_peak
from .noise import NoiseModel, local_noise, threshold_resels
from .reference import candidate_noise

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
    terms: list[tuple[int, np.ndarray, np.ndarray]] = []   # iz, region, |m|^2
    remeasured = False
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
            if terms and not remeasured and len(terms) == len(comps):
                # Re-measure every model's error on the residual of all of them: what
                # one object's fit box held of its neighbours (the next piece of a bar,
                # a weak object beside a strong one) is explained now, and only the
                # models' own error is left to count.
                V = _remeasure(R, terms, comps)
                remeasured = True
                continue
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
        m2 = np.abs(m) ** 2
        eps2 = _eps2(R[iz], m2[iz], region)
        V = V + eps2 * m2
        if R.size * (len(terms) + 1) <= _REMEASURE_FLOATS:
            terms.append((iz, region, m2.astype(np.float32)))
        remeasured = False
        mask |= lobe
        am = np.abs(m)
        j = np.unravel_index(int(np.argmax(am)), am.shape)
        comps.append(Component(peak=peak, position=info.get("position", peak),
                               peak_index=idx, amplitude=complex(m[j]), statistic=value,
                               model_error=float(np.sqrt(eps2)),
                               std=info.get("std", (np.nan, np.nan, np.nan)), extra=info))
    return CleanResult(comps, R, noise, V)


_REMEASURE_FLOATS = 5e7
"""The models' |m|^2 kept for re-measuring their errors, at most (200 MB in float32)."""


def _eps2(plane: np.ndarray, m2: np.ndarray, region: np.ndarray) -> float:
    """A model's relative error energy on its region of the residual plane (notes).

    The residual's excess over the noise, weighted by the model's own intensity
    ``|m|^2`` (the error taken proportional to the model, ``V = eps^2 |m|^2``: its
    least-squares estimate weights each pixel by ``|m|^2``; what lies where the
    model is faint, the next piece of a bar or another object, weighs little).
    The noise: the plane's median of ``|R|^2`` over ln 2 once the object is
    subtracted (the local estimate, made before, holds the object itself).
    """
    w = m2[region]
    den = float(np.sum(w * w))
    if not den > 0:
        return 1.0
    s2_after = float(np.median(np.abs(plane) ** 2)) / np.log(2)
    num = float(np.sum(w * (np.abs(plane[region]) ** 2 - s2_after)))
    return min(max(num, 0.0) / den, 1.0)


def _remeasure(R: np.ndarray, terms: list[tuple[int, np.ndarray, np.ndarray]],
               comps: list[Component]) -> np.ndarray:
    """``V`` from every model's error measured on the residual of all, each component's
    ``model_error`` updated."""
    V = np.zeros(R.shape)
    for (iz, region, m2), c in zip(terms, comps, strict=True):
        eps2 = _eps2(R[iz], m2[iz], region)
        c.model_error = float(np.sqrt(eps2))
        V += eps2 * m2
    return V
