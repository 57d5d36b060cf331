"""A hologram sampled anywhere: scattered receiver positions (a hand-held scan, a robot's
uneven steps), each sample one complex number per frequency.

``SampledHologram`` holds ``data`` of shape ``(nf, n)`` (or ``(n,)`` for one frequency),
the ``n`` receiver positions ``(x, y, z)`` in metres in the aperture's frame (z, the
range, 0 on the aperture plane: the samples are taken on it), the frequencies, and
what lit the scene: a transceiver at each position (``monostatic=True``) or a separate
``source`` (a receiver array's). Samples use holoradar's conventions: time dependence
``exp(-i omega t)``, the complex sample ``I + iQ``.

Imaging goes through the grid's machinery (:mod:`holoradar.imaging.samples`): the
samples are carried onto a uniform grid by a type-1 non-uniform FFT (exactly the
adjoint of sampling that grid's band-limited field at the positions), then migrated
as a grid is.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validate import as_polarization
from .hologram import C0

__all__ = ["SampledHologram", "from_samples"]


@dataclass(frozen=True, eq=False, repr=False)
class SampledHologram:
    """Samples at scattered positions: see the module text and :func:`from_samples`."""

    data: np.ndarray          # (nf, n) complex, or (n,) for one frequency
    positions: np.ndarray     # (n, 3) metres: x, y, z (z = 0: on the aperture plane)
    frequency: Any            # Hz: a float, or (nf,) for a band
    source: Any = None
    monostatic: bool = False
    polarization: np.ndarray | None = None

    @property
    def frequencies(self) -> np.ndarray:
        """The frequencies as an array, Hz."""
        return np.atleast_1d(np.asarray(self.frequency, float))

    @property
    def is_wideband(self) -> bool:
        return isinstance(self.frequency, np.ndarray)

    @property
    def nf(self) -> int:
        return int(self.frequencies.size)

    @property
    def n(self) -> int:
        """The number of positions."""
        return int(self.positions.shape[0])

    def __repr__(self) -> str:
        f = self.frequencies
        band = f"{f[0] / 1e9:.4g} GHz" if f.size == 1 else \
            f"{f[0] / 1e9:.4g} to {f[-1] / 1e9:.4g} GHz ({f.size} frequencies)"
        lo, hi = self.positions[:, :2].min(axis=0), self.positions[:, :2].max(axis=0)
        kind = "scanned transceiver" if self.monostatic else "receiver positions"
        return (f"<holoradar.SampledHologram {self.n} samples: {band}; x {lo[0] * 100:.3g} "
                f"to {hi[0] * 100:.3g} cm, y {lo[1] * 100:.3g} to {hi[1] * 100:.3g} cm; "
                f"{kind}>")


def from_samples(data: Any, positions: Any, frequency: Any, *, tx: Any = None,
                 monostatic: bool = False, source: Any = None,
                 polarization: Any = None) -> SampledHologram:
    """A hologram of samples at scattered positions (``Hologram.from_samples``).

    Parameters
    ----------
    data : array_like, complex, shape (nf, n) or (n,)
        One sample per position and frequency (frequency first).
    positions : array_like, shape (n, 2) or (n, 3)
        Receiver positions, metres: x, y (and z, which must be 0: the samples lie on
        the aperture plane, from which ranges are counted).
    frequency : float or array_like of float
        Hz: one, or the band's ``nf`` frequencies (increasing).
    tx : array_like, shape (n, 3), optional
        Transmitter positions of bistatic or MIMO pairs. Not imaged by this version:
        a pair's two legs need their own kernel; refused with that reason. A
        transceiver is ``monostatic=True`` without ``tx``.
    monostatic : bool
        A transceiver at each position (the round trip).
    source : PlaneWave, PointSource or GaussianBeam, optional
        What lit the scene for receiver positions (``monostatic=False``).
    polarization : array_like of 3 floats, optional
        The field component the receivers record (world axes), as for a grid.

    Returns
    -------
    SampledHologram

    Raises
    ------
    ValueError
        Data and positions of different lengths; NaN or infinite values; positions
        repeated (their count and the first pair named); positions spread over less than
        a hundredth of a wavelength or more than 1000 (millimetres given as metres, or
        the reverse); a ``tx`` array; ``source`` with ``monostatic=True``.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> p = rng.uniform(-0.1, 0.1, (500, 2))
    >>> s = from_samples(np.ones((3, 500)), p, [9e9, 10e9, 11e9], monostatic=True)
    >>> s.n, s.nf, s.positions.shape
    (500, 3, (500, 3))
    """
    if tx is not None:
        raise ValueError("tx: transmitter-receiver pairs (bistatic, MIMO) are not imaged by "
                         "this version (each pair's two legs need their own kernel); give "
                         "monostatic=True for a transceiver, or a source for receivers")
    if not isinstance(monostatic, bool | np.bool_):
        raise ValueError(f"monostatic must be True or False, got {monostatic!r}")
    if monostatic and source is not None:
        raise ValueError("source: a transceiver lights the scene itself (monostatic=True); "
                         "pass source=None")
    if source is not None and not (hasattr(source, "field") and hasattr(source, "reflected")):
        raise ValueError(f"source must be a PlaneWave, PointSource, GaussianBeam or None, got "
                         f"{type(source).__name__}")
    pos = _positions(positions)
    f = np.atleast_1d(np.asarray(frequency, dtype=float))
    if f.ndim != 1 or not np.all(np.isfinite(f)) or np.any(f <= 0) or \
            (f.size > 1 and np.any(np.diff(f) <= 0)):
        raise ValueError(f"frequency must be positive and increasing, Hz, got {frequency!r}")
    try:
        arr = np.array(data, dtype=complex)
    except (TypeError, ValueError):
        raise ValueError("data must be complex numbers, shape (nf, n) or (n,)") from None
    arr = arr.reshape(1, -1) if arr.ndim == 1 else arr
    if arr.ndim != 2 or arr.shape != (f.size, len(pos)):
        raise ValueError(f"data must have shape (nf, n) = ({f.size}, {len(pos)}) (frequency "
                         f"first, one sample per position), got {np.shape(data)}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"data: {int(np.sum(~np.isfinite(arr)))} samples are NaN or infinite")
    lam = C0 / float(f.max())
    span = float(np.max(np.ptp(pos[:, :2], axis=0)))
    if span < lam / 100 or span > 1000 * lam:
        raise ValueError(f"positions span {span:g} m, against a wavelength of {lam:.3g} m: "
                         "metres are expected (millimetres given as metres?)")
    pos.setflags(write=False)
    arr.setflags(write=False)
    freq: Any = f if f.size > 1 else float(f[0])
    out = arr if f.size > 1 else arr[0]
    return SampledHologram(out, pos, freq, source, bool(monostatic),
                           as_polarization(polarization, "polarization"))


def _positions(positions: Any) -> np.ndarray:
    """The positions as an ``(n, 3)`` array, checked: shape, finite, on the aperture
    plane (z = 0), none repeated."""
    try:
        pos = np.array(positions, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"positions must be numbers, shape (n, 2) or (n, 3), got "
                         f"{type(positions).__name__}") from None
    if pos.ndim != 2 or pos.shape[1] not in (2, 3) or pos.shape[0] < 2:
        raise ValueError(f"positions must have shape (n, 2) or (n, 3) with n >= 2 (metres), "
                         f"got {pos.shape}")
    if pos.shape[1] == 2:
        pos = np.column_stack([pos, np.zeros(len(pos))])
    bad = ~np.all(np.isfinite(pos), axis=1)
    if bad.any():
        raise ValueError(f"positions: {int(bad.sum())} of {len(pos)} hold NaN or infinity "
                         f"(the first at index {int(np.argmax(bad))}); drop those samples")
    if np.any(pos[:, 2] != 0):
        raise ValueError("positions: z must be 0 (the samples lie on the aperture plane, from "
                         "which ranges are counted); give (n, 2) positions or move the "
                         "ranges by the height")
    _, first, counts = np.unique(pos[:, :2], axis=0, return_index=True, return_counts=True)
    if np.any(counts > 1):
        extra = int(np.sum(counts - 1))
        raise ValueError(f"positions: {extra} repeat an earlier position (e.g. index "
                         f"{int(first[np.argmax(counts > 1)])}); average the repeats or drop "
                         "them")
    return pos
