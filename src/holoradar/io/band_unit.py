"""The unit of a list of frequencies written without one.

A radar band lies between 0.1 GHz and 1 THz: a number list such as ``8.2, 9.1`` can
only be GHz, ``8.2e9`` only Hz. Where the values fit Hz they are taken in Hz (as
written); where two other units fit (``500``: GHz or MHz), none is guessed.
"""

from __future__ import annotations

import numpy as np

from .layout import FREQUENCY_UNITS

__all__ = ["BAND_HZ", "band_unit"]

BAND_HZ = (1e8, 1e12)
"""The frequencies a radar band may hold, Hz."""


def band_unit(values: np.ndarray, what: str, advice: str) -> str:
    """The unit (a key of ``FREQUENCY_UNITS``) that puts every value in :data:`BAND_HZ`.

    Raises
    ------
    ValueError
        ``"WHAT: ... could be in UNITS: ADVICE"`` where no unit or several fit.

    Examples
    --------
    >>> band_unit(np.array([8.2, 9.1]), "f", ""), band_unit(np.array([2e8, 9e8]), "f", "")
    ('GHz', 'Hz')
    """
    f = np.asarray(values, float)
    fits = [u for u, s in FREQUENCY_UNITS.items()
            if np.all(f * s >= BAND_HZ[0]) and np.all(f * s <= BAND_HZ[1])]
    if "Hz" in fits:        # in Hz where they fit: written as they are
        fits = ["Hz"]
    if len(fits) != 1:
        raise ValueError(f"{what}: frequencies {f.min():g} to {f.max():g} could be in "
                         f"{', '.join(fits) or 'no unit between 0.1 GHz and 1 THz'}: {advice}")
    return fits[0]
