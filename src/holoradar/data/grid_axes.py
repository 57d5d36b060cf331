"""Element coordinates as scanners write them: a reversed axis, and a grid rounded to
the digits of a text export.

A hologram's axes are strictly increasing and uniformly spaced (the angular
spectrum's FFT needs it). Two departures are common in measured files and mean
nothing physically:

* an axis written from its high end (a scan run backwards): the axis and the data
  along it are reversed together;
* coordinates written to a few decimals (``-64.1667`` mm for a pitch of 35/6 mm):
  the steps differ in their last digit. Where every coordinate lies within
  :data:`SNAP_FRACTION` of a pitch of the least-squares uniform grid, it is that
  grid: moving an element by ``d`` changes its phase by at most ``2 k d`` (a
  transceiver's round trip), ``4 pi / 1000`` rad = 0.7 degree for a pitch of half a
  wavelength -- far below any measured data's phase noise.

Each is said once (a :class:`CoordinateWarning`) with what was done.
"""

from __future__ import annotations

import warnings

import numpy as np

__all__ = ["SNAP_FRACTION", "CoordinateWarning", "regular_axis"]

SNAP_FRACTION = 1e-3
"""Coordinates this close to a uniform grid (in pitches) are snapped to it."""


class CoordinateWarning(UserWarning):
    """Element coordinates were put in order or snapped to their uniform grid."""


def regular_axis(values: np.ndarray, data: np.ndarray, name: str, axis: int
                 ) -> tuple[np.ndarray, np.ndarray]:
    """An axis (metres) made increasing and, within :data:`SNAP_FRACTION`, uniform; the data
    reversed along ``axis`` with it.

    Parameters
    ----------
    values : ndarray
        The coordinates as given (1-D, finite).
    data : ndarray
        The samples; ``axis`` is the one ``values`` label.
    name : str
        The axis's name in messages (``"x"``, ``"y"``).
    axis : int
        The data's axis.

    Returns
    -------
    (ndarray, ndarray)
        The axis and the data (the same objects where nothing was done).

    Examples
    --------
    >>> import warnings
    >>> x = np.round(np.arange(5) * 35 / 6, 4) * 1e-3        # mm to four decimals
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     ax, _ = regular_axis(x, np.zeros((2, 5)), "x", -1)
    >>> bool(np.allclose(np.diff(ax), np.diff(ax)[0], rtol=1e-12)), len(w)
    (True, 1)
    """
    v = np.asarray(values, float)
    if v.size < 2:
        return v, data
    d = np.diff(v)
    if np.all(d < 0):
        v, data = v[::-1].copy(), np.flip(data, axis=axis)
        warnings.warn(f"{name} was written from its high end (decreasing): the axis and the "
                      "data along it are reversed together", CoordinateWarning, stacklevel=4)
        d = -d[::-1]
    if np.any(d <= 0) or v.size < 3:
        return v, data      # the caller's check says what is wrong
    if np.max(np.abs(d - d.mean())) <= 1e-6 * abs(d.mean()):
        return v, data      # uniform already (the FFT's own tolerance): the usual case
    k = np.arange(v.size, dtype=float)
    step, start = np.polyfit(k, v, 1)
    grid = start + step * k
    off = float(np.max(np.abs(v - grid)))
    if off <= SNAP_FRACTION * step:
        warnings.warn(f"{name}: the coordinates lie within {off:.2g} m of a uniform grid of "
                      f"pitch {step:.6g} m (their written precision): snapped to it",
                      CoordinateWarning, stacklevel=4)
        return grid, data
    return v, data
