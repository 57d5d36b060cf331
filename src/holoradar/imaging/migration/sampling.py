"""What an array records: the field computed finely and sampled at the elements.

The plane-by-plane operators compute the field on the hologram's own grid from the
spectrum inside its Nyquist band ``|k_x| < pi / dx``. Where the pitch exceeds half
the shortest wavelength (``lambda / 2``, a transceiver's round trip ``lambda / 4``) a
point's field holds propagating waves beyond that band, which the elements record
folded into it (aliased); a band-limited model leaves them out, 10-30 % of a point's
samples under a 2.5 cm pitch at 9.9 GHz. ``sampling="array"`` computes the field on a
grid ``u`` times finer (``u`` the smallest integer with ``pitch / u`` at most half the
shortest wavelength) and keeps every ``u``-th sample: the forward map is the
physical sampling, the adjoint its exact transpose (zero insertion), and aliasing is
in the model rather than in its error.
"""

from __future__ import annotations

import math

import numpy as np

from ...data.hologram import C0, Hologram

__all__ = ["decimate", "fine_hologram", "oversampling", "zero_insert"]


def oversampling(hologram: Hologram) -> int:
    """``u``: how many times finer than the pitch the field must be computed (1: none).

    Examples
    --------
    >>> import holoradar as hr
    >>> h = hr.Hologram(np.zeros((16, 16)), np.arange(16) * 0.025, np.arange(16) * 0.025,
    ...                 9.9e9, source=hr.PlaneWave())
    >>> oversampling(h)     # 2.5 cm pitch, lambda / 2 = 1.51 cm
    2
    """
    lam = C0 / float(np.max(hologram.frequencies)) / (2 if hologram.monostatic else 1)
    return max(1, math.ceil(max(hologram.pitch) / (0.5 * lam) - 1e-9))


def fine_hologram(hologram: Hologram, u: int) -> Hologram:
    """The same geometry on a grid ``u`` times finer through the same elements (its
    data the given samples with zeros between: :func:`zero_insert`)."""
    dx, dy = hologram.pitch
    x = hologram.x[0] + np.arange(u * (hologram.x.size - 1) + 1) * (dx / u)
    y = hologram.y[0] + np.arange(u * (hologram.y.size - 1) + 1) * (dy / u)
    data = zero_insert(hologram.data, u, (y.size, x.size))
    return Hologram(data, x, y, hologram.frequency, source=hologram.source,
                    monostatic=hologram.monostatic, pose=hologram.pose,
                    polarization=hologram.polarization, tx_offset=hologram.tx_offset)


def decimate(fine: np.ndarray, u: int) -> np.ndarray:
    """Every ``u``-th sample along the last two axes (the elements)."""
    return fine[..., ::u, ::u]


def zero_insert(data: np.ndarray, u: int, shape: tuple[int, int]) -> np.ndarray:
    """The transpose of :func:`decimate`: ``data`` at every ``u``-th sample of a grid of
    ``shape`` (last two axes), zeros elsewhere."""
    out = np.zeros((*data.shape[:-2], *shape), dtype=data.dtype)
    out[..., ::u, ::u] = data
    return out
