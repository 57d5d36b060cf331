"""Image metrics: peak position with sub-pixel refinement, widths, correlations."""

from __future__ import annotations

import numpy as np

from ..data.hologram import Image

__all__ = ["main_lobe_width", "peak_position"]


def _parabolic(a: np.ndarray, i: int, *, log: bool = False) -> float:
    """Sub-sample offset of the extremum of a sampled peak from three points.

    With ``log`` the parabola goes through the logarithms (exact for a Gaussian peak).
    """
    if i <= 0 or i >= a.size - 1:
        return 0.0
    y0, y1, y2 = a[i - 1], a[i], a[i + 1]
    if log:
        if min(y0, y1, y2) <= 0:
            return 0.0
        y0, y1, y2 = np.log(y0), np.log(y1), np.log(y2)
    den = y0 - 2 * y1 + y2
    return 0.0 if den == 0 else float(0.5 * (y0 - y2) / den)


def peak_position(image: Image, *, refine: bool = True) -> tuple[float, float, float]:
    """``(x, y, z)`` of the brightest point of ``|image|``, metres.

    With ``refine`` each coordinate is refined by a parabola through the
    logarithms of the peak sample's intensity and its two neighbours along that
    axis: exact for a Gaussian peak, and close for the sinc^2 of a focus.

    Examples
    --------
    >>> import numpy as np
    >>> from holoradar import Image
    >>> d = np.exp(-((np.arange(9) - 4.3) ** 2))[None, None, :] * np.ones((1, 3, 1))
    >>> round(peak_position(Image(d, np.arange(9.0), np.arange(3.0), np.array([1.0]), 1e9))[0], 1)
    4.3
    """
    a = np.abs(image.data) ** 2
    if not image.has_z_axis:
        a = a[..., None, :, :]
    a = a.reshape((-1, *a.shape[-3:])).max(axis=0)
    iz, iy, ix = np.unravel_index(int(np.argmax(a)), a.shape)
    coords = []
    for axis_vals, prof, i in ((image.x, a[iz, iy, :], ix), (image.y, a[iz, :, ix], iy),
                               (image.z, a[:, iy, ix], iz)):
        if refine and axis_vals.size > 2:
            off = _parabolic(prof, i, log=True)
            step = axis_vals[min(i + 1, axis_vals.size - 1)] - axis_vals[max(i - 1, 0)]
            step /= (min(i + 1, axis_vals.size - 1) - max(i - 1, 0))
            coords.append(float(axis_vals[i] + off * step))
        else:
            coords.append(float(axis_vals[i]))
    return coords[0], coords[1], coords[2]


def main_lobe_width(profile: np.ndarray, coords: np.ndarray) -> float:
    """Distance between the first minima on each side of the maximum of ``|profile|``.

    For a sinc-shaped point image ``sin(mu*x)/x`` this is ``2*pi/mu = 2*delta``.
    Minima are located to sub-sample accuracy with parabolas.
    """
    a = np.abs(np.asarray(profile))
    i = int(np.argmax(a))
    j = i
    while j + 1 < a.size and a[j + 1] < a[j]:
        j += 1
    m = i
    while m - 1 >= 0 and a[m - 1] < a[m]:
        m -= 1
    step = float(coords[1] - coords[0])
    right = coords[j] + _parabolic(-a, j) * step
    left = coords[m] + _parabolic(-a, m) * step
    return float(right - left)
