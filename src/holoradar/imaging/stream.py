"""Frame-rate imaging of a multi-view device: glare suppression and synthesis per frame.

A holographic radar that moves its horn through K positions delivers a frame of
K holograms again and again. :class:`StreamImager` prepares everything that does
not change between frames (transfer functions, incident-phase phasors, the
direct waves) and then, per frame, does only:

1. fit the glare of every view at once (the complex-source-point beam of
   :func:`~holoradar.imaging.glare.suppress_surface` with its direct wave),
   by one Gauss-Newton step warm-started from the previous frame (a device
   that does not jump between frames needs no more), and subtract it;
2. one batched FFT of the K holograms, K products with the cached transfer
   function, one batched inverse FFT onto the image grid;
3. the coherent sum with the cached phasors ``conj(E0_k)/|E0_k|``.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np

from ..data.hologram import Hologram, Image
from ..physics.medium import Medium
from ..physics.propagation import DEFAULT_SNR_DB
from ..physics.sources import PointSource
from ..theory import lateral_resolution
from .glare import FitWarning, direct_wave, suppress_surface
from .migration.image import Migration
from .migration.settings import MigrationSettings
from .synthesis import check_views

__all__ = ["StreamImager"]


class StreamImager:
    """Glare suppression and coherent synthesis of K views, frame after frame.

    Parameters
    ----------
    views : sequence of Hologram
        A first frame: K views sharing frequency and grid, each with its
        ``source`` (a :class:`PointSource` when ``suppress``). Their fits start
        the tracking.
    z : float
        Image range, metres.
    medium : Medium
        The ground.
    upsample : int
        Image pixels per element pitch; the image covers the whole padded grid
        (``fov="full"``, at least twice the array, more at long range: see
        :func:`~holoradar.physics.propagation.padded_shape`): 128 pixels a side
        for the paper's 16 x 16 array at 0.4 m and ``upsample=4``.
    suppress : bool
        Remove the glare and the direct wave of each view (default True). The
        mirror planes follow from ``medium``'s surface and the radiators'
        positions, fixed for the imager's life: a moved surface or horn needs a
        new imager.

    Examples
    --------
    >>> import holoradar as hr
    >>> sand = hr.Medium.half_space(0.3, 2.5)
    >>> horns = [hr.PointSource((0.0, y, -0.05)) for y in (-0.1, 0.0, 0.1)]
    >>> views = [hr.simulate(hr.Scene(sand, s, [hr.PointTarget((0, 0, 0.4), 0.05)]),
    ...                      hr.Aperture.grid(16, 0.02), 9.9e9) for s in horns]
    >>> imager = StreamImager(views, 0.4, sand)
    >>> imager(np.stack([v.data for v in views])).data.shape
    (128, 128)
    """

    def __init__(self, views: Sequence[Hologram], z: float, medium: Medium, *,
                 upsample: int = 4, suppress: bool = True) -> None:
        views = check_views(views)
        if np.ndim(z) != 0:
            raise ValueError(f"z must be one range in metres (a frame images one plane), got "
                             f"{z!r}")
        for i, v in enumerate(views):
            if not v.pose.is_identity:
                raise ValueError(f"views[{i}].pose must be the identity (a frontal array at "
                                 f"z = 0) for streaming, got {v.pose!r}; image posed "
                                 "holograms with synthesize(..., frame='ground')")
        h0 = views[0]
        self.k = h0.k
        self.shape = h0.data.shape[-2:]
        self.suppress = suppress
        dx = h0.pitch[0]
        # Each view's migration frozen for the imager's life: the whole padded grid,
        # the loss compensated (one SNR for every view and frame, so that they add
        # alike), the view's incident phase removed at every pixel (the operator's
        # "phase" illumination, computed once).
        settings = MigrationSettings(upsample=upsample, fov="full", illumination="phase",
                                     snr_db=DEFAULT_SNR_DB, progress=False)
        self.migrations = [Migration(v, float(z), medium, settings) for v in views]
        m0 = self.migrations[0]
        self.x, self.y = m0.x, m0.y
        self.z = float(z)
        self.frequency = h0.frequency
        med = medium if medium is not None else Medium.free_space()
        self.pts = h0.points
        if suppress:
            self._init_tracking(views, med, dx * h0.x.size)

    # -------------------------------------------------------------- glare tracking
    def _init_tracking(self, views: list[Hologram], medium: Medium, A: float) -> None:
        D, theta = [], []
        for v in views:
            if not isinstance(v.source, PointSource):
                raise ValueError("suppress=True needs each view's source to be a PointSource")
            _, rep = suppress_surface(v, medium, v.source, "gaussian")
            theta.append([rep.parameters["x"], rep.parameters["y"], rep.parameters["b"]])
            D.append(direct_wave(v.source, self.k, self.pts))
        self.D = np.stack(D)                                   # (K, N)
        self.theta = np.array(theta, float)                    # (K, 3): xc, yc, b
        self.zm = np.array([2 * medium.z_interfaces[0] - v.source.position[2] for v in views])
        self.cell = lateral_resolution(2 * np.pi / self.k, float(self.zm.mean()), A)

    def _beam(self, theta: np.ndarray) -> tuple[np.ndarray, ...]:
        """Complex-source-point beams of all views and their derivatives (K, N)."""
        dx = self.pts[None, :, 0] - theta[:, 0:1]
        dy = self.pts[None, :, 1] - theta[:, 1:2]
        s = self.zm[:, None] - 1j * theta[:, 2:3]
        R = np.sqrt(dx * dx + dy * dy + s * s)
        R = np.where(R.real < 0, -R, R)
        G = np.exp(1j * self.k * R) / R
        dG_dR = G * (1j * self.k - 1 / R)
        return G, dG_dR * (-dx / R), dG_dR * (-dy / R), dG_dR * (-1j * s / R)

    def _fit(self, h: np.ndarray) -> np.ndarray:
        """One Gauss-Newton step for all views at once; returns the fitted glare + direct.

        Variable projection: the amplitudes (a, d) of each view are solved exactly
        for the current beam, then the beam's (xc, yc, b) take one Gauss-Newton
        step, and the model follows that step to first order (the step is small
        when tracking, and the next frame starts from it).
        """
        G, *dG = self._beam(self.theta)
        B = np.stack([G, self.D], axis=2)                                # (K, N, 2)
        BH = B.conj().transpose(0, 2, 1)
        coef = np.linalg.solve(BH @ B, BH @ h[..., None])[..., 0]       # (K, 2)
        model = (B @ coef[..., None])[..., 0]
        r = h - model
        explained = 1 - np.sum(np.abs(r) ** 2, axis=1) / np.maximum(
            np.sum(np.abs(h) ** 2, axis=1), 1e-300)
        if np.any(explained < 0.5):
            warnings.warn("StreamImager: in some views the glare model explains less than "
                          "half of the frame; the glare may have changed more than one step "
                          "can follow (re-create the imager from this frame)", FitWarning,
                          stacklevel=3)
        J = -coef[:, 0:1, None] * np.stack(dG, axis=2)                   # d r / d theta
        JH = J.conj().transpose(0, 2, 1)
        step = np.linalg.solve(np.real(JH @ J), np.real(JH @ r[..., None]))[..., 0]
        theta = self.theta - step
        theta[:, 2] = np.clip(theta[:, 2], 0.0, 2 * np.pi**2 / self.k)
        step = self.theta - theta
        self.theta = theta
        return model + (J @ step[..., None].astype(J.dtype))[..., 0]

    # ------------------------------------------------------------------- a frame
    def __call__(self, data: np.ndarray) -> Image:
        """Image one frame: ``data`` of shape (K, ny, nx), the views in order."""
        h = np.asarray(data)
        K = len(self.migrations)
        if h.shape != (K, *self.shape):
            raise ValueError(f"data must have shape {(K, *self.shape)}, got {h.shape}")
        flat = h.reshape(h.shape[0], -1).astype(complex, copy=False)
        if not np.all(np.isfinite(flat)):
            raise ValueError("data must be finite: the frame contains NaN or inf values")
        if self.suppress and np.any(flat):
            flat = flat - self._fit(flat)
        frame = flat.reshape(h.shape)
        img = self.migrations[0].adjoint(frame[0])
        for m, view in zip(self.migrations[1:], frame[1:], strict=True):
            img += m.adjoint(view)
        return Image(img, self.x, self.y, np.array([self.z]), self.frequency,
                     "stream:coherent", has_z_axis=False)
