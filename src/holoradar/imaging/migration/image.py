"""A migration fixed for one geometry, applied to data: what every part that images runs.

:class:`Migration` holds a plan and its backend: the migration operator without
scipy's interface (its import is not paid here). ``migrate`` applies its adjoint to
the hologram it was made from (:func:`image_of`); the glare's mirror plane, the frame
streamer, the detection's model and the glare's dominance check apply the same frozen
operator to other data of the same geometry (residuals, parts of a hologram, the
next frame), so the weights and SNR it derived from the first data stay fixed.
``combine="incoherent"`` (not linear) is the root sum of squares of the frequencies'
separate images.
"""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np

from ...caches import named_cache
from ...data.hologram import Hologram, Image
from .choose import choose
from .memory import check_fits
from .plan import make_plan, warn
from .settings import MigrationSettings

__all__ = ["Migration", "image_of"]


class Migration:
    """One geometry's migration operator, frozen (see the module docstring).

    Parameters
    ----------
    hologram : Hologram
        The geometry (and the data the weights and SNR are derived from, once).
    z : float or sequence of float
        Ranges of the image planes, metres.
    medium : Medium or None
        The ground.
    settings : MigrationSettings
        How to migrate.

    Attributes
    ----------
    plan : MigrationPlan
    backend : Backend
    x, y : ndarray
        The image's pixel coordinates, metres.

    Examples
    --------
    >>> import holoradar as hr
    >>> h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))],
    ...                          source=hr.PlaneWave()), hr.Aperture.grid(16, 0.01), 9.9e9)
    >>> m = Migration(h, [0.25, 0.3], None, MigrationSettings())
    >>> m.adjoint(h.data).shape, m.forward(m.adjoint(h.data)).shape
    ((2, 16, 16), (16, 16))
    """

    def __init__(self, hologram: Hologram, z: Any, medium: Any,
                 settings: MigrationSettings) -> None:
        self.incoherent = settings.combine == "incoherent" and \
            isinstance(hologram, Hologram) and hologram.is_wideband
        if self.incoherent:
            # Each frequency's image apart, without its incident phase (its magnitude
            # is all the sum keeps).
            settings = settings.replace(combine="none",
                                        illumination=settings.illumination or "none")
        self.settings = settings
        self.plan = make_plan(hologram, z, medium, settings)
        self.backend = choose(self.plan)
        self.x, self.y = self.backend.axes(self.plan)

    def _frames(self, data: np.ndarray) -> tuple[tuple[int, ...], np.ndarray]:
        shape = self.plan.data_shape
        if type(data) is not np.ndarray:
            data = np.asarray(data)
        if data.shape[data.ndim - len(shape):] != shape:
            raise ValueError(f"data must end in shape {shape} (this geometry's samples), "
                             f"got {data.shape}")
        lead = data.shape[:data.ndim - len(shape)]
        return lead, data.reshape((-1, self.plan.nf, *self.plan.grid))

    def adjoint(self, data: Any) -> np.ndarray:
        """The image of samples ``(..., [nf,] ny, nx)``: ``(..., [nf,] nz, ny', nx')``
        (no plane axis for one range ``z``)."""
        lead, frames = self._frames(data)
        out = self.backend.adjoint(self.plan, frames)
        if self.incoherent:
            out = np.sqrt(np.sum(np.abs(out) ** 2, axis=1))
        out = out.reshape((*lead, *out.shape[1:]))
        return out[..., 0, :, :] if self.plan.scalar else out

    def forward(self, image: Any) -> np.ndarray:
        """The samples ``(..., [nf,] ny, nx)`` of a reflectivity on the image grid
        ``(..., [nf,] nz, ny', nx')`` (the exact adjoint of :meth:`adjoint`)."""
        if self.incoherent:
            raise ValueError("combine='incoherent' is not linear: it has no forward map")
        img = np.asarray(image)
        if self.plan.scalar:
            img = img[..., None, :, :]
        per = ((self.plan.nf,) if self.plan.separate else ()) + (
            self.plan.z.size, self.y.size, self.x.size)
        if img.shape[img.ndim - len(per):] != per:
            raise ValueError(f"image must end in shape {per}, got {np.shape(image)}")
        lead = img.shape[:img.ndim - len(per)]
        out = self.backend.forward(self.plan, img.reshape((-1, *per)).astype(
            self.plan.work, copy=False))
        return out.reshape((*lead, *self.plan.data_shape))

    def image(self, data: Any) -> Image:
        """:meth:`adjoint` as an :class:`~holoradar.Image` with its coordinates."""
        g = self.plan.geometry
        combine = "incoherent" if self.incoherent else self.settings.combine
        label = self.backend.method(self.plan) + (f":{combine}" if g.is_wideband else "")
        frequency = g.frequencies.copy() if g.is_wideband else g.frequency
        return Image(self.adjoint(data), self.x, self.y, self.plan.z, frequency, label,
                     has_z_axis=not self.plan.scalar)


def image_of(hologram: Hologram, z: Any, medium: Any, settings: MigrationSettings) -> Image:
    """``migrate(hologram, z, medium=medium, **settings)`` (see :func:`holoradar.migrate`):
    refused before any work where the volume would not fit in memory.

    The same hologram object migrated again onto the same planes with the same settings
    (a viewer's redraw, a benchmark, a loop over methods) reuses its plan (a plan holds
    no data; the hologram is immutable): what the call warns about is said again."""
    m = _recent(hologram, z, medium, settings)
    g = m.plan.geometry
    fast = m.backend.name in ("columns", "kspace", "stolt") or not m.plan.wideband
    check_fits(g, m.plan.z.size * (m.plan.nf if m.plan.separate else 1), settings.upsample,
               settings.dtype, factor=1.5 if fast else 3.0)
    img = m.image(hologram.data)
    _keep(hologram, z, medium, settings, m)
    return img


#: The last few migrations (their hologram held weakly), for the next call on the same
#: data, planes, ground and settings.
_RECENT = named_cache("recent migrations", max_entries=4)
_RECENT_MEMO_BYTES = 1 << 24   # a plan that keeps more (illumination phasors) is not kept


def _key(hologram: Any, z: Any, medium: Any, settings: MigrationSettings) -> tuple | None:
    if type(z) is float:
        zkey: Any = z
    elif isinstance(z, np.ndarray | list | tuple):
        zkey = np.asarray(z, dtype=float).tobytes() + bytes([np.ndim(z)])
    else:
        return None
    try:
        return (id(hologram), zkey, medium, settings) if hash(medium) is not None else None
    except TypeError:
        return None


def _recent(hologram: Any, z: Any, medium: Any, settings: MigrationSettings) -> Migration:
    key = _key(hologram, z, medium, settings)
    hit = _RECENT.lookup(key) if key is not None else None
    m = hit[1] if hit is not None and hit[0]() is hologram else None
    if m is None:
        return Migration(hologram, z, medium, settings)
    if m.backend.name == "kspace" and m.plan.wideband and m.settings.algorithm == "auto":
        # The NumPy sum, taken while the compiled loop was not worth loading: asked
        # again, the process's summed work may now pay for loading it (the same sum).
        m.backend = choose(m.plan)
    warn(hologram, m.settings, m.plan.illumination)
    return m


def _keep(hologram: Any, z: Any, medium: Any, settings: MigrationSettings,
          m: Migration) -> None:
    key = _key(hologram, z, medium, settings)
    kept = sum(getattr(v, "nbytes", 0) for v in m.plan.memo.values())
    if key is None or kept > _RECENT_MEMO_BYTES:
        return
    _RECENT.put(key, (weakref.ref(hologram), m), replace=True)
