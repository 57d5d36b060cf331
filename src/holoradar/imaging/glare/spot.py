"""Where the glare focuses: the mirror plane, its image and the spot found there.

The radiator's specular reflection from a flat ground is the wave of its mirror
image; migrated through air to the mirror plane (range ``z_m`` along the aperture's
normal) it focuses into a compact spot. :class:`MirrorSpot` holds what every
model-based method of :func:`~holoradar.suppress_surface` starts from: that plane's
migration operator (the whole padded grid, in double precision: the spot may lie
beside the array), the spot found within three resolution cells of where the
mirror image predicts it and its peak before any removal, the elements in the
aperture's own frame and in the world, and the radiator's direct wave into them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...data.hologram import Hologram
from ...physics.medium import Medium
from ...theory import lateral_resolution
from ..migration.image import Migration
from ..migration.settings import MigrationSettings
from ._common import direct_wave, recorded_polarization

__all__ = ["MirrorSpot", "find_spot", "mirror_image", "mirror_operator", "to_world"]


def mirror_operator(h: Hologram, z_m: float) -> Migration:
    """Free-space migration to the mirror plane z_m over the whole padded grid (the
    mirror source may lie beside the array), in double precision."""
    return Migration(h, z_m, None, MigrationSettings(fov="full", compensate_loss=False,
                                                     dtype=np.complex128, progress=False))


def mirror_image(op: Migration, data: np.ndarray) -> np.ndarray:
    """The mirror plane's image of ``data`` (its grid: ``op.x``, ``op.y``)."""
    return op.adjoint(data)


def find_spot(op: Migration, E: np.ndarray, guess: np.ndarray,
              radius: float) -> tuple[float, float, float]:
    """Peak of |E| within ``radius`` of the predicted mirror position: ``(x, y, |E|)``."""
    gx, gy = op.x, op.y
    a = np.abs(E.reshape((-1, *E.shape[-2:]))).max(axis=0)
    near = np.hypot(gx[None, :] - guess[0], gy[:, None] - guess[1]) <= radius
    if not near.any():
        raise ValueError("the mirror image lies outside the imaged grid; pad more")
    iy, ix = np.unravel_index(int(np.argmax(np.where(near, a, -1))), a.shape)
    return float(gx[ix]), float(gy[iy]), float(a[iy, ix])


def to_world(pose: Any, x: float, y: float, z: float) -> tuple[float, float, float]:
    """A point of the aperture's frame (x, y along its axes, z along its normal) in
    the world."""
    w = pose.to_world(np.array(x), np.array(y)) + z * pose.normal
    return float(w[0]), float(w[1]), float(w[2])


@dataclass(frozen=True)
class MirrorSpot:
    """One view's mirror plane and glare spot (see the module docstring).

    Attributes
    ----------
    hologram : Hologram
    src : PointSource, Dipole or GaussianBeam
        The radiator.
    z_m : float
        The mirror plane's range along the aperture's normal, metres.
    op : Migration
        The mirror plane's migration operator.
    cell : float
        A lateral resolution cell at ``z_m``, metres.
    xs, ys : float
        The spot, in the aperture's frame, metres.
    peak_before : float
        ``|image|`` at the spot before removal.
    k : float
        Wavenumber in air, rad/m.
    pts : ndarray
        The elements in the world (n, 3).
    local : ndarray
        The elements in the aperture's frame (n, 3), z' = 0.
    pol : ndarray or None
        The recorded field component (the vector model), or None.
    D : ndarray or None
        The radiator's direct wave at the elements (None: not removed).
    h : ndarray
        The data, flattened.
    """

    hologram: Hologram
    src: Any
    z_m: float
    op: Migration
    cell: float
    xs: float
    ys: float
    peak_before: float
    k: float
    pts: np.ndarray
    local: np.ndarray
    pol: np.ndarray | None
    D: np.ndarray | None
    h: np.ndarray

    @classmethod
    def find(cls, hologram: Hologram, medium: Medium, src: Any, direct: bool) -> MirrorSpot:
        """The mirror plane of ``src`` in ``medium``'s surface and the spot on it.

        Everything happens in the aperture's own frame (x, y along its axes, z' along
        its normal): the mirror image's spherical wave focuses, in free space, at its
        own coordinates there, for any tilt (frontal: the mirror plane
        ``z_m = 2 z0 - z_s``).
        """
        pose = hologram.pose
        mirror_local = pose.to_local(src.mirror_position(medium))
        z_m = float(mirror_local[2])
        if z_m <= 0:
            raise ValueError("hologram.pose: the source's mirror image in the surface lies "
                             "behind the aperture's plane, where no image of it forms; "
                             "use method='background'")
        data = hologram.data
        if data.ndim != 2:
            raise ValueError(f"suppress_surface takes one view (ny, nx), got shape "
                             f"{data.shape}")
        X, Y = np.meshgrid(hologram.x, hologram.y)
        local = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)
        op = mirror_operator(hologram, z_m)
        cell = lateral_resolution(hologram.wavelength, z_m, min(hologram.aperture_size))
        xs, ys, peak = find_spot(op, mirror_image(op, data), mirror_local[:2], 3 * cell)
        pts = hologram.points
        pol = recorded_polarization(hologram, src)
        D = direct_wave(src, hologram.k, pts, pol) if direct else None
        return cls(hologram, src, z_m, op, cell, xs, ys, peak, hologram.k, pts, local, pol,
                   D, data.ravel())

    @property
    def shape(self) -> tuple[int, int]:
        """The view's ``(ny, nx)``."""
        return self.hologram.data.shape

    def image(self, v: np.ndarray) -> np.ndarray:
        """The mirror plane's image of a flattened view ``v``."""
        return mirror_image(self.op, v.reshape(self.shape))

    def world(self, x: float, y: float, z: float) -> tuple[float, float, float]:
        """A point of the aperture's frame in the world."""
        return to_world(self.hologram.pose, x, y, z)
