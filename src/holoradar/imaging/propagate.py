"""``hr.propagate``: a recorded field carried to a parallel plane, either way.

The angular spectrum carries each plane wave of the recorded field by its own phase,
``exp(i kz d)`` with ``kz = sqrt(n^2 k^2 - kx^2 - ky^2)`` (a scanned transceiver's
round trip: ``sqrt(4 n^2 k^2 - kx^2 - ky^2)``, the two legs' half wavenumbers):

* ``distance > 0``: further from the sources, the way the waves travel (a near-field
  scanner's plane carried to a farther one; evanescent components decay, as they do);
* ``distance < 0``: back towards the sources, the conjugate phase (what ``migrate``
  does for one plane): the evanescent components are not regrown (they would grow
  as ``exp(|kz| d)`` from the noise), so only what travels comes back.

The array lies in air: away from the sources is up through the air; back towards
them is down through ``medium`` (the ground below the array, ranges from it, as
``migrate`` takes it), the conjugate of its layered transfer.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..data.tx_offset import refuse_tx_offset

__all__ = ["propagate"]


def propagate(hologram: Any, distance: float, *, medium: Any = None,
              pad: bool | float = True) -> Any:
    """The recorded field on the parallel plane ``distance`` further from the sources.

    Parameters
    ----------
    hologram : Hologram
        The field on the array's plane (one frequency or several; a scanned
        transceiver's round trip with ``monostatic=True``).
    distance : float
        Metres along the waves' travel: > 0 away from the sources, < 0 back towards
        them. 0 returns the hologram.
    medium : Medium, optional
        The ground below the array (interfaces at ranges from it; default free space):
        crossed by a negative ``distance``; a positive one moves up through the air the
        array lies in.
    pad : bool or float
        Zero padding of the FFT grid (as ``migrate``'s): ``True`` at least doubles each
        size, so that the field leaving the array's edges does not wrap around.

    Returns
    -------
    Hologram
        The field on the new plane, on the same elements (same ``x``, ``y``,
        frequencies, source and pose: the plane is the array's, moved along its
        normal).

    Raises
    ------
    ValueError
        Not a Hologram, a distance that is not a finite number, a medium that is not a
        :class:`~holoradar.Medium`.

    Examples
    --------
    A point's field recorded 20 cm from it, carried 5 cm further, is its field 25 cm
    from it:

    >>> import numpy as np, holoradar as hr
    >>> x = (np.arange(64) - 31.5) * 0.005
    >>> k = 2 * np.pi * 10e9 / hr.C0
    >>> def field(L):
    ...     r = np.sqrt(x[None] ** 2 + x[:, None] ** 2 + L**2)
    ...     return np.exp(1j * k * r) / r
    >>> h = hr.Hologram(field(0.20), x, x, 10e9)
    >>> far = hr.propagate(h, 0.05)
    >>> c = slice(24, 40)      # the middle, away from the aperture's edges
    >>> err = np.abs(far.data - field(0.25))[c, c].max() / np.abs(field(0.25)[c, c]).max()
    >>> bool(err < 0.05)       # what the 32 cm aperture leaves out: a few per cent
    True

    Back towards the point the same aperture gives less: the field nearer a point
    holds steeper waves than the aperture caught (24 % off at 15 cm here).
    """
    from ..data.hologram import C0, Hologram
    from ..physics.medium import Medium
    from ..physics.propagation import AngularSpectrum

    if not isinstance(hologram, Hologram):
        raise ValueError(f"hologram must be a holoradar.Hologram, got "
                         f"{type(hologram).__name__}")
    refuse_tx_offset(hologram, "propagate (a field of one transmitter, carried plane to "
                     "plane)")
    if isinstance(distance, bool) or not isinstance(distance, int | float | np.floating) \
            or not math.isfinite(float(distance)):
        raise ValueError(f"distance must be a finite number of metres (> 0 away from the "
                         f"sources, < 0 back towards them), got {distance!r}")
    if medium is None:
        medium = Medium.free_space()
    if not isinstance(medium, Medium):
        raise ValueError(f"medium must be a holoradar.Medium (the ground below the array) or "
                         f"None, got {type(medium).__name__}")
    d = float(distance)
    if d > 0:
        medium = Medium.free_space()     # up through the air the array lies in
    if d == 0.0:
        return hologram
    dx, dy = hologram.pitch
    data = np.asarray(hologram.data)
    out = np.empty(data.shape, dtype=complex)
    freqs = hologram.frequencies
    for i, f in enumerate(freqs):
        k = 2 * math.pi * float(f) / C0
        op = AngularSpectrum(data.shape[-2:], dx, dy, k, [abs(d)], medium=medium, pad=pad,
                             monostatic=hologram.monostatic)
        plane = data[..., i, :, :] if hologram.is_wideband else data
        moved = op.forward(plane[..., None, :, :]) if d > 0 else op.adjoint(plane)[..., 0, :, :]
        if hologram.is_wideband:
            out[..., i, :, :] = moved
        else:
            out = moved
    return Hologram(out, hologram.x, hologram.y, hologram.frequency, source=hologram.source,
                    monostatic=hologram.monostatic, pose=hologram.pose,
                    polarization=hologram.polarization)
