"""Normalised lateral Gaussian smoothing of (nz, ny, nx) fields, on a decimated grid.

The local noise statistics (:func:`~.noise.local_noise`) are Gaussian windows of
``sigma`` pixels (3 resolution cells, tens of pixels on an image sampled at
4 pixels per cell) over products of the residual image. Their output is smooth
on the scale of ``sigma``: its spectrum is the input's times
``exp(-p^2 sigma^2 / 2)``. So the windows are evaluated exactly at every
``D``-th pixel along x and y (``D = floor(sigma / DECIMATE_SIGMAS)``, the first and
last pixels always included) by the truncated kernel's rows as matrices (two
matrix products per field, all fields at once), and brought back to every pixel by
a cubic spline through those samples.

Accuracy. A cubic spline through samples ``D`` apart reproduces a mode of
wavenumber ``p`` to within ``(5/384) (p D)^4`` of its amplitude; the smoothed
field holds ``exp(-p^2 sigma^2/2)`` of it, and the product is largest near
``p sigma = 2``, where with ``D = sigma/3`` it is ``(5/384)(2/3)^4 exp(-2) = 3.5e-4``
of the input's amplitude at that wavenumber, spread over many wavenumbers: a
relative error of order ``1e-4`` of the smoothed field (measured: below
``2e-4`` on white noise). The estimates themselves scatter by
``1/sqrt(n_ref)``, about 10 % (``n_ref = 4 pi 3^2`` cells): the decimation
changes them by a thousandth of their own uncertainty.

The kernel is the whole Gaussian, zero outside the image, as in the FFT
convolution kept as the reference (:func:`gauss_1d`): on the retained pixels the
two agree to rounding. (It was cut at ``4 sigma`` while it was applied by FFT:
the cut weighs ``exp(-8) = 3e-4``, and where the window's edge crossed an object
30 dB above the noise it put a step of the noise's size into the estimate,
which no interpolation follows; uncut, the window costs nothing more.)
"""

from __future__ import annotations

import numpy as np

__all__ = ["DECIMATE_SIGMAS", "LateralSmoother", "gauss_1d", "kernel_rows", "spline_matrix"]

DECIMATE_SIGMAS = 2.0
"""The decimation step in kernel standard deviations: ``D = floor(sigma / 2)`` pixels."""

_MIN_SAMPLES = 8
"""At least this many samples along an axis (a kernel wider than the image)."""


def gauss_1d(a: np.ndarray, sigma: float, axis: int) -> np.ndarray:
    """Gaussian convolution along ``axis``, zero outside, by FFT (the reference).

    The kernel is ``exp(-0.5 (j/sigma)^2)`` for every ``|j| < n`` (not truncated),
    unnormalised (the normalised smoothing divides by the smoothed weights).
    """
    n = a.shape[axis]
    half = n
    k = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma) ** 2)
    size = 1 << int(np.ceil(np.log2(n + 2 * half + 1)))
    K = np.fft.rfft(k, size)
    shape = [1] * a.ndim
    shape[axis] = K.size
    out = np.fft.irfft(np.fft.rfft(a, size, axis=axis) * K.reshape(shape), size, axis=axis)
    return np.take(out, np.arange(half, half + n), axis=axis)


def kernel_rows(n: int, sigma: float, rows: np.ndarray) -> np.ndarray:
    """Rows ``rows`` of :func:`gauss_1d`'s convolution as a matrix, (len(rows), n)."""
    d = rows[:, None].astype(float) - np.arange(n)[None, :]
    return np.exp(-0.5 * (d / sigma) ** 2)


def _samples(n: int, sigma: float, decimate: bool) -> np.ndarray:
    """The retained pixels along an axis of ``n``: every D-th, the last included."""
    step = int(sigma // DECIMATE_SIGMAS) if decimate else 1
    step = max(1, min(step, (n - 1) // (_MIN_SAMPLES - 1) if n > _MIN_SAMPLES else 1))
    return np.unique(np.r_[np.arange(0, n, step), n - 1])


def spline_matrix(rows: np.ndarray, n: int) -> np.ndarray:
    """Cubic-spline interpolation from samples at ``rows`` to every pixel, (n, len(rows)).

    The not-a-knot spline (third derivative continuous at the second and the last
    but one knot; ``scipy.interpolate.CubicSpline``'s default): its second
    derivatives ``M`` solve the tridiagonal system, written here as dense
    matrices (a few tens of knots).
    """
    if rows.size == n:
        return np.eye(n)
    t = rows.astype(float)
    m = t.size
    h = np.diff(t)
    if m < 4:   # too few knots for a cubic: linear
        out = np.zeros((n, m))
        xs = np.arange(n, dtype=float)
        i = np.clip(np.searchsorted(t, xs, side="right") - 1, 0, m - 2)
        f = (xs - t[i]) / h[i]
        out[np.arange(n), i] = 1 - f
        out[np.arange(n), i + 1] = f
        return out
    A = np.zeros((m, m))
    B = np.zeros((m, m))
    for i in range(1, m - 1):
        A[i, i - 1:i + 2] = h[i - 1], 2 * (h[i - 1] + h[i]), h[i]
        B[i, i - 1:i + 2] = 6 / h[i - 1], -6 / h[i - 1] - 6 / h[i], 6 / h[i]
    A[0, :3] = h[1], -(h[0] + h[1]), h[0]
    A[-1, -3:] = h[-1], -(h[-2] + h[-1]), h[-2]
    Mc = np.linalg.solve(A, B)                  # second derivatives per unit sample
    xs = np.arange(n, dtype=float)
    i = np.clip(np.searchsorted(t, xs, side="right") - 1, 0, m - 2)
    hi = h[i]
    a = (t[i + 1] - xs) / hi
    b = (xs - t[i]) / hi
    out = np.zeros((n, m))
    r = np.arange(n)
    out[r, i] += a
    out[r, i + 1] += b
    out += ((a ** 3 - a) * hi ** 2 / 6)[:, None] * Mc[i]
    out += ((b ** 3 - b) * hi ** 2 / 6)[:, None] * Mc[i + 1]
    return out


class LateralSmoother:
    """``G*(w a) / G*w`` along x and y for fields of shape (nz, ny, nx).

    Parameters
    ----------
    w : ndarray, (ny, nx)
        Weights (0: the pixel is left out).
    sx, sy : float
        Kernel standard deviations along x and y, pixels.
    decimate : bool
        Evaluate on every ``D``-th pixel and interpolate (module notes); False: every
        pixel (the reference).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> a = rng.normal(size=(2, 60, 70))
    >>> s = LateralSmoother(np.ones((60, 70)), 9.0, 9.0)
    >>> ref = LateralSmoother(np.ones((60, 70)), 9.0, 9.0, decimate=False)
    >>> bool(np.max(np.abs(s.full(s.coarse(a)) - ref.full(ref.coarse(a)))) < 1e-3)
    True
    """

    def __init__(self, w: np.ndarray, sx: float, sy: float, decimate: bool = True) -> None:
        ny, nx = w.shape
        self.shape = (ny, nx)
        self.rows_x = _samples(nx, sx, decimate)
        self.rows_y = _samples(ny, sy, decimate)
        self.kx = kernel_rows(nx, sx, self.rows_x)          # (nxc, nx)
        self.ky = kernel_rows(ny, sy, self.rows_y)          # (nyc, ny)
        self.w = np.asarray(w, float)
        self.ones = bool(np.all(self.w == 1.0))
        den = self.ky @ self.w @ self.kx.T
        # As the reference: pixels whose window holds (almost) no weight are left out.
        self.inv_den = np.where(den > 1e-9 * den.max(), 1.0 / np.where(den > 0, den, 1.0), 0.0)
        self._ix: np.ndarray | None = None
        self._iy: np.ndarray | None = None

    def coarse(self, a: np.ndarray) -> np.ndarray:
        """The normalised smoothing of ``a`` (..., ny, nx) on the retained pixels,
        (..., nyc, nxc)."""
        nx = self.shape[1]
        b = a if self.ones else a * self.w
        b = (b.reshape(-1, nx) @ self.kx.T).reshape(*a.shape[:-1], -1)   # (..., ny, nxc)
        b = np.matmul(self.ky, b)                                        # (..., nyc, nxc)
        return b * self.inv_den

    def full(self, c: np.ndarray) -> np.ndarray:
        """Interpolate retained-pixel values (..., nyc, nxc) to every pixel (..., ny, nx)."""
        ny, nx = self.shape
        if self.rows_x.size == nx and self.rows_y.size == ny:
            return c
        if self._ix is None:
            self._ix = spline_matrix(self.rows_x, nx)
            self._iy = spline_matrix(self.rows_y, ny)
        assert self._iy is not None
        return np.matmul(self._iy, c @ self._ix.T)
