"""Dead and noisy elements: flagged, left out of processing, interpolated only for display.

From the repeats of a reference measurement (DC removed, I/Q corrected, right
sign) and its modelled field M:

* **dead**: the element's gain ``|mean/M|`` (median over frequencies) is below
  ``dead_below`` times the median over all elements (default 0.1, -20 dB): no
  signal reaches its output;
* **noisy**: its repeat-to-repeat scatter (standard deviation of the complex
  samples, RMS over frequencies, device units) is above ``noisy_above`` times the
  median over the elements (default 3).

A good element's squared scatter over n repeats and nf frequencies is
``sigma^2 * chi2(nu)/nu`` with ``nu = 2*nf*(n - 1)`` degrees of freedom, so it is
flagged (a false alarm) with probability ``P(chi2(nu) > nu*noisy_above^2)``:
1e-4 for nu = 2 (two repeats, one frequency; 3% that one of 256 elements is),
below 1e-12 from nu = 8 on. Record at least 4 repeats.

A flagged element is set to 0 in the calibrated hologram (migration treats it as
an element that saw nothing). :func:`interpolate_for_display` fills it from its
neighbours for a picture only: an interpolated value is a guess, not a
measurement.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .._lazy import lazy_module
from ..data.hologram import Hologram
from ._arrays import complex_field, element_mask

# Imported on first use (holoradar._lazy): `import holoradar` should cost little more
# than numpy.
sp = lazy_module("scipy.sparse")
spla = lazy_module("scipy.sparse.linalg")

__all__ = ["BadElements", "find_bad_elements", "interpolate_for_display"]


class BadElements(NamedTuple):
    """Flags (each of shape (ny, nx)) and the numbers they were drawn from."""

    mask: np.ndarray
    """True where an element is dead or noisy."""
    dead: np.ndarray
    """True where the gain is far below the median."""
    noisy: np.ndarray
    """True where the scatter is far above the median (and the element is not dead)."""
    gain_ratio: np.ndarray
    """Each element's |gain| over the median |gain|."""
    scatter_ratio: np.ndarray
    """Each element's scatter over the median scatter (inf where the median is 0)."""


def _ratio(a: np.ndarray) -> np.ndarray:
    med = float(np.median(a))
    if med > 0:
        return a / med
    return np.where(a > 0, np.inf, 0.0)


def find_bad_elements(repeats: Any, model: Any, *, dead_below: float = 0.1,
                      noisy_above: float = 3.0) -> BadElements:
    """Flag dead and noisy elements from the repeats of a reference measurement.

    Parameters
    ----------
    repeats : array_like, complex, shape (n, ny, nx) or (n, nf, ny, nx)
        n >= 2 repeats of the reference, DC removed, I/Q corrected, right sign.
    model : array_like, complex, shape (ny, nx) or (nf, ny, nx)
        Its modelled field (:func:`.reference_field`).
    dead_below : float
        A gain below this fraction of the median gain is dead (default 0.1).
    noisy_above : float
        A scatter above this multiple of the median scatter is noisy (default 3).

    Returns
    -------
    BadElements

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> reps = np.ones((8, 4, 4)) + 0.01 * rng.standard_normal((8, 4, 4))
    >>> reps[:, 0, 0] = 0.01 * rng.standard_normal(8)            # no signal
    >>> reps[:, 2, 1] += 0.2 * rng.standard_normal(8)            # 20x the noise
    >>> bad = find_bad_elements(reps, np.ones((4, 4)))
    >>> [tuple(map(int, p)) for p in np.argwhere(bad.dead)], np.argwhere(bad.noisy).tolist()
    ([(0, 0)], [[2, 1]])
    """
    r = complex_field(repeats, "repeats", ndim=(3, 4))
    m = complex_field(model, "model")
    if r.shape[1:] != m.shape:
        raise ValueError(f"repeats must have shape (n, *model.shape) = (n, {m.shape}), got "
                         f"{r.shape}")
    if r.shape[0] < 2:
        raise ValueError("noisy elements are found from the scatter between repeats: record "
                         f"at least 2 (better 4), got {r.shape[0]}")
    if np.any(m == 0):
        raise ValueError("model must be non-zero at every element")
    if not (dead_below > 0 and noisy_above > 1):
        raise ValueError(f"need dead_below > 0 and noisy_above > 1, got {dead_below}, "
                         f"{noisy_above}")
    if m.ndim == 2:
        r, m = r[:, None], m[None]
    mean = r.mean(axis=0)
    gain = np.median(np.abs(mean / m), axis=0)
    var = np.sum(np.abs(r - mean) ** 2, axis=0) / (r.shape[0] - 1)
    scatter = np.sqrt(var.mean(axis=0))
    gain_ratio, scatter_ratio = _ratio(gain), _ratio(scatter)
    dead = gain_ratio < dead_below
    noisy = (scatter_ratio > noisy_above) & ~dead
    return BadElements(dead | noisy, dead, noisy, gain_ratio, scatter_ratio)


def interpolate_for_display(hologram: Hologram, mask: Any) -> Hologram:
    """Fill flagged elements from their neighbours, for a picture only.

    Each flagged element gets the mean of its (up to four) neighbours, flagged
    ones included: the discrete harmonic interpolation, solved exactly (a cluster
    of flagged elements gets a smooth fill). Good elements are kept as they are.
    Do not image or fit the result: the filled values were never measured.

    Parameters
    ----------
    hologram : Hologram
        A calibrated hologram (flagged elements 0).
    mask : array_like of bool, shape (ny, nx)
        True where an element is flagged (:attr:`Calibration.mask`).

    Returns
    -------
    Hologram

    Examples
    --------
    >>> x = np.arange(3) * 0.01
    >>> h = Hologram(np.array([[1.0, 2, 3], [4, 0, 6], [7, 8, 9]]), x, x, 9.9e9)
    >>> bad = np.zeros((3, 3), bool); bad[1, 1] = True
    >>> interpolate_for_display(h, bad).data[1, 1]
    np.complex128(5+0j)
    """
    if not isinstance(hologram, Hologram):
        raise ValueError(f"hologram must be a holoradar.Hologram, got {type(hologram).__name__}")
    ny, nx = hologram.shape[-2:]
    bad = element_mask(mask, (ny, nx))
    if not bad.any():
        return hologram
    n = int(bad.sum())
    index = -np.ones((ny, nx), int)
    index[bad] = np.arange(n)
    rows, cols, vals = [], [], []          # the flagged elements' equations
    k_rows, k_cols = [], []                # their good neighbours (flat index)
    for eq, (iy, ix) in enumerate(np.argwhere(bad)):
        nbrs = [(iy + dy, ix + dx) for dy, dx in ((-1, 0), (1, 0), (0, -1), (0, 1))
                if 0 <= iy + dy < ny and 0 <= ix + dx < nx]
        rows.append(eq)
        cols.append(eq)
        vals.append(float(len(nbrs)))
        for jy, jx in nbrs:
            if bad[jy, jx]:
                rows.append(eq)
                cols.append(int(index[jy, jx]))
                vals.append(-1.0)
            else:
                k_rows.append(eq)
                k_cols.append(jy * nx + jx)
    a = sp.csc_matrix((vals, (rows, cols)), shape=(n, n))
    b = sp.csr_matrix((np.ones(len(k_rows)), (k_rows, k_cols)), shape=(n, ny * nx))
    data = np.array(hologram.data, dtype=complex)
    flat = data.reshape(-1, ny * nx)
    rhs = (b @ flat.T).reshape(n, -1)          # (n, frames)
    lu = spla.splu(a)
    solved = lu.solve(np.ascontiguousarray(rhs.real)) + 1j * lu.solve(
        np.ascontiguousarray(rhs.imag))
    flat[:, bad.ravel()] = solved.T
    return hologram.with_data(flat.reshape(data.shape))
