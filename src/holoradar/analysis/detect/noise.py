"""The image's own noise, its resolution cell, and the detection threshold.

Noise model. Receiver noise, white across the elements, back-propagates into an
image whose noise is a circular complex Gaussian field: ``|I|^2`` is exponential
with mean ``sigma^2``. ``sigma^2`` is estimated per plane as the mean of ``|R|^2``
over the residual image ``R`` (the image less the models of the objects found),
excluding the main lobes of the objects found (:func:`plane_noise`).

Resolution cell. The field's smoothness is its spectral spread: along an axis with
wavenumber ``p`` it is ``lambda_p = Var(p)`` under the noise's power spectrum
(lateral axes: a Hann-windowed FFT of each plane; range: finite differences between
planes, the mean wavenumber removed). A field whose spectrum filled a band
``|p| <= P`` uniformly has ``lambda_p = P^2/3`` and independent samples at
``pi/P``; the cell along each axis is that equivalent band's sample spacing,
``c = pi/sqrt(3 lambda_p)`` (the element pitch for an array coarser than lambda/2,
whose image noise fills its whole Nyquist band).

Threshold. An object is a local maximum of ``|R|^2/sigma^2`` above ``t``. For a
smooth chi-square field of two degrees of freedom the expected number of local
maxima above a high ``t`` is the expected Euler characteristic of the excursion set
(Worsley 1994, Adv. Appl. Prob. 26, 13; EC densities of chi^2_2, ``u = 2t``). In
cells along each axis (``n_i`` cells), for a box,

    E(t) = e^{-t} [1 + a sqrt(2t) sum n_i + a^2 (2t - 1) sum_{i<j} n_i n_j
                   + a^3 sqrt(2t)(2t - 3) n_x n_y n_z],     a = sqrt(pi/6),

since ``sqrt(lambda/(2 pi)) c = sqrt(pi/6)``. ``sigma^2`` is itself estimated from
``N`` independent cells of the plane: with ``X = sigma_hat^2/sigma^2 ~ Gamma(N, 1/N)``
each term's ``t^m e^{-t}`` is replaced by its expectation over ``X`` (cell-averaging
CFAR: ``E e^{-tX} = (1 + t/N)^{-N}``). ``t`` solves ``E(t) = false_alarm *
prod(max(n_i, 1))``: ``false_alarm`` is the expected number of false objects per
resolution cell (:func:`threshold`). The peak search must see the field's maxima:
the image sampled at several pixels per cell (``migrate(upsample=4)`` or finer);
on a grid of one pixel per cell the rate falls below the nominal one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._lazy import lazy_module

_opt = lazy_module("scipy.optimize")  # imported on first use: see holoradar._lazy
_special = lazy_module("scipy.special")

__all__ = ["NoiseModel", "box_resels", "expected_false_peaks",
           "local_noise", "spectral_cells", "threshold", "threshold_resels"]

_A = np.sqrt(np.pi / 6)  # sqrt(lambda/(2 pi)) times the cell pi/sqrt(3 lambda)


@dataclass(frozen=True)
class NoiseModel:
    """The image noise and the threshold derived from it.

    Attributes
    ----------
    sigma2 : ndarray, shape (nz, ny, nx)
        Local noise variance ``E|I|^2`` (the image's units squared).
    cell : tuple of float
        Resolution cell along x, y and range from the residual's whole spectrum,
        metres (range: ``inf`` for fewer than 3 planes).
    n_cells : float
        Resolution cells in the image: the top resel count in cell units.
    resels : tuple of float
        Lipschitz-Killing curvatures ``(R0, R1, R2, R3)`` of the search region in the
        field's own metric, over ``(2 pi)^(d/2)``.
    n_ref : float
        Independent cells behind each local ``sigma2`` estimate.
    t : float
        Threshold on ``|R|^2 / sigma^2`` (dimensionless).
    """

    sigma2: np.ndarray
    cell: tuple[float, float, float]
    n_cells: float
    resels: tuple[float, float, float, float]
    n_ref: float
    t: float


def _gamma_moment(a: float, t: float, n: float) -> float:
    """``E[X^a exp(-t X)]`` for ``X ~ Gamma(n, 1/n)`` (``n = inf``: ``exp(-t)``)."""
    if not np.isfinite(n):
        return float(np.exp(-t))
    return float(np.exp(_special.gammaln(n + a) - _special.gammaln(n) - a * np.log(n)
                        - (n + a) * np.log1p(t / n)))


def expected_false_peaks(t: float, resels: tuple[float, ...], n_ref: float = np.inf) -> float:
    """Expected number of noise maxima above ``t`` (the EC approximation, module notes).

    Parameters
    ----------
    t : float
        Threshold on ``|I|^2 / sigma_hat^2``.
    resels : tuple of float
        ``(R0, R1, R2, R3)``: the search region's Lipschitz-Killing curvatures in the
        field's metric over ``(2 pi)^(d/2)``; a box of ``n_i`` cells has
        ``R0 = 1``, ``R1 = a sum n_i``, ``R2 = a^2 sum_{i<j} n_i n_j``,
        ``R3 = a^3 n_x n_y n_z`` (:func:`box_resels`).
    n_ref : float
        Independent cells behind the estimate ``sigma_hat^2`` (``inf``: known exactly).

    Returns
    -------
    float
        The expected Euler characteristic of the excursion set, the number of
        false objects at high ``t``.

    Examples
    --------
    >>> round(expected_false_peaks(np.log(1000), box_resels((1.0, 0.0, 0.0))) * 1000, 2)
    3.69
    """
    r0, r1, r2, r3 = (float(v) for v in resels)
    m0 = _gamma_moment(0.0, t, n_ref)
    mh = _gamma_moment(0.5, t, n_ref)
    m1 = _gamma_moment(1.0, t, n_ref)
    m3h = _gamma_moment(1.5, t, n_ref)
    r2t = np.sqrt(2 * t)
    return float(r0 * m0 + r1 * r2t * mh + r2 * (2 * t * m1 - m0)
                 + r3 * ((2 * t) ** 1.5 * m3h - 3 * r2t * mh))


def box_resels(n_cells: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """Resels of a box of ``n_i`` cells along each axis (0 for an absent axis).

    Examples
    --------
    >>> [round(v, 4) for v in box_resels((2.0, 3.0, 0.0))]
    [1.0, 3.618, 3.1416, 0.0]
    """
    n = [float(v) for v in n_cells]
    s2 = n[0] * n[1] + n[1] * n[2] + n[0] * n[2]
    return (1.0, float(_A * sum(n)), float(_A**2 * s2), float(_A**3 * n[0] * n[1] * n[2]))


def threshold_resels(target: float, resels: tuple[float, ...], n_ref: float = np.inf) -> float:
    """The ``t`` at which :func:`expected_false_peaks` equals ``target`` false objects.

    Examples
    --------
    >>> r = box_resels((16.0, 16.0, 0.0))
    >>> t = threshold_resels(0.256, r)
    >>> round(expected_false_peaks(t, r), 6)
    0.256
    """
    def f(t: float) -> float:
        return np.log(max(expected_false_peaks(t, resels, n_ref), 1e-300)) - np.log(target)

    lo, hi = 2.0, 10.0  # the EC approximation holds for high thresholds only
    while f(hi) > 0 and hi < 1e4:
        hi *= 2
    if f(lo) < 0:
        return lo
    return float(_opt.brentq(f, lo, hi, xtol=1e-10))


def threshold(false_alarm: float, n_cells: tuple[float, float, float],
              n_ref: float = np.inf) -> float:
    """Threshold for ``false_alarm`` false objects per cell in a box of ``n_i`` cells.

    Examples
    --------
    >>> round(threshold(1e-3, (16.0, 16.0, 0.0)), 3)
    9.154
    """
    total = float(np.prod([max(float(v), 1.0) for v in n_cells]))
    return threshold_resels(false_alarm * total, box_resels(n_cells), n_ref)


def _lateral_spread(data: np.ndarray, step: float, axis: int) -> float:
    """Spectral variance ``Var(p)`` (rad^2/m^2) along a lateral axis of (nz, ny, nx) data."""
    n = data.shape[axis]
    if n < 3:
        return np.nan
    w = np.hanning(n + 2)[1:-1]
    shape = [1, 1, 1]
    shape[axis] = n
    F = np.fft.fft(data * w.reshape(shape), axis=axis)
    P = np.sum(np.abs(F) ** 2, axis=tuple(a for a in range(3) if a != axis))
    p = 2 * np.pi * np.fft.fftfreq(n, step)
    if P.sum() <= 0:
        return np.nan
    P = P / P.sum()
    # The mean on the circle of the FFT's period (a ramp's spectrum may straddle its edge).
    period = 2 * np.pi / step
    mean = np.angle(np.sum(P * np.exp(1j * p * step))) / step
    d = (p - mean + period / 2) % period - period / 2
    var = float(np.sum(P * d * d))
    # The Hann window convolves the spectrum with its own, whose variance is
    # int|w'|^2 / int|w|^2 = (4/3) (pi/L)^2 for w = sin^2(pi x/L) over L = n*step.
    return max(var - (4.0 / 3.0) * (np.pi / (n * step)) ** 2, 0.0)


def _range_spread(data: np.ndarray, z: np.ndarray) -> float:
    """Spectral variance of the range wavenumber from differences between planes."""
    if data.shape[0] < 3:
        return np.nan
    d = np.gradient(data, z, axis=0)
    e = float(np.mean(np.abs(data) ** 2))
    if e <= 0:
        return np.nan
    m1 = np.mean(np.conj(data) * d) / e       # i * (mean range wavenumber)
    return max(float(np.mean(np.abs(d) ** 2)) / e - abs(m1) ** 2, 0.0)


def spectral_cells(data: np.ndarray, x: np.ndarray, y: np.ndarray, z: np.ndarray
                   ) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Resolution cells (metres) and their numbers along x, y and range.

    Parameters
    ----------
    data : ndarray, complex, shape (nz, ny, nx)
        The noise-dominated (residual) image.
    x, y, z : ndarray
        Its coordinates, metres.

    Returns
    -------
    cell, n_cells : tuple of float
        ``c = pi/sqrt(3 Var(p))`` along each axis and the extent over ``c`` (the
        extent of n pixels being n steps); one plane: ``inf`` and 0 along range.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> d = (rng.normal(size=(1, 64, 64)) + 1j * rng.normal(size=(1, 64, 64)))
    >>> cell, n = spectral_cells(d, np.arange(64) * 0.01, np.arange(64) * 0.01, np.array([0.3]))
    >>> 0.009 < cell[0] < 0.011, n[2]
    (True, 0.0)
    """
    cells: list[float] = []
    counts: list[float] = []
    for axis, coord in ((2, x), (1, y)):
        step = float(coord[1] - coord[0]) if coord.size > 1 else np.nan
        lam = _lateral_spread(data, step, axis) if coord.size > 2 else np.nan
        c = np.pi / np.sqrt(3 * lam) if np.isfinite(lam) and lam > 0 else np.inf
        cells.append(float(c))
        counts.append(float(coord.size * step / c) if np.isfinite(c) else 0.0)
    if data.shape[0] >= 3:
        lam = _range_spread(data, z)
        c = np.pi / np.sqrt(3 * lam) if np.isfinite(lam) and lam > 0 else np.inf
        extent = float(z[-1] - z[0]) * data.shape[0] / (data.shape[0] - 1)
        cells.append(float(c))
        counts.append(extent / c if np.isfinite(c) else 0.0)
    else:
        cells.append(np.inf)
        counts.append(0.0)
    return (cells[0], cells[1], cells[2]), (counts[0], counts[1], counts[2])


def _d5(a: np.ndarray, step: float, axis: int) -> np.ndarray:
    """Derivative along ``axis`` by the 5-point stencil (1 % low at a quarter of the
    sampling rate, where a 4-times upsampled image's band ends), 3-point at the edges."""
    n = a.shape[axis]
    if n < 3:
        return np.zeros_like(a)
    d = np.gradient(a, step, axis=axis)
    if n >= 5:
        s = [slice(None)] * a.ndim

        def take(lo: int, hi: int | None) -> np.ndarray:
            s2 = list(s)
            s2[axis] = slice(lo, hi)
            return a[tuple(s2)]

        inner = (-take(4, None) + 8 * take(3, -1) - 8 * take(1, -3) + take(0, -4)) / (12 * step)
        s[axis] = slice(2, -2)
        d[tuple(s)] = inner
    return d


def _gauss_1d(a: np.ndarray, sigma: float, axis: int) -> np.ndarray:
    """Gaussian convolution along ``axis``, zero outside (by FFT: the windows are
    tens of pixels wide)."""
    n = a.shape[axis]
    half = min(int(np.ceil(4 * sigma)), n)
    k = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma) ** 2)
    size = 1 << int(np.ceil(np.log2(n + 2 * half + 1)))
    K = np.fft.rfft(k, size)
    shape = [1] * a.ndim
    shape[axis] = K.size
    out = np.fft.irfft(np.fft.rfft(a, size, axis=axis) * K.reshape(shape), size, axis=axis)
    return np.take(out, np.arange(half, half + n), axis=axis)


def _smooth(a: np.ndarray, w: np.ndarray, sx: float, sy: float) -> np.ndarray:
    """Normalised Gaussian smoothing of (nz, ny, nx) ``a`` laterally with weights ``w``
    (ny, nx): ``G*(w a) / G*w`` (pixels with w = 0 are left out)."""
    num = _gauss_1d(_gauss_1d(a * w, sx, 2), sy, 1)
    den = _gauss_1d(_gauss_1d(w[None].astype(float), sx, 2), sy, 1)
    return num / np.where(den > 1e-9 * den.max(), den, np.inf)


SMOOTH_CELLS = 3.0
"""Standard deviation of the Gaussian window of the local noise estimates, in cells."""


def local_noise(residual: np.ndarray, mask: np.ndarray, x: np.ndarray, y: np.ndarray,
                z: np.ndarray, false_alarm: float) -> NoiseModel:
    """Local noise variance, resels and threshold of a residual image (module notes).

    The noise of an image through a finite aperture is not stationary: its variance
    falls towards the footprint's edges (to 0.7 of the centre's for a 32 x 32 array
    at lambda/2, 30 cm away), and its local spectrum is centred on the direction of
    the aperture seen from each pixel. So ``sigma^2(r)`` and the demodulated
    derivative covariance ``Lambda(r) = S[grad I grad I^*]/S[|I|^2] - m m^T``
    (``m = Im S[I^* grad I]/S[|I|^2]``, ``S`` a Gaussian window of
    :data:`SMOOTH_CELLS` cells, the objects' main lobes left out) are local, and
    the Euler characteristic's Lipschitz-Killing curvatures are the integrals of
    ``sqrt(det Lambda)`` over the image, its faces and its edges (Adler & Taylor,
    *Random Fields and Geometry*, 2007, ch. 12).

    Parameters
    ----------
    residual : ndarray, complex, (nz, ny, nx)
    mask : ndarray of bool, (ny, nx)
        Pixels to leave out of the estimates (objects' main lobes).
    x, y, z : ndarray
        Coordinates, metres (x, y uniform).
    false_alarm : float
        Expected false objects per resolution cell.

    Returns
    -------
    NoiseModel

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> d = rng.normal(size=(1, 96, 96)) + 1j * rng.normal(size=(1, 96, 96))
    >>> from scipy.ndimage import gaussian_filter
    >>> d = gaussian_filter(d.real, (0, 2, 2)) + 1j * gaussian_filter(d.imag, (0, 2, 2))
    >>> nm = local_noise(d, np.zeros((96, 96), bool), np.arange(96.0), np.arange(96.0),
    ...                  np.array([1.0]), 1e-3)
    >>> bool(8 < nm.t < 11)
    True
    """
    nz, ny, nx = residual.shape
    dx, dy = float(x[1] - x[0]), float(y[1] - y[0])
    cell, _ = spectral_cells(residual, x, y, z)
    cx = cell[0] if np.isfinite(cell[0]) else nx * dx
    cy = cell[1] if np.isfinite(cell[1]) else ny * dy
    sx, sy = SMOOTH_CELLS * cx / dx, SMOOTH_CELLS * cy / dy
    w = (~mask).astype(float) if (~mask).sum() >= max(4, mask.size // 8) else np.ones(mask.shape)
    p = np.abs(residual) ** 2
    sigma2 = _smooth(p, w, sx, sy)
    sigma2 = np.where(np.isfinite(sigma2) & (sigma2 > 0), sigma2, np.nanmax(sigma2))

    # The local mean wavenumber over a narrower window (one cell): the image of noise
    # through a finite aperture is chirped (its local spectrum centred on the aperture's
    # direction from each pixel), and the chirp across the wide window would count as
    # spread. The derivatives are demodulated by it pixel by pixel.
    p1 = _smooth(p, w, sx / SMOOTH_CELLS, sy / SMOOTH_CELLS)
    p1 = np.where(p1 > 0, p1, np.inf)

    def demodulated(d: np.ndarray) -> np.ndarray:
        m = _smooth((np.conj(residual) * d).imag, w, sx / SMOOTH_CELLS, sy / SMOOTH_CELLS) / p1
        return d - 1j * m * residual

    gx = demodulated(_d5(residual, dx, 2))
    gy = demodulated(_d5(residual, dy, 1))
    lxx = _smooth(np.abs(gx) ** 2, w, sx, sy) / sigma2
    lyy = _smooth(np.abs(gy) ** 2, w, sx, sy) / sigma2
    lxy = _smooth((np.conj(gx) * gy).real, w, sx, sy) / sigma2
    lxx, lyy = np.maximum(lxx, 0), np.maximum(lyy, 0)
    det2 = np.maximum(lxx * lyy - lxy * lxy, 0)
    two_pi = 2 * np.pi
    volume_3d = nz >= 3
    if volume_3d:
        dz = np.gradient(z)
        gz = np.gradient(residual, z, axis=0)
        mz = _smooth((np.conj(residual) * gz).imag, w, sx, sy) / sigma2
        lzz = np.maximum(_smooth(np.abs(gz) ** 2, w, sx, sy) / sigma2 - mz * mz, 0)
        r3 = float(np.sum(np.sqrt(det2 * lzz) * dz[:, None, None]) * dx * dy / two_pi ** 1.5)
        # Half the surface: the x-y faces (first and last plane), the x-z and y-z faces.
        r2 = 0.5 * (float(np.sum(np.sqrt(det2[[0, -1]]))) * dx * dy
                    + float(np.sum(np.sqrt(lxx[:, [0, -1], :] * lzz[:, [0, -1], :])
                                   * dz[:, None, None])) * dx
                    + float(np.sum(np.sqrt(lyy[:, :, [0, -1]] * lzz[:, :, [0, -1]])
                                   * dz[:, None, None])) * dy) / two_pi
        # A quarter of the edges' length.
        r1 = 0.25 * (float(np.sum(np.sqrt(lxx[[0, 0, -1, -1]][:, [0, -1, 0, -1]]))) * dx
                     + float(np.sum(np.sqrt(lyy[[0, 0, -1, -1]][:, :, [0, -1, 0, -1]]))) * dy
                     + float(np.sum(np.sqrt(lzz[:, [0, 0, -1, -1], [0, -1, 0, -1]])
                                    * dz[:, None]))) / np.sqrt(two_pi)
        resels = (1.0, r1, r2, r3)
        n_cells = r3 * (6 / np.pi) ** 1.5
    else:
        # Each plane searched on its own: their curvatures add.
        r2 = float(np.sum(np.sqrt(det2))) * dx * dy / two_pi
        r1 = 0.5 * (float(np.sum(np.sqrt(lxx[:, [0, -1], :]))) * dx
                    + float(np.sum(np.sqrt(lyy[:, :, [0, -1]]))) * dy) / np.sqrt(two_pi)
        resels = (float(nz), r1, r2, 0.0)
        n_cells = r2 * 6 / np.pi
    # sigma^2(r) averages the Gaussian window's effective 4 pi s_x s_y / (c_x c_y) cells.
    n_ref = max(4 * np.pi * SMOOTH_CELLS**2, 1.0)
    t = threshold_resels(false_alarm * max(n_cells, 1.0), resels, n_ref)
    return NoiseModel(sigma2, (cx, cy, cell[2]), float(n_cells), resels, n_ref, t)
