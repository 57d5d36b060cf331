"""The receiver model: what a real array does to the field (the faults a calibration undoes).

For a field E at an element (``Hologram.data``, I + iQ under ``exp(-i*omega*t)``)
at frequency f, the device delivers

    s  = response[f] * element_gain[f, iy, ix] * E + n       (n: receiver noise)
    s' = conj(s) if the device delivers I - iQ, else s
    I  = Re(s') + dc_i,       Q = iq_gain*(cos(phi)*Im(s') + sin(phi)*Re(s')) + dc_q

with n circular complex Gaussian of variance ``noise^2`` (``E|n|^2``; I and Q
each ``noise^2/2`` before the demodulator), ``phi = iq_phase``. A dead element has
gain 0 (noise only), a noisy one a larger ``noise``. The calibration inverts the
chain from the bottom up: DC, I/Q imbalance, sign, gains and response, mask.
:class:`DeviceFaults` simulates it, to test a calibration on raw data with known
faults.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..data.hologram import Hologram
from .raw import RawFrames

__all__ = ["DeviceFaults"]


@dataclass(frozen=True, eq=False)
class DeviceFaults:
    """Faults of a receiver array (module text); each broadcasts over ``(nf, ny, nx)``.

    Parameters
    ----------
    dc_i, dc_q : float or array_like
        Offsets of the I and Q channels, device units.
    iq_gain : float or array_like
        The Q channel's gain relative to I (1: balanced).
    iq_phase : float or array_like
        The Q channel's phase error, radians (0: in quadrature).
    element_gain : complex or array_like
        Each element's complex gain, shape (ny, nx) or (nf, ny, nx).
    response : complex or array_like
        The device's response at each frequency, shape (nf,).
    conjugate : bool
        The device delivers ``I - iQ`` (the conjugate).
    noise : float or array_like
        Standard deviation of the complex receiver noise (``E|n|^2 = noise^2``),
        device units; per element with shape (ny, nx).

    Examples
    --------
    >>> x = np.arange(3) * 0.025
    >>> truth = Hologram(np.full((3, 3), 1j), x, x, 9.9e9)
    >>> raw = DeviceFaults(dc_i=0.5, iq_gain=2.0).record(truth, "HSR-1")
    >>> float(raw.i[0, 0]), float(raw.q[0, 0])
    (0.5, 2.0)
    """

    dc_i: Any = 0.0
    dc_q: Any = 0.0
    iq_gain: Any = 1.0
    iq_phase: Any = 0.0
    element_gain: Any = 1.0
    response: Any = 1.0
    conjugate: bool = False
    noise: Any = 0.0

    def record(self, field: Hologram, device: str, *, repeats: int | None = None,
               transmitter: bool = True, seed: int | None = None) -> RawFrames:
        """The raw frames the faulty device records of the true field ``field``.

        Parameters
        ----------
        field : Hologram
            The true field at the elements (e.g. from :func:`holoradar.simulate`).
        device : str
            The device's identity, written into the frames.
        repeats : int, optional
            Record this many repeats (a new leading axis), each with its own noise.
        transmitter : bool
            False records dark frames: no signal, only offsets and noise.
        seed : int, optional
            Seed of the noise generator.

        Returns
        -------
        RawFrames
        """
        if not isinstance(field, Hologram):
            raise ValueError(f"field must be a holoradar.Hologram, got {type(field).__name__}")
        e = field.data if transmitter else np.zeros(field.shape)
        if field.is_wideband:
            resp = np.asarray(self.response, complex)
            resp = resp[:, None, None] if resp.ndim == 1 else resp
        else:
            resp = np.asarray(self.response, complex)
            resp = resp.reshape(()) if resp.size == 1 else resp
        shape = (e.shape if repeats is None else (int(repeats), *e.shape))
        rng = np.random.default_rng(seed)
        sigma = np.asarray(self.noise, float)
        n = sigma / np.sqrt(2) * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
        s = resp * np.asarray(self.element_gain, complex) * e + n
        if self.conjugate:
            s = np.conj(s)
        phi = np.asarray(self.iq_phase, float)
        i = s.real + np.asarray(self.dc_i, float)
        q = (np.asarray(self.iq_gain, float) * (np.cos(phi) * s.imag + np.sin(phi) * s.real)
             + np.asarray(self.dc_q, float))
        i, q = np.broadcast_arrays(i, q)
        return RawFrames(i, q, field.x, field.y, field.frequency, device, source=field.source,
                         pose=None if field.pose.is_identity else field.pose)
