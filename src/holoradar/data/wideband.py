"""Habits of measured wideband data: the mean of each frequency, a per-frequency
calibration table, and the I/Q sign.

Conventions: the complex sample is ``I + iQ`` of a field under the time dependence
``exp(-i*omega*t)``. A device that delivers ``I - iQ`` (or mixes with the other
sideband) gives the complex conjugate: see :func:`iq_convention`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np

from .hologram import Hologram

__all__ = ["apply_calibration", "conjugate", "remove_mean"]


def remove_mean(hologram: Hologram) -> Hologram:
    """Subtract each frequency's (and frame's) mean over the elements.

    The mean holds a receiver's DC offset and the static background common to all
    positions of a scan (for a monostatic scan over flat ground: each
    transceiver's own glare, the same at every position). It also removes the
    zero spatial frequency of the objects, which a scan much wider than the
    objects hardly misses.

    Examples
    --------
    >>> x = np.arange(4) * 0.01
    >>> h = Hologram(np.ones((2, 4, 4)) * np.array([1.0, 2j])[:, None, None], x, x, [9e9, 1e10])
    >>> float(np.abs(remove_mean(h).data).max())
    0.0
    """
    d = hologram.data
    return hologram.with_data(d - d.mean(axis=(-2, -1), keepdims=True))


def conjugate(hologram: Hologram) -> Hologram:
    """The complex conjugate: data recorded as ``I - iQ`` turned into ``I + iQ``."""
    return hologram.with_data(np.conj(hologram.data))


def apply_calibration(hologram: Hologram, table_frequency: Sequence[float] | np.ndarray,
                      table: Sequence[complex] | np.ndarray, *,
                      kind: Literal["phase", "complex"] = "phase") -> Hologram:
    """Divide each frequency by the device's response from a calibration table.

    Parameters
    ----------
    hologram : Hologram
        Single- or multi-frequency.
    table_frequency : array_like
        Frequencies of the table, Hz, strictly increasing; they must cover every
        frequency of the hologram (no extrapolation).
    table : array_like
        ``kind="phase"``: the device's phase at each table frequency, radians
        (the response is ``exp(i*phase)``); ``kind="complex"``: its complex
        response. Between table frequencies the amplitude and the unwrapped
        phase are interpolated linearly.
    kind : {"phase", "complex"}

    Returns
    -------
    Hologram
        ``data / response(f)`` for each frequency.

    Raises
    ------
    ValueError
        A table that does not cover the band, is not increasing, or holds a zero.

    Examples
    --------
    >>> x = np.arange(4) * 0.01
    >>> h = Hologram(np.ones((2, 4, 4)) * 1j, x, x, [9e9, 1e10])
    >>> c = apply_calibration(h, [8e9, 11e9], [np.pi / 2, np.pi / 2])
    >>> np.round(c.data[:, 0, 0], 12)
    array([1.+0.j, 1.+0.j])
    """
    tf = np.asarray(table_frequency, dtype=float)
    tv = np.asarray(table, dtype=complex if kind == "complex" else float)
    if tf.ndim != 1 or tv.shape != tf.shape or tf.size < 1:
        raise ValueError("table_frequency and table must be 1-D and of one length, got "
                         f"{tf.shape} and {tv.shape}")
    if np.any(np.diff(tf) <= 0) or not np.all(np.isfinite(tf)):
        raise ValueError("table_frequency must be finite and strictly increasing (Hz)")
    if kind not in ("phase", "complex"):
        raise ValueError(f"kind must be 'phase' or 'complex', got {kind!r}")
    f = hologram.frequencies
    tol = 1e-9 * f.max()
    if f.min() < tf[0] - tol or f.max() > tf[-1] + tol:
        raise ValueError(f"the calibration table covers {tf[0] / 1e9:.6g}-{tf[-1] / 1e9:.6g} "
                         f"GHz but the hologram spans {f.min() / 1e9:.6g}-{f.max() / 1e9:.6g} "
                         "GHz: it must cover every frequency (no extrapolation)")
    if kind == "phase":
        phase = np.interp(f, tf, np.unwrap(tv))
        response = np.exp(1j * phase)
    else:
        if np.any(tv == 0):
            raise ValueError("table must hold non-zero complex responses")
        amp = np.interp(f, tf, np.abs(tv))
        phase = np.interp(f, tf, np.unwrap(np.angle(tv)))
        response = amp * np.exp(1j * phase)
    if hologram.is_wideband:
        return hologram.with_data(hologram.data / response[:, None, None])
    return hologram.with_data(hologram.data / response[0])
