"""DC offset: what each element's I and Q channels read with no signal.

Measured with the transmitter off (a *dark* measurement): each channel then reads
its offset plus receiver noise, so the mean over n dark frames estimates the offset
with the standard error ``s/sqrt(n)`` (``s`` the channel's frame-to-frame standard
deviation). With complex receiver noise of variance ``sigma^2`` (``E|n|^2``) the
I channel's ``s`` is ``sigma/sqrt(2)`` and the Q channel's ``g*sigma/sqrt(2)`` for a
Q gain ``g`` (:mod:`.iq`).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

__all__ = ["DCOffset", "dc_offset", "remove_dc"]


class DCOffset(NamedTuple):
    """Per-element offsets of the raw I and Q channels (device units) and their
    standard errors (NaN for a single dark frame)."""

    i: np.ndarray
    q: np.ndarray
    stderr_i: np.ndarray
    stderr_q: np.ndarray


def dc_offset(dark_i: Any, dark_q: Any) -> DCOffset:
    """Offsets of the I and Q channels from dark frames (transmitter off).

    Parameters
    ----------
    dark_i, dark_q : array_like, real, shape (n, ...)
        n dark frames of the raw I and Q channels, e.g. (n, nf, ny, nx); axis 0
        is the repeats.

    Returns
    -------
    DCOffset
        ``i``, ``q``: the mean over the n frames, shape ``dark_i.shape[1:]``,
        device units; ``stderr_i``, ``stderr_q``: ``std(ddof=1)/sqrt(n)`` of each
        element (NaN when n = 1).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> dark_i = 3.0 + 0.1 * rng.standard_normal((400, 2, 2))
    >>> off = dc_offset(dark_i, -1.0 + 0 * dark_i)
    >>> bool(np.all(np.abs(off.i - 3.0) < 4 * off.stderr_i)), float(off.q[0, 0])
    (True, -1.0)
    """
    di, dq = np.asarray(dark_i, dtype=float), np.asarray(dark_q, dtype=float)
    if di.shape != dq.shape or di.ndim < 1 or di.shape[0] < 1:
        raise ValueError(f"dark_i and dark_q must have one shape (n, ...) with n >= 1 dark "
                         f"frames, got {di.shape} and {dq.shape}")
    if not (np.all(np.isfinite(di)) and np.all(np.isfinite(dq))):
        raise ValueError("dark frames must be finite")
    n = di.shape[0]
    mi, mq = di.mean(axis=0), dq.mean(axis=0)
    if n > 1:
        si = di.std(axis=0, ddof=1) / np.sqrt(n)
        sq = dq.std(axis=0, ddof=1) / np.sqrt(n)
    else:
        si = np.full(mi.shape, np.nan)
        sq = np.full(mq.shape, np.nan)
    return DCOffset(mi, mq, si, sq)


def remove_dc(i: Any, q: Any, dc_i: Any, dc_q: Any) -> tuple[np.ndarray, np.ndarray]:
    """Subtract the channel offsets: ``(i - dc_i, q - dc_q)`` (broadcasting over frames).

    Examples
    --------
    >>> remove_dc(np.array([2.0, 3.0]), np.array([1.0, 1.0]), 2.0, 1.0)
    (array([0., 1.]), array([0., 0.]))
    """
    return (np.asarray(i, dtype=float) - np.asarray(dc_i, dtype=float),
            np.asarray(q, dtype=float) - np.asarray(dc_q, dtype=float))
