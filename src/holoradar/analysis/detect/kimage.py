"""A point's image across a band: the frequencies summed before the inverse FFT.

``migrate`` of a wideband hologram images each frequency on its own (transfer
function per plane, zero-padded spectrum, inverse FFT, crop) and adds the
weighted images. Frequencies with the same padded FFT grid (``pad=True`` sizes
it from the wavelength and the deepest plane: across a 1.5:1 band there are one
or two grids) share the inverse FFT, the zero padding and the crop, which are
linear, so their sum may be taken first:

    I_z = sum_grids crop(IFFT(ZP(sum_f w_f H_f U_fz))),

one inverse FFT per plane and grid instead of one per plane and frequency, the
same numbers to rounding. :class:`~.model.HologramModel` uses it for its objects'
images (each object's image is a whole volume) once it has reproduced
``migrate`` on the planes of its image check; otherwise it calls ``migrate``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...data.hologram import Hologram
from ...physics.medium import Medium

__all__ = ["MAX_BYTES", "SpectralSum"]

_CHUNK = 16
"""Planes per batched inverse FFT."""

MAX_BYTES = 512 * 2**20
"""The transfer functions of all frequencies and planes are held while the model lives
(nf nz My Mx complex numbers); beyond this ``migrate`` is used."""

_OPTIONS = {"upsample", "equalize", "snr_db", "pad", "compensate_loss", "method", "dtype",
            "combine", "fov", "frame", "algorithm", "progress"}


class SpectralSum:
    """The migration of a monostatic band's data (nf, N) onto planes ``zs``.

    Parameters
    ----------
    hologram : Hologram
        The band's geometry (a scanned transceiver on a level aperture).
    zs : ndarray
        Ranges of the planes, metres.
    medium : Medium or None
        The ground.
    options : dict
        ``migrate``'s keyword arguments; ``equalize`` as the frequencies' weights and
        ``snr_db`` set (:class:`~.model.HologramModel` fixes both).

    Raises
    ------
    ValueError
        When the sum does not apply (not a monostatic band, another method or field
        of view, transfer functions over :data:`MAX_BYTES`).
    """

    def __init__(self, hologram: Hologram, zs: np.ndarray, medium: Medium | None,
                 options: dict[str, Any]) -> None:
        from ...physics.propagation import AngularSpectrum

        opts = dict(options)
        bad = set(opts) - _OPTIONS
        if (bad or not hologram.is_wideband or not hologram.monostatic
                or not hologram.pose.is_identity
                or opts.get("method", "angular") != "angular"
                or opts.get("fov", "aperture") != "aperture"
                or opts.get("combine", "coherent") != "coherent"
                or opts.get("frame", "aperture") != "aperture"
                or opts.get("snr_db") is None
                or isinstance(opts.get("equalize", True), bool | np.bool_)):
            raise ValueError("the frequencies' sum applies to a monostatic band migrated "
                             "with method='angular', fov='aperture', combine='coherent'")
        self.w = np.asarray(opts["equalize"], float)
        self.u = int(opts.get("upsample", 1))
        work = np.dtype(opts["dtype"]) if opts.get("dtype") is not None else np.dtype(
            np.complex64 if hologram.data.dtype == np.complex64 else np.complex128)
        dx, dy = hologram.pitch
        shape = hologram.data.shape[-2:]
        self.ops = [AngularSpectrum(shape, dx, dy, float(k), zs, medium,
                                    opts.get("pad", True), work,
                                    compensate_loss=bool(opts.get("compensate_loss", True)),
                                    snr_db=float(opts["snr_db"]), monostatic=True)
                    for k in hologram.wavenumbers]
        nz = np.atleast_1d(zs).size
        held = sum(nz * op.fft_shape[0] * op.fft_shape[1] for op in self.ops) * work.itemsize
        if held > MAX_BYTES:
            raise ValueError(f"the frequencies' transfer functions ({held / 2**20:.0f} MiB) "
                             f"exceed {MAX_BYTES / 2**20:.0f} MiB: migrate plane by plane")
        # Frequencies whose padded grids are alike share one inverse FFT per plane.
        self.groups: dict[tuple[int, int], list[int]] = {}
        for i, op in enumerate(self.ops):
            self.groups.setdefault(op.fft_shape, []).append(i)
        self.shape = shape
        self.nz = np.atleast_1d(zs).size
        self.dtype = work

    def image(self, data: np.ndarray, planes: np.ndarray | None = None) -> np.ndarray:
        """The image of data (nf, ny*nx) on the planes (indices; all by default),
        (len(planes), oy, ox)."""
        from ...imaging.migrate import _zero_pad_spectrum
        from ...physics.propagation import ifft2_cropped

        idx = np.arange(self.nz) if planes is None else np.asarray(planes, int)
        d = np.asarray(data).reshape(len(self.ops), *self.shape)
        H = [op.spectrum(d[i]) * self.w[i] for i, op in enumerate(self.ops)]
        ny, nx = self.shape
        u = self.u
        oy, ox = u * (ny - 1) + 1, u * (nx - 1) + 1
        out = np.empty((idx.size, oy, ox), dtype=self.dtype)
        workers = self.ops[0].workers
        for c0 in range(0, idx.size, _CHUNK):
            sel = idx[c0:c0 + _CHUNK]
            acc: np.ndarray | None = None
            for grid, members in self.groups.items():
                S = np.zeros((sel.size, *grid), dtype=self.dtype)
                for i in members:
                    U = self.ops[i].adjoint_transfers
                    for j, iz in enumerate(sel):
                        S[j] += H[i] * U[iz]
                if u > 1:
                    S = _zero_pad_spectrum(S, u)
                part = ifft2_cropped(S, (oy, ox), workers, overwrite=True)[..., :oy, :ox]
                acc = part if acc is None else acc + part
            assert acc is not None
            out[c0:c0 + sel.size] = acc * (u * u) if u > 1 else acc
        return out
