"""The image of a point without its hologram: the aperture's spectral window.

A point focused at its own range through a rectangular aperture of full widths
``A x B`` images as the inverse Fourier transform of the window ``|p| <= mu``,
``|q| <= nu``, ``mu = k A/(2 L)`` (``L`` the apparent distance,
:func:`holoradar.theory.spectral_window`):

    PSF(x, y) = sinc(mu (x - x0)) sinc(nu (y - y0)) exp(i (p_c (x - x0) + q_c (y - y0))),

``sinc(u) = sin(u)/u`` (first sidelobe 13.3 dB down), with the phase ramp
``(p_c, q_c)`` of the point's view of the array measured from the image at the
peak. ``A`` and ``B`` are taken as the image's extent (a frontal image spans the
aperture), ``k`` at the mean frequency. A tilted array's ground-frame image spans
more than its aperture's footprint, and its window is stretched along the tilt:
there ``mu`` and ``nu`` are the image's own spectral widths, ``pi / c`` with ``c``
the cell of the equivalent uniform band (:func:`~.noise.spectral_cells`: the band
whose spectral variance is the image's). Without the hologram the range response
is not modelled: the window's amplitude is fitted plane by plane over the main
lobe, which removes the object's smear along range with it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...data.hologram import C0
from .grid import Volume

__all__ = ["WindowModel"]


class WindowModel:
    """Analytic point response of an image (no hologram).

    Parameters
    ----------
    volume : Volume
        The image.
    medium : Medium, optional
        The ground the image was formed through (for the apparent distance).
    """

    kind = "window"

    def __init__(self, volume: Volume, medium: Any = None) -> None:
        f = volume.frequency
        fm = float(np.mean(np.atleast_1d(f))) if f is not None else np.nan
        if not np.isfinite(fm) or fm <= 0:
            raise ValueError("image.frequency must be the frequency in Hz (> 0) for an image "
                             "without its hologram")
        self.k = 2 * np.pi * fm / C0
        self.vol = volume
        self.medium = medium
        self.A = volume.x.size * volume.dx
        self.B = volume.y.size * volume.dy
        self.fixed: tuple[float, float] | None = None
        if volume.method.endswith(":ground"):
            from .noise import spectral_cells

            (cx, cy, _), _ = spectral_cells(volume.data, volume.x, volume.y, volume.z)
            if np.isfinite(cx) and np.isfinite(cy) and cx > 0 and cy > 0:
                self.fixed = (np.pi / cx, np.pi / cy)

    def start(self) -> np.ndarray:
        """The residual to begin with: the image itself."""
        return self.vol.data.copy()

    def widths(self, z: float) -> tuple[float, float]:
        """``(mu, nu)`` at range ``z``, rad/m."""
        if self.fixed is not None:
            return self.fixed
        L = self.medium.apparent_distance(z) if self.medium is not None else z
        L = max(L, 1e-3)
        return self.k * self.A / (2 * L), self.k * self.B / (2 * L)

    def lateral(self, x0: float, y0: float, z: float, pc: float, qc: float) -> np.ndarray:
        """The unit-peak PSF on the image's plane grid, (ny, nx)."""
        mu, nu = self.widths(z)
        dx = self.vol.x - x0
        dy = self.vol.y - y0
        px = np.sinc(mu * dx / np.pi) * np.exp(1j * pc * dx)
        py = np.sinc(nu * dy / np.pi) * np.exp(1j * qc * dy)
        return py[:, None] * px[None, :]

    def main_lobe(self, x0: float, y0: float, z: float) -> np.ndarray:
        """Pixels inside the first nulls, (ny, nx) bool."""
        mu, nu = self.widths(z)
        return ((np.abs(self.vol.y - y0)[:, None] < np.pi / nu)
                & (np.abs(self.vol.x - x0)[None, :] < np.pi / mu))

    def fit(self, residual: np.ndarray, index: tuple[int, int, int],
            position: tuple[float, float, float]
            ) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        """The model of an object at ``position`` (found at pixel ``index``).

        Returns
        -------
        model : ndarray, (nz, ny, nx)
            The fitted response, one complex amplitude per plane over the main lobe.
        lobe : ndarray of bool, (ny, nx)
            The main lobe at the object's range.
        info : dict
            Nothing more (the position is the image's).
        """
        iz, iy, ix = index
        x0, y0, z0 = position
        plane = residual[iz]
        # The local phase ramp: phase differences across the peak pixel.
        pc = _ramp(plane[iy, :], ix, self.vol.dx)
        qc = _ramp(plane[:, ix], iy, self.vol.dy)
        model = np.zeros_like(residual)
        for j, z in enumerate(self.vol.z):
            psf = self.lateral(x0, y0, float(z), pc, qc)
            lobe = self.main_lobe(x0, y0, float(z))
            n = float(np.sum(np.abs(psf[lobe]) ** 2))
            if n > 0:
                a = np.vdot(psf[lobe], residual[j][lobe]) / n
                model[j] = a * psf
        return model, self.main_lobe(x0, y0, z0), {}


def _ramp(line: np.ndarray, i: int, step: float) -> float:
    lo, hi = max(i - 1, 0), min(i + 1, line.size - 1)
    if hi == lo:
        return 0.0
    return float(np.angle(line[hi] * np.conj(line[lo])) / ((hi - lo) * step))
