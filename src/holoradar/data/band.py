"""What a record with a ``frequency`` knows of its band (a mixin).

A hologram and the raw frames of a device hold ``frequency`` as one number (Hz) for
one frequency, or as a 1-D array for a band (the data then carry a frequency axis
before the array's two). :class:`Band` gives both the same answers.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["Band"]


class Band:
    """``is_wideband``, ``frequencies`` and ``nf`` of a record's ``frequency``.

    Examples
    --------
    >>> class R(Band):
    ...     frequency = np.array([9e9, 1e10])
    >>> R().is_wideband, R().nf
    (True, 2)
    """

    frequency: Any

    @property
    def is_wideband(self) -> bool:
        """True when ``frequency`` is an axis of frequencies (data (..., nf, ny, nx))."""
        return isinstance(self.frequency, np.ndarray)

    @property
    def frequencies(self) -> np.ndarray:
        """The frequencies, Hz, as a 1-D array (one element for a single frequency)."""
        return np.atleast_1d(np.asarray(self.frequency, dtype=float))

    @property
    def nf(self) -> int:
        """Number of frequencies."""
        return self.frequencies.size
