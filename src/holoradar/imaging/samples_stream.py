"""An image that grows as a hand-held scan's samples arrive.

The samples reach the image through their spectrum on the box's wavenumbers,
``D(k) = sum_n d_n exp(-i k.(r_n - r_0))`` (:mod:`holoradar.imaging.samples`), which is
a sum over samples: ``add`` checks a batch and keeps it; ``image`` adds the type-1
non-uniform FFT of every sample kept since the last image to what the earlier ones
left (one transform per image: its cost is mostly the box's FFTs, whatever the number
of samples), and the image at any moment is the grid's migration of ``ifft2(D)``,
the same as :func:`~holoradar.imaging.samples.migrate_samples` of every sample so far
(to the transforms' rounding; test). ``equalize=True`` weighs each frequency by 1 /
the RMS of the samples so far, kept as running sums.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._lazy import lazy_module
from ..data.hologram import C0, Image
from ..data.samples import from_samples
from .samples import SamplesBox, _box_hologram, _check_options

sfft = lazy_module("scipy.fft")

__all__ = ["SampleStream"]


class SampleStream:
    """Samples in, an image out, at any moment.

    Parameters
    ----------
    frequency : float or array_like of float
        Hz, as the samples will come (``nf`` values).
    z : float or sequence of float
        Ranges of the image planes, metres.
    x, y : array_like
        The image grid (uniform pixel positions, metres). Samples must fall inside the
        periodic box around it (twice its extent); others are refused.
    monostatic, source, polarization
        As for :meth:`holoradar.Hologram.from_samples`.
    **options
        ``migrate``'s (``medium``, ``dtype``, ``equalize``...).

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> f = np.linspace(8e9, 12e9, 4)
    >>> xs = np.linspace(-0.05, 0.05, 21)
    >>> s = SampleStream(f, [0.08, 0.1], xs, xs, monostatic=True)
    >>> for _ in range(3):                      # three batches of a sweep
    ...     p = rng.uniform(-0.05, 0.05, (200, 2))
    ...     s.add(np.ones((4, 200)), p)
    >>> s.n, s.image().data.shape
    (600, (2, 21, 21))
    """

    def __init__(self, frequency: Any, z: Any, x: Any, y: Any, *, monostatic: bool = False,
                 source: Any = None, polarization: Any = None, **options: Any) -> None:
        from .samples import image_axes

        _check_options(options)
        # A probe of two samples checks the band and the kind as from_samples does.
        f = np.atleast_1d(np.asarray(frequency, dtype=float))
        step = C0 / max(float(np.max(np.abs(f))), 1.0) / 4   # a plausible span
        probe = from_samples(np.zeros((f.size, 2)), [[0.0, 0.0], [step, 0.0]], frequency,
                             monostatic=monostatic, source=source, polarization=polarization)
        self._probe = probe
        self.x, self.y = image_axes(probe, x, y)
        self.box = SamplesBox.spanning(self.x, self.y)
        self.z = z
        self.options = options
        self._D = np.zeros((probe.nf, self.box.my, self.box.mx), complex)
        self._power = np.zeros(probe.nf)
        self._pending: list[tuple[np.ndarray, np.ndarray]] = []
        self.n = 0

    def add(self, data: Any, positions: Any) -> None:
        """Add a batch: ``data`` ``(nf, m)`` (or ``(m,)``), ``positions`` ``(m, 2)`` metres,
        checked as :meth:`~holoradar.Hologram.from_samples` checks them."""
        p = self._probe
        s = from_samples(data, positions, p.frequency, monostatic=p.monostatic,
                         source=p.source, polarization=p.polarization)
        inside = self.box.holds(s.positions)
        if not inside.all():
            raise ValueError(f"positions: {int((~inside).sum())} of {s.n} lie outside the "
                             f"image's box (x {self.box.x0:.3g} .. "
                             f"{self.box.x0 + self.box.mx * self.box.dx:.3g} m, y "
                             f"{self.box.y0:.3g} .. {self.box.y0 + self.box.my * self.box.dy:.3g}"
                             " m): give an image grid x, y that covers the scan")
        d = s.data.reshape(p.nf, s.n)
        # Kept until the next image: one transform of every sample since the last
        # image (a transform's cost is mostly the box's FFTs, whatever the batch).
        self._pending.append((s.positions, d))
        self._power += np.sum(np.abs(d) ** 2, axis=1)
        self.n += s.n

    def image(self) -> Image:
        """The image of every sample added so far."""
        from .migrate import migrate

        if self.n == 0:
            raise ValueError("no samples yet: add() some first")
        if self._pending:
            pos = np.concatenate([q for q, _ in self._pending])
            d = np.concatenate([v for _, v in self._pending], axis=1)
            self._D += self.box.spectrum(pos, d)
            self._pending.clear()
        p = self._probe
        opts = dict(self.options)
        if opts.get("equalize", True) is True and p.is_wideband:
            rms = np.sqrt(self._power / self.n)
            opts["equalize"] = np.divide(1.0, rms, out=np.zeros_like(rms), where=rms > 0)
        field = sfft.ifft2(self._D, workers=-1)
        img = migrate(_box_hologram(p, self.box, field), self.z, pad=False, fov="aperture",
                      **opts)
        return Image(self.box.crop(img.data), self.x, self.y, img.z, img.frequency,
                     f"{img.method}:samples", has_z_axis=img.has_z_axis)
