"""How many image pixels per element pitch a hologram's resolution asks for.

An image of a hologram holds no detail finer than its lateral resolution cell
``delta = lambda L / A`` (the first null of the point response; ``lambda`` at the
band's centre, ``L`` the apparent distance of the plane, ``A`` the aperture along the
axis), never finer than ``lambda / 2`` however near the plane (the non-paraxial
limit of one-way imaging; a transceiver's round trip halves both, so its image band
is still sampled at Nyquist or finer). Pixels of ``delta / 4`` draw the point
response smoothly and place a peak to a fraction of a cell; finer ones add file
size and time, not information. A scan sampled finer than that already (a
transceiver stepped at 3 mm at 10 GHz) is imaged one pixel per element; a coarse
receiver array (16 x 16 at 2.5 cm, 60 cm away) gets three.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ...theory import C0

__all__ = ["PIXELS_PER_CELL", "upsample_for"]

#: Pixels across one lateral resolution cell that the default upsampling aims at.
PIXELS_PER_CELL = 4


def upsample_for(hologram: Any, z: float | Sequence[float] | np.ndarray,
                 medium: Any = None, *, top: int = 8) -> int:
    """The smallest upsampling (pixels per element pitch) that gives the image
    :data:`PIXELS_PER_CELL` pixels across its finest lateral resolution cell.

    Parameters
    ----------
    hologram : Hologram
        Its pitch, aperture and band (centre frequency).
    z : float or sequence of float
        The ranges to be imaged, metres; the finest cell (the nearest plane) decides.
    medium : Medium, optional
        The ground: a plane's distance is its apparent distance through the layers.
    top : int
        The largest factor returned.

    Returns
    -------
    int
        From 1 to ``top``; 1 where the pitch is already a quarter cell or finer.

    Examples
    --------
    >>> import numpy as np
    >>> import holoradar as hr
    >>> scan = hr.Hologram(np.zeros((11, 187, 144), complex), np.arange(144) * 0.003,
    ...                    np.arange(187) * 0.003, np.linspace(8e9, 12e9, 11),
    ...                    monostatic=True)
    >>> upsample_for(scan, np.linspace(0, 0.18, 110))
    1
    >>> paper = hr.Hologram(np.zeros((16, 16), complex), np.arange(16) * 0.025,
    ...                     np.arange(16) * 0.025, 9.9e9)
    >>> upsample_for(paper, 0.6)
    3
    """
    zs = np.atleast_1d(np.asarray(z, float))
    if zs.size == 0 or not np.all(np.isfinite(zs)):
        raise ValueError(f"z must be finite ranges in metres, got {z!r}")
    wavelength = C0 / float(np.mean(hologram.frequencies))
    near = float(np.min(zs))
    distance = medium.apparent_distance(near) if medium is not None else near
    factor = 1
    for n, pitch, size in zip((hologram.x.size, hologram.y.size), hologram.pitch,
                              hologram.aperture_size, strict=True):
        if n < 2 or not pitch > 0:
            continue   # a line scan's one row: nothing to sample across it
        cell = max(wavelength * max(distance, 0.0) / size, wavelength / 2)
        # 1e-9: a pitch of exactly a quarter cell needs no more pixels
        factor = max(factor, math.ceil(pitch / (cell / PIXELS_PER_CELL) - 1e-9))
    return int(min(max(factor, 1), top))
