"""The ``"cut"`` method: the glare's spot masked in the mirror plane and carried back.

Migrate to the mirror plane, mask the spot with a hard disk or a raised-cosine taper
(from ``r`` to ``1.5 r``), propagate the masked part back to the aperture (the
operator's forward map) and subtract it: the paper's "biting off". The direct wave is
fitted to what the bite leaves, and the bite taken again without it.
"""

from __future__ import annotations

import numpy as np

from ...physics.sources import GaussianBeam
from ._common import _joint_direct
from .report import GlareFit
from .spot import MirrorSpot

__all__ = ["remove_cut"]


def remove_cut(spot: MirrorSpot, cut_radius: float | None, taper: bool) -> GlareFit:
    """The glare bitten off at ``spot`` (``cut_radius`` metres; default 1.5 resolution
    cells, or for a Gaussian beam also two waists: its amplitude there is e^-4, -35 dB).

    Examples
    --------
    Through :func:`holoradar.suppress_surface` (``method="cut"``).
    """
    r = cut_radius if cut_radius is not None else 1.5 * spot.cell
    if cut_radius is None and isinstance(spot.src, GaussianBeam):
        # the reflected beam's spot is its waist blurred by the aperture
        r = float(np.hypot(1.5 * spot.cell, 2 * spot.src.waist))
    dist = np.hypot(spot.op.x[None, :] - spot.xs, spot.op.y[:, None] - spot.ys)
    if taper:
        mask = np.clip((1.5 * r - dist) / (0.5 * r), 0, 1)
        mask = 0.5 - 0.5 * np.cos(np.pi * mask)
    else:
        mask = (dist <= r).astype(float)

    def bite(v: np.ndarray) -> np.ndarray:
        # The masked spot carried back to the aperture: the operator's forward map.
        return spot.op.forward(spot.image(v) * mask).ravel()

    h, D = spot.h, spot.D
    glare = bite(h)
    dcoef, glare, direct_part = _joint_direct(h, glare, D)
    if D is not None:
        # The direct wave leaves part of itself in the masked spot: take it out first
        # and bite again (a second pass changes the result by the direct wave's share
        # of the spot, no more).
        glare = bite(h - direct_part)
        dcoef, glare, direct_part = _joint_direct(h, glare, D)
    report = {"mirror_position": spot.world(spot.xs, spot.ys, spot.z_m), "waist": r,
              "amplitude": None}
    return GlareFit(glare, direct_part, dcoef, True, {"x": spot.xs, "y": spot.ys}, report)
