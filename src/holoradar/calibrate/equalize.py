"""Equalisation between frequencies: the complex response common to all elements.

At frequency f the array records ``D = H_f * g * M`` of a reference field M, H_f
the device's response at f (transmitter power and phase, the receiver's common
chain) and g the elements' own gains. The least-squares fit of ``D ~ H_f*M`` over
the good elements,

    H_f = sum conj(M)*D / sum |M|^2,

is the power-weighted mean of the elements' complex gains at f; dividing by it
equalises the frequencies (amplitude and phase) so that they add coherently in
range. With D the mean of n repeats of noise ``sigma^2`` per element its standard
error is ``sigma/sqrt(n * sum |M|^2)``. Compare :func:`holoradar.apply_calibration`,
which divides by such a response given as a table.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._arrays import complex_field, element_mask, same_shape

__all__ = ["equalize_frequencies"]


def equalize_frequencies(reference: Any, model: Any, mask: Any = None) -> np.ndarray:
    """The device's complex response at each frequency from a reference measurement.

    Parameters
    ----------
    reference : array_like, complex, shape (nf, ny, nx) or (ny, nx)
        The measured reference (DC removed, I/Q corrected, right sign; mean of
        its repeats), device units.
    model : array_like, complex, same shape
        Its modelled field (:func:`.reference_field`).
    mask : array_like of bool, shape (ny, nx), optional
        Bad elements (True), left out of the fit.

    Returns
    -------
    ndarray, complex, shape (nf,)
        ``H_f`` (nf = 1 for a single frequency), device units per model unit.

    Examples
    --------
    >>> m = np.ones((2, 3, 3)) * np.array([1.0, 1j])[:, None, None]
    >>> h = equalize_frequencies(m * np.array([2.0, -1j])[:, None, None], m)
    >>> bool(np.allclose(h, [2.0, -1j]))
    True
    """
    d = complex_field(reference, "reference")
    m = complex_field(model, "model")
    same_shape(d, m, "reference and model")
    if d.ndim == 2:
        d, m = d[None], m[None]
    good = ~element_mask(mask, d.shape[-2:])
    num = np.sum(np.conj(m) * d * good, axis=(-2, -1))
    den = np.sum(np.abs(m) ** 2 * good, axis=(-2, -1))
    if np.any(den == 0):
        raise ValueError("the model is zero on every good element at some frequency")
    return num / den
