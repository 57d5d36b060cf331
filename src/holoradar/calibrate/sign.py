"""The I/Q sign (I + iQ or I - iQ), told from two reference measurements.

holoradar reads a sample as ``I + iQ`` of a field under ``exp(-i*omega*t)``; a
device whose Q has the other sign delivers the conjugate. One reference cannot
tell: every element's unknown complex gain G absorbs the difference (``D = G*M``
and ``D = conj(G*M)`` both fit with some G). Two references of the same device,
``D_a = G*M_a`` and ``D_b = G*M_b``, can: with the right sign

    D_a*M_b - D_b*M_a = 0

at every element and frequency (G cancels, and so does the frequency response),
while for the conjugate it is ``conj(G)*(conj(M_a)*M_b - conj(M_b)*M_a)``, which
vanishes only where the two references have the same phase. The two residuals

    e(+) = sum |D_a M_b - D_b M_a|^2 / sum (|D_a M_b|^2 + |D_b M_a|^2)
    e(-) = the same with conj(D_a), conj(D_b)

are compared; the margin ``10*log10(e(wrong)/e(right))`` (dB) grows with the
references' signal-to-noise ratio. Pairs that work: the plate at two ranges
about an eighth of a wavelength apart (the two-way phase then differs by about
90 degrees; a shift of a quarter wavelength would make the references differ by
a sign only and tell nothing), or the empty scene and the plate when the horn's
direct wave reaches the array. The DC offset and the I/Q imbalance must be removed
first (:mod:`.dc`, :mod:`.iq`).
"""

from __future__ import annotations

from typing import Any, Literal, NamedTuple

import numpy as np

from ._arrays import complex_field, same_shape

__all__ = ["IQSign", "detect_iq_sign"]


class IQSign(NamedTuple):
    """The detected sign and how clearly it was told."""

    sign: Literal["I+iQ", "I-iQ"]
    """``"I-iQ"``: conjugate the device's samples."""
    margin_db: float
    """``10*log10(e(wrong)/e(right))``: how much better the chosen sign fits, dB."""
    residual_plus: float
    """e(+), the normalised residual of ``I + iQ``."""
    residual_minus: float
    """e(-), that of ``I - iQ``."""


def _residual(da: np.ndarray, db: np.ndarray, ma: np.ndarray, mb: np.ndarray) -> float:
    p, q = da * mb, db * ma
    den = float(np.sum(np.abs(p) ** 2 + np.abs(q) ** 2))
    if den == 0:
        raise ValueError("the references are zero: nothing to compare")
    return float(np.sum(np.abs(p - q) ** 2)) / den


def detect_iq_sign(reference_a: Any, reference_b: Any, model_a: Any, model_b: Any) -> IQSign:
    """``"I+iQ"`` or ``"I-iQ"`` from two reference measurements and their models.

    Parameters
    ----------
    reference_a, reference_b : array_like, complex, shape (ny, nx) or (nf, ny, nx)
        Two measured references of the same device as delivered (``I + iQ`` after
        DC removal and I/Q correction; means of their repeats).
    model_a, model_b : array_like, complex, same shape
        Their modelled fields (:func:`.reference_field`).

    Returns
    -------
    IQSign
        The sign, the margin in dB and both residuals (module text).

    Raises
    ------
    ValueError
        Shapes differ, or the references are zero.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> g = np.exp(2j * np.pi * rng.random((4, 4)))                 # unknown element phases
    >>> ma, mb = np.exp(1j * rng.random((4, 4))), 1j * np.exp(1j * rng.random((4, 4)))
    >>> detect_iq_sign(np.conj(g * ma), np.conj(g * mb), ma, mb).sign
    'I-iQ'
    """
    da, db = complex_field(reference_a, "reference_a"), complex_field(reference_b, "reference_b")
    ma, mb = complex_field(model_a, "model_a"), complex_field(model_b, "model_b")
    for arr, name in ((db, "reference_b"), (ma, "model_a"), (mb, "model_b")):
        same_shape(da, arr, f"reference_a and {name}")
    plus = _residual(da, db, ma, mb)
    minus = _residual(np.conj(da), np.conj(db), ma, mb)
    sign: Literal["I+iQ", "I-iQ"] = "I+iQ" if plus <= minus else "I-iQ"
    right, wrong = min(plus, minus), max(plus, minus)
    if wrong == 0:  # both fit exactly (identical references): nothing told
        margin = 0.0
    else:
        margin = np.inf if right == 0 else 10 * np.log10(wrong / right)
    return IQSign(sign, float(margin), plus, minus)
