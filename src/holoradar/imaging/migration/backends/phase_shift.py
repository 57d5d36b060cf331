"""Uniform planes in the deepest layer: the phase-shift sum (``"kspace"``), compiled
(``"columns"``) or resampled (``"stolt"``).

Below the last interface each plane wave's transfer grows from plane to plane by one
factor, so a band's coherent sum is carried from plane to plane in the wavenumber
domain (:mod:`.kspace`, :mod:`.columns`,
:mod:`.stolt`). The three share what they need and refuse alike:
uniformly spaced planes in the deepest region, the exact angular spectrum on the
aperture's own footprint, a coherent sum, an illumination the same across each plane
(a transceiver, or a plane wave at normal incidence, or none) and no loss to
compensate. Their forward maps are the exact adjoints of what each computes.
"""

from __future__ import annotations

import numpy as np

from .. import illumination, units
from ..plan import MigrationPlan
from . import columns, kspace, stolt
from .base import Backend, uniform_planes
from .terms import TINY, TermsKey, band_weights

__all__ = ["Columns", "PhaseShift", "Stolt"]


class PhaseShift(Backend):
    """The phase-shift sum in NumPy (the reference of the compiled loop)."""

    name = "kspace"
    def refuses(self, plan: MigrationPlan) -> str | None:
        why = self._needs(plan)
        return "; ".join(why) if why else None

    def _needs(self, plan: MigrationPlan) -> list[str]:
        s = plan.settings
        why = []
        if s.method != "angular":
            why.append(f"method='angular' (got {s.method!r})")
        if s.fov != "aperture":
            why.append(f"fov='aperture' (got {s.fov!r})")
        if plan.separate:
            why.append(f"combine='coherent' (got {s.combine!r})")
        if s.frame != "aperture":
            why.append("the aperture's own frame (frame='aperture')")
        elif plan.nf > 1 and not plan.geometry.pose.is_identity:
            why.append("an untilted aperture at z = 0 (hologram.pose the identity)")
        if not uniform_planes(plan.z):
            why.append("two or more uniformly spaced planes, increasing")
        last = plan.local.n_regions - 1
        if np.any(np.asarray(plan.local.region_of(plan.z)) != last):
            why.append(f"all planes in the deepest layer (z >= {plan.local.z_interfaces[-1]} "
                       "m): one kz per column")
        if plan.compensates:
            lossy = sum(complex(e).imag != 0 for e in plan.medium.eps)
            why.append(f"no loss to compensate ({lossy} lossy layer(s); give "
                       "compensate_loss=False)")
        pol = units.polarization(plan) if units.is_point(plan) else None
        if pol is not None and pol[0] * pol[1] != 0:
            why.append("a recorded field component along x or y for point scatterers "
                       "(its terms are kept on one quadrant of the spectrum)")
        if plan.settings.band_limit != "sharp":
            why.append("band_limit='sharp' (the recurrence drops a component at one plane)")
        if not illumination.is_uniform(plan):
            src = type(plan.geometry.source).__name__
            why.append("a transceiver, or a receiver array lit by a plane wave at normal "
                       f"incidence (hologram.source is {src}: its incident phase varies "
                       "across each plane)")
        return why

    def terms(self, plan: MigrationPlan) -> TermsKey:
        """The key of the plan's terms (:meth:`.terms.TermsKey.of`), with this
        backend's drop fraction."""
        return TermsKey.of(plan).with_tiny(self.tiny(plan))

    def tiny(self, plan: MigrationPlan) -> float:
        """The fraction of a frequency's largest term below which a term is dropped."""
        return TINY

    def _planes(self, plan: MigrationPlan) -> np.ndarray | None:
        """A transceiver's point unit's factor per plane, ``i/(n_m L)`` (None: 1)."""
        if not (units.is_point(plan) and plan.monostatic):
            return None
        m = plan.local
        f = np.array([1j / (m.n(int(m.region_of(float(z)))).real * m.apparent_distance(float(z)))
                      for z in plan.z])
        return f.astype(plan.work)[:, None, None]

    def adjoint(self, plan: MigrationPlan, data: np.ndarray) -> np.ndarray:
        out = self._adjoint(plan, data)
        c = self._planes(plan)
        return out if c is None else np.multiply(out, np.conj(c), out=out)

    def forward(self, plan: MigrationPlan, image: np.ndarray) -> np.ndarray:
        c = self._planes(plan)
        return self._forward(plan, image if c is None else image * c)

    def _adjoint(self, plan: MigrationPlan, data: np.ndarray) -> np.ndarray:
        return kspace.adjoint_kspace(data, self.terms(plan), band_weights(plan),
                                     plan.settings.upsample)

    def _forward(self, plan: MigrationPlan, image: np.ndarray) -> np.ndarray:
        return kspace.forward_kspace(image, plan.grid, self.terms(plan), band_weights(plan),
                                     plan.settings.upsample)

    def axes(self, plan: MigrationPlan) -> tuple[np.ndarray, np.ndarray]:
        g = plan.geometry
        dx, dy = g.pitch
        u = plan.settings.upsample
        ny, nx = plan.grid
        return (g.x[0] + np.arange(u * (nx - 1) + 1) * dx / u,
                g.y[0] + np.arange(u * (ny - 1) + 1) * dy / u)

    def method(self, plan: MigrationPlan) -> str:
        return "kspace" if plan.wideband else "angular"


class Columns(PhaseShift):
    """The phase-shift sum by a compiled loop over the spectral columns (numba)."""

    name = "columns"

    def refuses(self, plan: MigrationPlan) -> str | None:
        why = self._needs(plan)
        # numba's import (0.2 s) only where nothing else rules the loop out
        if not why and not columns.available():
            why.append("numba (not installed)")
        return "; ".join(why) if why else None

    def tiny(self, plan: MigrationPlan) -> float:
        return columns.TINY[plan.work.char]

    def _adjoint(self, plan: MigrationPlan, data: np.ndarray) -> np.ndarray:
        return columns.adjoint_columns(data, self.terms(plan), band_weights(plan),
                                       plan.settings.upsample)


class Stolt(PhaseShift):
    """Stolt's migration: each column's plane waves resampled onto a uniform kz grid,
    then one FFT along z (each plane wave within 0.9 % of the exact sum)."""

    name = "stolt"

    def refuses(self, plan: MigrationPlan) -> str | None:
        why = self._needs(plan)
        if plan.nf < 2:
            why.append("several frequencies")
        if not plan.monostatic and plan.geometry.source is None:
            why.append("a receiver array's hologram.source (without it the incident "
                       "phase of each frequency cannot be compensated)")
        return "; ".join(why) if why else None

    def _adjoint(self, plan: MigrationPlan, data: np.ndarray) -> np.ndarray:
        return stolt.adjoint_stolt(data, self.terms(plan), band_weights(plan),
                                   plan.settings.upsample)

    def _forward(self, plan: MigrationPlan, image: np.ndarray) -> np.ndarray:
        return stolt.forward_stolt(image, plan.grid, self.terms(plan), band_weights(plan),
                                   plan.settings.upsample)

    def method(self, plan: MigrationPlan) -> str:
        return "stolt"
