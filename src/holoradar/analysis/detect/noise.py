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

import zlib
from dataclasses import dataclass

import numpy as np

from ..._lazy import lazy_module
from .smooth import LateralSmoother, gauss_1d, spline_matrix

_opt = lazy_module("scipy.optimize")  # imported on first use: see holoradar._lazy
_special = lazy_module("scipy.special")
_fft = lazy_module("scipy.fft")

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
    F = _fft.fft(data * w.reshape(shape), axis=axis, overwrite_x=True)
    spec = "zyx,zyx->" + "zyx"[axis]
    P = np.einsum(spec, F.real, F.real) + np.einsum(spec, F.imag, F.imag)
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


def _range_spread(data: np.ndarray, z: np.ndarray, d: np.ndarray | None = None) -> float:
    """Spectral variance of the range wavenumber from differences between planes
    (``d``: ``np.gradient(data, z, axis=0)`` when already at hand)."""
    if data.shape[0] < 3:
        return np.nan
    if d is None:
        d = np.gradient(data, z, axis=0)
    e = float(np.vdot(data, data).real) / data.size
    if e <= 0:
        return np.nan
    m1 = np.vdot(data, d) / data.size / e       # i * (mean range wavenumber)
    return max(float(np.vdot(d, d).real) / data.size / e - abs(m1) ** 2, 0.0)


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
    return _cells(data, x, y, z)


def _cells(data: np.ndarray, x: np.ndarray, y: np.ndarray, z: np.ndarray,
           gz: np.ndarray | None = None
           ) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """:func:`spectral_cells`, the range derivative ``gz`` given when at hand."""
    cells: list[float] = []
    counts: list[float] = []
    for axis, coord in ((2, x), (1, y)):
        step = float(coord[1] - coord[0]) if coord.size > 1 else np.nan
        lam = _lateral_spread(data, step, axis) if coord.size > 2 else np.nan
        c = np.pi / np.sqrt(3 * lam) if np.isfinite(lam) and lam > 0 else np.inf
        cells.append(float(c))
        counts.append(float(coord.size * step / c) if np.isfinite(c) else 0.0)
    if data.shape[0] >= 3:
        lam = _range_spread(data, z, gz)
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
    sampling rate, where a 4-times upsampled image's band ends), 3-point at the edges
    (``np.gradient``'s: central next to the edges, one-sided on them)."""
    n = a.shape[axis]
    if n < 3:
        return np.zeros_like(a)
    if n < 5:
        return np.gradient(a, step, axis=axis)
    b = np.moveaxis(a, axis, -1)
    d = np.empty_like(b)
    d[..., 2:-2] = (b[..., :-4] - b[..., 4:] + 8 * (b[..., 3:-1] - b[..., 1:-3])) / (12 * step)
    d[..., 0] = (b[..., 1] - b[..., 0]) / step
    d[..., -1] = (b[..., -1] - b[..., -2]) / step
    d[..., 1] = (b[..., 2] - b[..., 0]) / (2 * step)
    d[..., -2] = (b[..., -1] - b[..., -3]) / (2 * step)
    return np.moveaxis(d, -1, axis)


def _dz(a: np.ndarray, z: np.ndarray) -> np.ndarray:
    """``np.gradient(a, z, axis=0)``; on uniform planes by its formula written out
    (central differences inside, one-sided on the first and last plane), without
    the general case's temporaries."""
    d = np.diff(z)
    if np.ptp(d) > 1e-9 * abs(d[0]):
        return np.gradient(a, z, axis=0)
    out = np.empty_like(a)
    np.subtract(a[2:], a[:-2], out=out[1:-1])
    out[1:-1] *= 1.0 / (z[2] - z[0])
    out[0] = (a[1] - a[0]) / d[0]
    out[-1] = (a[-1] - a[-2]) / d[-1]
    return out


def _smooth(a: np.ndarray, w: np.ndarray, sx: float, sy: float) -> np.ndarray:
    """Normalised Gaussian smoothing of (nz, ny, nx) ``a`` laterally with weights ``w``
    (ny, nx): ``G*(w a) / G*w`` (pixels with w = 0 are left out), by FFT on every pixel
    (the reference of :class:`~.smooth.LateralSmoother`)."""
    num = gauss_1d(gauss_1d(a * w, sx, 2), sy, 1)
    den = gauss_1d(gauss_1d(w[None].astype(float), sx, 2), sy, 1)
    return num / np.where(den > 1e-9 * den.max(), den, np.inf)


SMOOTH_CELLS = 3.0
"""Standard deviation of the Gaussian window of the local noise estimates, in cells."""


def local_noise(residual: np.ndarray, mask: np.ndarray, x: np.ndarray, y: np.ndarray,
                z: np.ndarray, false_alarm: float, *, decimate: bool = True) -> NoiseModel:
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
    key = _fingerprint(residual, mask, x, y, z, false_alarm, decimate)
    if _LAST and _LAST[0] == key:
        return _LAST[1]
    nz, ny, nx = residual.shape
    dx, dy = float(x[1] - x[0]), float(y[1] - y[0])
    gz_all = _dz(residual, z) if nz >= 3 else None
    cell, _ = _cells(residual, x, y, z, gz_all)
    cx = cell[0] if np.isfinite(cell[0]) else nx * dx
    cy = cell[1] if np.isfinite(cell[1]) else ny * dy
    sx, sy = SMOOTH_CELLS * cx / dx, SMOOTH_CELLS * cy / dy
    w = (~mask).astype(float) if (~mask).sum() >= max(4, mask.size // 8) else np.ones(mask.shape)
    wide = LateralSmoother(w, sx, sy, decimate)
    narrow = LateralSmoother(w, sx / SMOOTH_CELLS, sy / SMOOTH_CELLS, decimate)
    s2 = wide.coarse(residual.real ** 2 + residual.imag ** 2)
    s2 = np.where(np.isfinite(s2) & (s2 > 0), s2, np.nanmax(s2))
    # The map interpolated in its logarithm: by a bright object it spans decades (a
    # Gaussian bump, whose logarithm is a parabola that the spline follows).
    sigma2 = np.exp(wide.full(np.log(s2))) if decimate else s2

    # The derivative covariance on every k-th plane (range_planes), brought back to
    # every plane by a spline (module notes of .smooth).
    planes = range_planes(z, cell[2]) if decimate else np.arange(nz)
    r = residual[planes]
    gz = gz_all[planes] if gz_all is not None else None
    del gz_all
    p = r.real ** 2 + r.imag ** 2

    # The local mean wavenumber over a narrower window (one cell): the image of noise
    # through a finite aperture is chirped (its local spectrum centred on the aperture's
    # direction from each pixel), and the chirp across the wide window would count as
    # spread. The derivatives are demodulated by it pixel by pixel.
    dxr = _d5(r, dx, 2)
    dyr = _d5(r, dy, 1)
    rc = np.conj(r)
    sn = narrow.coarse(np.stack([p, (rc * dxr).imag, (rc * dyr).imag]))
    p1 = np.where(sn[0] > 0, sn[0], np.inf)
    mx, my = narrow.full(sn[1:] / p1)
    gx = dxr - 1j * mx * r
    gy = dyr - 1j * my * r
    del dxr, dyr, mx, my, p
    fields = [gx.real ** 2 + gx.imag ** 2, gy.real ** 2 + gy.imag ** 2,
              (np.conj(gx) * gy).real]
    if gz is not None:
        fields += [(rc * gz).imag, gz.real ** 2 + gz.imag ** 2]
    del gx, gy, rc
    sw = wide.coarse(np.stack(fields)) / s2[planes]
    del fields
    lam = [np.maximum(sw[0], 0), np.maximum(sw[1], 0), sw[2]]
    if gz is not None:
        lam.append(np.maximum(sw[4] - sw[3] * sw[3], 0))
    del sw
    lam_c = np.stack(lam)
    if planes.size < nz:
        lam_c = np.moveaxis(np.moveaxis(lam_c, 1, -1) @ spline_matrix(planes, nz).T, -1, 1)
    lxx, lyy, lxy, *rest = wide.full(lam_c)
    lxx, lyy = np.maximum(lxx, 0), np.maximum(lyy, 0)
    det2 = np.maximum(lxx * lyy - lxy * lxy, 0)
    two_pi = 2 * np.pi
    if gz is not None:
        lzz = np.maximum(rest[0], 0)
        dz = np.gradient(z)
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
    out = NoiseModel(sigma2, (cx, cy, cell[2]), float(n_cells), resels, n_ref, t)
    _LAST[:] = [key, out]
    return out


RANGE_SAMPLES = 8.0
"""Planes per range cell on which the derivative covariance is computed (at least)."""


def range_planes(z: np.ndarray, cell_z: float) -> np.ndarray:
    """The planes on which :func:`local_noise` computes the derivative covariance.

    Every ``k``-th plane, the last included, ``k`` the whole number of planes in
    1/:data:`RANGE_SAMPLES` of the range cell ``cell_z`` (metres) on uniformly spaced
    planes (every plane otherwise, or for fewer than 16). The covariance is a ratio
    of local averages of products of the image and its derivatives, whose spectrum
    along range reaches twice the image's band, ``+-2 pi / cell_z``: at ``k dz =
    cell_z / 8`` a spline follows its highest wavenumber to
    ``(5/384)(pi/4)^4 = 5e-3`` of that component's amplitude, itself a small part
    of the laterally averaged field.

    Examples
    --------
    >>> range_planes(np.linspace(0.1, 0.3, 101), 0.04)[:4]   # 2 mm planes, 4 cm cell
    array([0, 2, 4, 6])
    """
    nz = z.size
    if nz < 16 or not np.isfinite(cell_z):
        return np.arange(nz)
    d = np.diff(z)
    if np.ptp(d) > 1e-6 * abs(d[0]):
        return np.arange(nz)
    k = int(cell_z / (RANGE_SAMPLES * d[0]))
    k = max(1, min(k, (nz - 1) // 7))
    return np.unique(np.r_[np.arange(0, nz, k), nz - 1])


_LAST: list = []
"""The last call's inputs' fingerprint and result (CLEAN asks again, unchanged, after
re-measuring its models' errors)."""


def _fingerprint(residual: np.ndarray, mask: np.ndarray, x: np.ndarray, y: np.ndarray,
                 z: np.ndarray, false_alarm: float, decimate: bool) -> tuple:
    """The inputs of :func:`local_noise` as a key (CRC-32 of the data: 10 ms for 30 MB)."""
    arrays = [np.ascontiguousarray(a) for a in (residual, mask, x, y, z)]
    return (tuple((a.dtype.str, a.shape, zlib.crc32(a)) for a in arrays),
            float(false_alarm), bool(decimate))
