"""Image metrics: peak position with sub-pixel refinement, widths, correlations."""

from __future__ import annotations

import numpy as np

from ..data.hologram import Image
from ..model.targets import PlanarTarget

__all__ = ["circle_fit", "main_lobe_width", "peak_position", "shape_correlation"]


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


def shape_correlation(image: Image, target: PlanarTarget) -> float:
    """Pearson correlation between ``|image|`` and a planar target's footprint.

    The target's reflectivity mask (|f| > 0) is sampled at the image's pixels
    (nearest target pixel; 0 outside its grid) and correlated with the image
    magnitude: 1 for an image proportional to the mask, ~0 for no resemblance.
    Used to judge how well an image shows a shape (paper Figs. 11, 22).

    Examples
    --------
    >>> from holoradar import Image, PlanarTarget
    >>> t = PlanarTarget.from_shape("disk", 0.4, diameter=0.1)
    >>> x = np.linspace(-0.1, 0.1, 41)
    >>> m = (x[None, :] ** 2 + x[:, None] ** 2 <= 0.05**2).astype(float)
    >>> shape_correlation(Image(m, x, x, np.array([0.4]), 1e10, has_z_axis=False), t) > 0.98
    True
    """
    a = np.abs(image.data)
    if image.has_z_axis:
        a = a.reshape((-1, *a.shape[-2:])).max(axis=0)
    a = a.reshape((-1, *a.shape[-2:]))[0]
    ix = np.clip(np.round((image.x - target.x[0]) / (target.x[1] - target.x[0])).astype(int),
                 -1, target.x.size)
    iy = np.clip(np.round((image.y - target.y[0]) / (target.y[1] - target.y[0])).astype(int),
                 -1, target.y.size)
    inside = ((iy[:, None] >= 0) & (iy[:, None] < target.y.size)
              & (ix[None, :] >= 0) & (ix[None, :] < target.x.size))
    mask = np.zeros(a.shape)
    fy = np.clip(iy, 0, target.y.size - 1)
    fx = np.clip(ix, 0, target.x.size - 1)
    mask[inside] = (np.abs(target.reflectivity) > 0)[np.ix_(fy, fx)][inside]
    return float(np.corrcoef(a.ravel(), mask.ravel())[0, 1])


def circle_fit(image: np.ndarray, x: np.ndarray, y: np.ndarray,
               level: float = 0.5) -> tuple[float, float, float]:
    """Diameter and centre ``(d, cx, cy)`` in metres of the circle through the
    bright pixels of a 2-D image (``|image| >= level * max``), by weighted
    algebraic least squares, ``x^2 + y^2 = 2 a x + 2 b y + c`` (weights
    ``sqrt|image|``): the outline of a disk imaged by its rim.

    Examples
    --------
    >>> x = y = np.linspace(-0.2, 0.2, 81)
    >>> X, Y = np.meshgrid(x, y)
    >>> ring = np.exp(-((np.hypot(X - 0.02, Y) - 0.09) / 0.01) ** 2)
    >>> [round(v, 2) for v in circle_fit(ring, x, y)]
    [0.18, 0.02, 0.0]
    """
    a = np.abs(np.asarray(image))
    if a.ndim != 2 or a.shape != (len(y), len(x)):
        raise ValueError(f"image must be 2-D of shape (len(y), len(x)) = ({len(y)}, "
                         f"{len(x)}), got {a.shape}")
    m = a >= level * a.max()
    Y, X = np.meshgrid(np.asarray(y, float), np.asarray(x, float), indexing="ij")
    w = np.sqrt(a[m])
    A = np.c_[2 * X[m], 2 * Y[m], np.ones(int(m.sum()))] * w[:, None]
    b = (X[m] ** 2 + Y[m] ** 2) * w
    (cx, cy, c), *_ = np.linalg.lstsq(A, b, rcond=None)
    return float(2 * np.sqrt(max(c + cx**2 + cy**2, 0.0))), float(cx), float(cy)
