"""The incident field on the image planes, as the migration operator weighs voxels by it.

The forward model multiplies a plane's reflectivity by ``psi`` before it
propagates to the aperture; the adjoint multiplies the back-propagated field by
``conj(psi)``. With ``illumination="field"`` ``psi = E0``, the source's incident field
at the voxel (the Born/Kirchhoff model of :func:`holoradar.simulate`'s planar
targets); ``"phase"``: ``E0/|E0|`` (0 where ``E0`` vanishes), which makes the
frequencies of a band add in phase without weighting voxels by the illumination's
strength (what :func:`holoradar.migrate` does); ``"none"``: 1. Without
``hologram.source`` a plane wave at normal incidence is assumed (phase 0 at z = 0).

A plane wave at normal incidence on a level aperture at z = 0 is the same across
each plane: one value per plane (:func:`uniform`), so that a band's spectra may be
summed before the inverse FFT. Otherwise one value per pixel (:func:`on_planes`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...data.hologram import has_polarization
from ...physics.incident import incident_on_planes, incident_phasors
from ...physics.sources import PlaneWave
from .plan import MigrationPlan

__all__ = ["is_uniform", "on_planes", "uniform"]


def _source(plan: MigrationPlan) -> Any:
    src = plan.geometry.source
    return src if src is not None else PlaneWave()


def is_uniform(plan: MigrationPlan) -> bool:
    """Whether ``psi`` is one number per plane (or 1 everywhere)."""
    if plan.illumination == "none":
        return True
    src = _source(plan)
    return (isinstance(src, PlaneWave) and src.alpha == 0.0 and src.beta == 0.0
            and (plan.settings.frame == "ground" or plan.geometry.pose.is_identity))


def _vector(plan: MigrationPlan) -> bool:
    g = plan.geometry
    return plan.illumination == "field" and g.polarization is not None \
        and has_polarization(g.source)


def uniform(plan: MigrationPlan, i: int) -> np.ndarray | None:
    """``conj(psi)`` of frequency ``i`` on every plane, shape (nz,), or None for 1
    (where :func:`is_uniform`: a normal plane wave, one pixel per plane)."""
    if plan.illumination == "none":
        return None
    k = float(plan.wavenumbers[i])
    if _vector(plan):   # the recorded component of the polarised wave, one pixel a plane
        e0 = _field_at(plan, _source(plan), k, _world(None, np.zeros(1), np.zeros(1),
                                                      plan.z))[:, 0, 0]
        if plan.illumination == "phase":
            return np.divide(e0.conj(), np.abs(e0), out=np.zeros_like(e0),
                             where=np.abs(e0) > 0)
        return e0.conj()
    if plan.illumination == "phase":    # conj(E0)/|E0|
        return incident_phasors([_source(plan)], k, plan.medium, np.zeros(1), np.zeros(1),
                                plan.z)[0, :, 0, 0]
    return incident_on_planes(_source(plan), k, plan.medium, np.zeros(1), np.zeros(1),
                              plan.z)[:, 0, 0].conj()


#: Per-pixel factors kept with their plan (for the next frame or iteration) up to this size.
_KEEP_BYTES = 1 << 26


def on_planes(plan: MigrationPlan, i: int, x: np.ndarray, y: np.ndarray) -> np.ndarray | None:
    """``conj(psi)`` of frequency ``i`` on the image's pixels, (nz, ny, nx), or None for 1.

    The pixels ``(x, y)`` are the image's: in the aperture's own frame (planes
    parallel to it at distances ``z``) they are carried to the world through its
    pose; ``frame="ground"`` gives world pixels already. What the adjoint multiplies
    by (the conjugate: kept as such, the common case, to spare a pass). Computed once
    per plan and frequency (a point source's field at every pixel is costly) where it
    is not too large to keep (read-only).
    """
    if plan.illumination == "none":
        return None
    key = ("illumination", i, x.size, y.size, float(x[0]), float(y[0]))
    if key in plan.memo:
        return plan.memo[key]
    factor = _on_planes(plan, i, x, y)
    if factor.nbytes <= _KEEP_BYTES or factor.strides[-1] == 0:
        factor.setflags(write=False)
        plan.memo[key] = factor
    return factor


def _on_planes(plan: MigrationPlan, i: int, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    k = float(plan.wavenumbers[i])
    src = _source(plan)
    pose = None if plan.settings.frame == "ground" else plan.geometry.pose
    zs = plan.z
    if plan.illumination == "phase" and not _vector(plan):
        if pose is not None and not pose.is_identity:
            e0 = _field_at(plan, src, k, _world(pose, x, y, zs))
            mag = np.abs(e0)
            return np.divide(e0.conj(), mag, out=np.zeros_like(e0), where=mag > 0)
        if isinstance(src, PlaneWave) and src.alpha == 0.0 and src.beta == 0.0:
            # At normal incidence the wave is the same across every plane (its lateral
            # factor is exactly 1): one pixel per plane, broadcast (read-only).
            one = incident_phasors([src], k, plan.medium, x[:1], y[:1], zs)[0]
            return np.broadcast_to(one, (zs.size, y.size, x.size))
        return incident_phasors([src], k, plan.medium, x, y, zs)[0]
    posed = pose is not None and not pose.is_identity
    if posed or _vector(plan):
        e0 = _field_at(plan, src, k, _world(pose if posed else None, x, y, zs))
    else:
        e0 = incident_on_planes(src, k, plan.medium, x, y, zs)
    if plan.illumination == "phase":
        mag = np.abs(e0)
        return np.divide(e0.conj(), mag, out=np.zeros_like(e0), where=mag > 0)
    return e0.conj()


def _world(pose: Any, x: np.ndarray, y: np.ndarray, zs: np.ndarray) -> np.ndarray:
    """World positions (nz, ny, nx, 3) of the pixels of planes at ``zs``."""
    X, Y = np.meshgrid(x, y)
    if pose is None:
        return np.stack(np.broadcast_arrays(X[None], Y[None], zs[:, None, None]), axis=-1)
    return pose.to_world(X, Y)[None] + zs[:, None, None, None] * pose.normal


def _field_at(plan: MigrationPlan, src: Any, k: float, pts: np.ndarray) -> np.ndarray:
    """``E0`` at world points (..., 3): the recorded component of a polarised source's
    vector field where the hologram has a polarisation, else the scalar field."""
    flat = pts.reshape(-1, 3)
    if _vector(plan):
        e0 = src.field_vector(k, plan.medium, flat) @ plan.geometry.polarization
    else:
        e0 = src.field(k, plan.medium, flat)
    return e0.reshape(pts.shape[:-1])
