"""The reflectivity's unit: a reflecting plane's coefficient, or a point's Born amplitude.

With ``scatterer="plane"`` the operator maps the reflected field on each plane,
``r E0``, up to the aperture by the transfer ``U``: the Kirchhoff model. With
``scatterer="point"`` each voxel is a point scatterer of amplitude ``r`` (a point
target's ``amplitude``), whose field at the elements is ``r E0 G``, ``G`` the layered
Green's function. By Weyl's identity ``exp(i k R)/R = (i/2 pi) int exp(i (p x + q y +
kz |z|))/kz dp dq``; a voxel on a grid of cell ``dA`` is a plane-wave spectrum of
``r dA`` per unit area, so the point's transfer is the plane's times

    S = 2 pi i / (kz_m dA),

``kz_m`` the vertical wavenumber in the voxel's layer (the source radiates into its
own layer). A scanned transceiver receives ``r G^2``: at stationary phase both legs
carry half the transverse wavenumber and ``G^2`` is the round-trip transfer times

    S = 2 pi i / (2 k n_m L dA),

``L`` the paraxial apparent range of the voxel and ``n_m`` its layer's index (the
spreading of the round trip; measured against ``simulate``'s point targets within
1-5 % in free space and layered ground). Grazing components (``kz -> 0``) are the
ones the band limit drops.
"""

from __future__ import annotations

import numpy as np

from ...physics.medium import Medium
from ...physics.propagation import TRANSFER_CACHE, spectral_quadrant
from .plan import MigrationPlan

__all__ = ["is_point", "point_factor"]


def is_point(plan: MigrationPlan) -> bool:
    """Whether the plan's reflectivity is a point's Born amplitude."""
    return plan.settings.scatterer == "point"


def point_factor(grid: tuple[int, int], pitch: tuple[float, float], k: float,
                 medium: Medium, z: float, mono: bool, area: float,
                 work: np.dtype) -> complex | np.ndarray:
    """``S`` of a voxel at range ``z`` (see the module docstring) on an FFT grid of
    ``grid`` and ``pitch`` (FFT order, read-only, cached), or the transceiver's scalar;
    ``area`` the voxel cell ``dA``, square metres."""
    m = int(medium.region_of(float(z)))
    if mono:
        n = float(medium.n(m).real)
        return complex(2j * np.pi / (2 * k * n * medium.apparent_distance(float(z)) * area))
    key = ("point-unit", grid, pitch, k, medium, m, area, np.dtype(work).str)

    def make() -> np.ndarray:
        _, _, kappa2, unfold = spectral_quadrant(grid, *pitch)
        kz = medium.kz(k, kappa2, m)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(kz != 0, 2j * np.pi / (kz * area), 0)
        out = s.ravel()[unfold].reshape(grid).astype(work)
        out.setflags(write=False)
        return out

    return TRANSFER_CACHE.get(key, make)
