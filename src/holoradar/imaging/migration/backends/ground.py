"""Horizontal world planes from a posed (tilted) aperture: ``frame="ground"``.

Each frequency's data are summed onto the plane waves of a horizontal reference
plane through the lowest element (the spectrum's sum, :mod:`.oblique`)
and carried down through the layers onto the world planes. Two backends differ in
that sum only: ``"ground-direct"`` (factored matrix products, exact) and
``"ground-nufft"`` (finufft, to 1e-6 in complex128, 1e-5 in complex64; the elements on
a uniform grid). A band's images are weighted and multiplied by the illumination's
``conj(psi)`` in the world frame.
"""

from __future__ import annotations

import numpy as np

from .. import illumination, units
from ..plan import MigrationPlan
from . import oblique, oblique_sum
from .base import Backend
from .oblique import GroundGrid

__all__ = ["GroundDirect", "GroundNufft"]


class GroundDirect(Backend):
    """The ground frame with the direct (factored) spectrum sums."""

    name = "ground-direct"
    route = "direct"

    def refuses(self, plan: MigrationPlan) -> str | None:
        if plan.settings.frame != "ground":
            return "frame='ground'"
        return None

    def grids(self, plan: MigrationPlan) -> list[GroundGrid]:
        """Each frequency's world FFT grid (made once per plan)."""
        if "ground" not in plan.memo:
            s = plan.settings
            plan.memo["ground"] = [
                oblique.ground_setup(plan.geometry, float(k), plan.z, plan.medium, x=s.x,
                                     y=s.y, pad=plan.pad, upsample=s.upsample)
                for k in plan.wavenumbers]
        return plan.memo["ground"]

    def _unit(self, plan: MigrationPlan, g: GroundGrid):
        """The point unit's factor of a voxel at world range z on ``g``'s world grid (the
        range from the reference plane; the cell of an output pixel on that grid,
        ``dx dy m_x m_y``, as the forward map places it), or None."""
        if not units.is_point(plan):
            return None
        my, mx = g.down
        area = g.pitch[0] * g.pitch[1] * mx * my
        pol = units.polarization(plan)
        return lambda z: units.point_factor(g.grid, g.pitch, g.k, g.medium, z - g.z_ref,
                                            g.mono, area, plan.work, pol)

    def axes(self, plan: MigrationPlan) -> tuple[np.ndarray, np.ndarray]:
        g = self.grids(plan)[0]
        return g.x, g.y

    def method(self, plan: MigrationPlan) -> str:
        return "angular:ground"

    def adjoint(self, plan: MigrationPlan, data: np.ndarray) -> np.ndarray:
        x, y = self.axes(plan)
        acc: np.ndarray | None = None
        parts = []
        for i, g in enumerate(self.grids(plan)):
            img = oblique.adjoint_ground(plan.geometry, data[:, i], g, plan.z,
                                         snr=plan.snr_db, work=plan.work, route=self.route,
                                         unit=self._unit(plan, g))
            phasor = illumination.on_planes(plan, i, x, y)
            if phasor is not None:
                img = img * phasor
            if plan.nf > 1:
                img = plan.weights[i] * img
            if plan.separate:
                parts.append(img)
            else:
                acc = img if acc is None else acc + img
        return np.stack(parts, axis=1) if plan.separate else acc

    def forward(self, plan: MigrationPlan, image: np.ndarray) -> np.ndarray:
        x, y = self.axes(plan)
        ny, nx = plan.grid
        out = np.empty((image.shape[0], plan.nf, ny, nx), dtype=plan.work)
        for i, g in enumerate(self.grids(plan)):
            r = image[:, i] if plan.separate else image
            phasor = illumination.on_planes(plan, i, x, y)
            if phasor is not None:
                r = r * np.conj(phasor)
            if plan.nf > 1:
                r = plan.weights[i] * r
            out[:, i] = oblique.forward_ground(plan.geometry, r.astype(plan.work, copy=False),
                                               g, plan.z, snr=plan.snr_db, work=plan.work,
                                               route=self.route, unit=self._unit(plan, g))
        return out


class GroundNufft(GroundDirect):
    """The ground frame with the spectrum summed by finufft (large tilted arrays)."""

    name = "ground-nufft"
    route = "nufft"

    def refuses(self, plan: MigrationPlan) -> str | None:
        if plan.settings.frame != "ground":
            return "frame='ground'"
        g = plan.geometry
        if not oblique_sum.uniform_elements(g):
            return "elements on a uniform grid (finufft's modes)"
        return None

    def prefer(self, plan: MigrationPlan) -> bool:
        """Whether the measured costs favour it over the direct sums (``"auto"``)."""
        return oblique_sum.preferred_route(plan.geometry, self.grids(plan)[0].grid) == "nufft"
