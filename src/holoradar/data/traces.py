"""Time-domain traces (A-scans) turned into the frequency samples holoradar images.

Pulse GPR records each position's echo as a trace ``s(t)``, sampled every ``dt``
from a time zero. holoradar's samples are the field at each frequency under
``exp(-i omega t)``: ``S(f) = sum_n s(t_n) exp(+2 pi i f (t_n - t0)) dt``, a delay
``tau`` giving ``exp(+2 pi i f tau)``, as propagation's ``exp(i k R)`` does (numpy's
FFT has the other sign: this is its conjugate for real traces, times ``dt``). Only
the band the antenna radiates carries the scene: the samples are the FFT's bins
within ``band`` (given, or where the traces' mean power spectrum is within
:data:`BAND_DB` of its peak), at most :data:`MAX_FREQUENCIES` of them spread evenly
over it (the rest add no range: the band's width sets the range cell, the bins'
spacing only the unambiguous range).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["BAND_DB", "MAX_FREQUENCIES", "frequency_samples"]

#: The antenna's band when none is named: where the traces' mean power spectrum is
#: within this many dB of its peak.
BAND_DB = -10.0

#: At most this many frequencies are kept (spread over the band).
MAX_FREQUENCIES = 256


def frequency_samples(traces: Any, dt: float, *, band: tuple[float, float] | None = None,
                      time_zero: float = 0.0, axis: int = 0
                      ) -> tuple[np.ndarray, np.ndarray]:
    """``(S, f)``: the traces' frequency samples over the band, and the band's
    frequencies (Hz).

    Parameters
    ----------
    traces : array_like, real or complex
        Samples in time along ``axis`` (default 0: ``(nt, ...)``), one trace per
        position along the other axes.
    dt : float
        The sample interval, seconds (> 0).
    band : (float, float), optional
        ``(f_min, f_max)`` in Hz, within the sampled band ``(0, 1 / (2 dt))``;
        default: where the mean power spectrum is within :data:`BAND_DB` of its peak.
    time_zero : float
        The time of the transmit pulse (the surface under a ground-coupled antenna),
        seconds from the first sample, within the trace.
    axis : int
        The traces' time axis.

    Returns
    -------
    S : ndarray, complex
        ``(nf, ...)``: the frequency axis first, the positions' axes after.
    f : ndarray
        ``(nf,)``, Hz, increasing.

    Raises
    ------
    ValueError
        A bad ``dt``, ``band`` or ``time_zero``, traces too short, not finite.

    Examples
    --------
    A delay of 2 ns is a phase ``2 pi f tau`` at every frequency:

    >>> dt, tau = 0.05e-9, 2e-9
    >>> t = np.arange(400) * dt
    >>> pulse = np.exp(-((t - tau) / 0.2e-9) ** 2)
    >>> S, f = frequency_samples(pulse, dt, band=(0.5e9, 1.5e9))
    >>> bool(np.allclose(np.angle(S * np.exp(-2j * np.pi * f * tau)), 0, atol=1e-6))
    True
    """
    try:
        s = np.moveaxis(np.asarray(traces), axis, 0)
    except ValueError:   # a ragged list (numpy refuses it)
        s = np.asarray([], dtype=object)
    if s.dtype == object:
        raise ValueError("traces must all hold the same number of samples (a 2-D array, "
                         "time by position): pad or cut them to one length")
    if not (np.issubdtype(s.dtype, np.number) and s.ndim >= 1):
        raise ValueError(f"traces must be a numeric array of samples in time, got {s.dtype}")
    if s.shape[0] < 4:
        raise ValueError(f"traces must hold at least 4 samples in time along axis {axis}, got "
                         f"{s.shape[0]}")
    if not np.all(np.isfinite(s)):
        raise ValueError("traces must be finite (NaN or inf found)")
    try:
        dt = float(dt)
    except (TypeError, ValueError):
        dt = float("nan")
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be the sample interval in seconds (> 0), got {dt!r}")
    nt = s.shape[0]
    if not (np.isfinite(time_zero) and 0 <= float(time_zero) < nt * dt):
        raise ValueError(f"time_zero must lie within the trace, 0 to {nt * dt:.4g} s, got "
                         f"{time_zero!r}")
    f_all = np.fft.fftfreq(nt, dt)
    # exp(+2 pi i f t) sums: numpy's inverse FFT times nt dt.
    spec = np.fft.ifft(s, axis=0) * (nt * dt)
    keep = f_all > 0
    f_all, spec = f_all[keep], spec[keep]
    order = np.argsort(f_all)
    f_all, spec = f_all[order], spec[order]
    if band is None:
        power = np.mean(np.abs(spec.reshape(spec.shape[0], -1)) ** 2, axis=1)
        inside = power >= power.max() * 10 ** (BAND_DB / 10) if power.max() > 0 else \
            np.ones(power.size, bool)
        lo, hi = f_all[np.flatnonzero(inside)[[0, -1]]]
    else:
        try:
            lo, hi = (float(v) for v in band)
        except (TypeError, ValueError):
            raise ValueError(f"band must be (f_min, f_max) in Hz, got {band!r}") from None
        nyquist = 1 / (2 * dt)
        if not (0 < lo < hi <= nyquist):
            raise ValueError(f"band must lie within the sampled band, 0 to {nyquist:.4g} Hz "
                             f"(1 / (2 dt)), with f_min < f_max; got {band!r}")
    sel = np.flatnonzero((f_all >= lo) & (f_all <= hi))
    if sel.size < 2:
        raise ValueError(f"band {lo:.4g} to {hi:.4g} Hz holds {sel.size} of the trace's "
                         f"frequencies (spaced 1 / (nt dt) = {1 / (nt * dt):.4g} Hz): widen "
                         "it, or give longer traces")
    if sel.size > MAX_FREQUENCIES:
        sel = sel[np.unique(np.round(np.linspace(0, sel.size - 1, MAX_FREQUENCIES)).astype(int))]
    f = f_all[sel]
    S = spec[sel] * np.exp(-2j * np.pi * f * float(time_zero)).reshape((-1,) + (1,) * (s.ndim - 1))
    return S, f
