"""Per-element complex gain: the measured reference over its modelled field.

A reference measurement of a perfect array would record the modelled field M
(:func:`.reference_field`); the array records ``D = G*M`` plus noise, G each
element's complex gain at each frequency (its antenna, cable and receiver: the
paths to the elements differ in length, so the phase of G changes with frequency
and G is kept per frequency). With D the mean of n repeats of receiver noise of
variance ``sigma^2`` (``E|n|^2``) per element, the estimate ``D/M`` has the
standard error ``sigma/(sqrt(n)*|M|)``: the plate's reflection is strongest on the
elements facing the horn's image, where the gains are best known.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._arrays import complex_field, same_shape

__all__ = ["element_gains"]


def element_gains(reference: Any, model: Any, response: Any = None) -> np.ndarray:
    """Complex gain of each element at each frequency: ``reference / (model * response)``.

    Parameters
    ----------
    reference : array_like, complex, shape (ny, nx) or (nf, ny, nx)
        The measured reference (DC removed, I/Q corrected, right sign; the mean of
        its repeats), device units.
    model : array_like, complex, same shape
        Its modelled field (:func:`.reference_field`).
    response : array_like of shape (nf,), optional
        The frequencies' common response (:func:`.equalize_frequencies`): given,
        the gains are relative to it (their power-weighted mean is 1 at every
        frequency); default 1 (absolute gains).

    Returns
    -------
    ndarray, complex, the shape of ``reference``

    Examples
    --------
    >>> m = np.array([[1.0, 2j], [0.5, -1.0]])
    >>> element_gains(3j * m, m, response=[1j]).real
    array([[3., 3.],
           [3., 3.]])
    """
    d = complex_field(reference, "reference")
    m = complex_field(model, "model")
    same_shape(d, m, "reference and model")
    if np.any(m == 0):
        raise ValueError("model must be non-zero at every element (the reference field must "
                         "reach every element)")
    g = d / m
    if response is None:
        return g
    r = complex_field(response, "response", ndim=(1,))
    nf = d.shape[0] if d.ndim == 3 else 1
    if r.size != nf or np.any(r == 0):
        raise ValueError(f"response must hold {nf} non-zero values (one per frequency), got "
                         f"{r.size}")
    return g / r[:, None, None] if d.ndim == 3 else g / r[0]
