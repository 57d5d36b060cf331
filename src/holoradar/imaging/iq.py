"""Which I/Q sign a device delivers, told from the data themselves.

holoradar reads a complex sample as ``I + iQ`` of a field under ``exp(-i*omega*t)``.
A device whose Q has the other sign (or that mixes with the other sideband)
delivers the complex conjugate. The two are told apart by physics: with the right
sign the scene focuses in front of the aperture; the conjugate is the field of
the mirror scene behind it, so back-propagated to the same ranges it spreads out
instead. The image with the sharper focus (larger peak-to-mean intensity) wins.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np

from ..data.hologram import Hologram
from ..data.wideband import conjugate
from .migrate import migrate

__all__ = ["iq_convention"]


def _sharpness(data: np.ndarray) -> float:
    a = np.abs(data) ** 2
    return float(a.max() / max(a.mean(), 1e-300))


def iq_convention(hologram: Hologram, z: float | Sequence[float] | np.ndarray,
                  **migrate_options: Any) -> Literal["I+iQ", "I-iQ"]:
    """``"I+iQ"`` if the data focus as recorded, ``"I-iQ"`` if their conjugate does.

    Parameters
    ----------
    hologram : Hologram
        Data holding at least one compact reflector (a metal plate or sphere at a
        known range is the classic check).
    z : float or sequence of float
        Ranges where it lies, metres.
    **migrate_options
        Passed to :func:`holoradar.migrate` (``medium=...``).

    Returns
    -------
    str
        ``"I-iQ"`` means: take :func:`holoradar.data.wideband.conjugate` of the
        data before imaging.

    Examples
    --------
    >>> import holoradar as hr
    >>> ap = hr.Aperture.grid(24, 0.0062, monostatic=True)
    >>> h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.2))]), ap,
    ...                 [9e9, 10e9, 11e9])
    >>> iq_convention(h, [0.18, 0.2, 0.22]), iq_convention(conjugate(h), [0.18, 0.2, 0.22])
    ('I+iQ', 'I-iQ')
    """
    as_is = _sharpness(migrate(hologram, z, **migrate_options).data)
    flipped = _sharpness(migrate(conjugate(hologram), z, **migrate_options).data)
    return "I+iQ" if as_is >= flipped else "I-iQ"
