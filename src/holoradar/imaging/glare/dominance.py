"""Whether an image's brightest point is the surface glare rather than an object.

The glare (the horn's reflection in the ground surface, the wave of its mirror
image) is usually the strongest part of a hologram: a first image of raw data
then shows the glare and nothing says so. :func:`glare_share` decides it from
the data: it fits the glare (the Gaussian-beam model of
:func:`~holoradar.imaging.glare.suppress_surface`, with the horn's direct wave),
images what the fit would remove at the brightest voxel with the same imaging,
and compares it there with the rest. Imaging is linear, so the image is the sum
of the two parts, and the glare *dominates* the brightest point when its part
there is larger than everything else's: ``|G(p)| > |I(p) - G(p)|``.
:func:`warn_if_glare_dominates` turns that into a :class:`GlareWarning` naming
the fix.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...data.hologram import Hologram, Image
from ...physics.medium import Medium
from ._common import Radiator

__all__ = ["DIRECT_SHARE", "GlareShare", "GlareWarning", "glare_share",
           "warn_if_glare_dominates"]

DIRECT_SHARE = 0.01
"""Energy share of the fitted direct wave above which the data are taken to hold one (the
rule :func:`~holoradar.imaging.glare.suppress_surface` uses for its reference)."""


class GlareWarning(UserWarning):
    """The brightest point of an image is the surface glare, not an object."""


@dataclass(frozen=True)
class GlareShare:
    """What :func:`glare_share` found at an image's brightest voxel.

    Attributes
    ----------
    peak : tuple of float
        The brightest voxel (x, y, z), metres.
    share : float
        ``|G(p)| / |I(p)|``: the amplitude the glare (and the direct wave) gives
        the brightest voxel over the image's there.
    over_rest : float
        ``|G(p)| / |I(p) - G(p)|``: the glare's part over everything else's.
    dominates : bool
        ``over_rest > 1``: the glare explains the brightest voxel more than
        everything else does.
    mirror_position : tuple of float
        Where the fit put the glare's source (the horn's mirror image), metres.
    direct : bool
        The data hold the horn's direct wave (at least :data:`DIRECT_SHARE` of
        their energy): ``holoradar suppress`` then keeps its default, otherwise it
        needs ``--no-direct``.
    glare_db : float
        Energy of the fitted glare over the rest of the hologram, dB.
    """

    peak: tuple[float, float, float]
    share: float
    over_rest: float
    dominates: bool
    mirror_position: tuple[float, float, float]
    direct: bool
    glare_db: float


def glare_share(hologram: Hologram, image: Image, medium: Medium | None, *,
                source: Any = None, **migrate_options: Any) -> GlareShare | None:
    """How much of an image's brightest voxel the surface glare makes.

    Parameters
    ----------
    hologram : Hologram
        The data imaged: one view at one frequency, from an array lit by a horn
        (a point source, a dipole or a Gaussian beam).
    image : Image
        Its image, as :func:`holoradar.migrate` made it with ``migrate_options``.
    medium : Medium or None
        The ground it was imaged through (its surface makes the glare).
    source : optional
        The radiator; default ``hologram.source``.
    **migrate_options
        The options the image was made with (``method``, ``upsample``, ``frame``,
        ``fov``...); the glare is imaged with them.

    Returns
    -------
    GlareShare or None
        None where the glare cannot be told: no ground, no point-like radiator,
        several frequencies or views, a scanned transceiver, or a fit the model
        refuses.

    Examples
    --------
    >>> import holoradar as hr
    >>> sand = hr.Medium.half_space(0.3, 2.5)
    >>> scene = hr.Scene(sand, hr.PointSource((0.0, -0.2, 0.0)),
    ...                  [hr.PointTarget((0.0, 0.0, 0.4), 0.005)])
    >>> h = hr.simulate(scene, hr.Aperture.grid(32, 0.0125), 9.9e9)
    >>> img = hr.migrate(h, [0.35, 0.4, 0.45], medium=sand)
    >>> glare_share(h, img, sand).dominates
    True
    """
    from ..migration.image import Migration
    from ..migration.settings import MigrationSettings
    from .suppress import suppress_surface

    src = source if source is not None else hologram.source
    if (medium is None or medium.is_free_space or hologram.is_wideband or hologram.monostatic
            or hologram.data.ndim != 2 or not isinstance(src, Radiator)):
        return None
    a = np.abs(image.data)
    if a.ndim == 2:
        a = a[None]
    iz, iy, ix = np.unravel_index(int(np.argmax(a)), a.shape)
    zs = np.atleast_1d(image.z)
    z_p = float(zs[iz])
    try:
        with warnings.catch_warnings():
            # the fit's and the imaging's own warnings belong to the steps that use them
            warnings.simplefilter("ignore")
            clean, rep = suppress_surface(hologram, medium, src, "gaussian", direct=True)
            removed = hologram.with_data(hologram.data - clean.data)
            # One frozen operator for both parts (the loss compensation's SNR from the
            # whole hologram, on the image's planes): the imaging stays linear.
            settings = MigrationSettings.of(**{**migrate_options, "progress": False})
            if settings.compensate_loss and settings.snr_db is None:
                snr = Migration(hologram, zs, medium, settings).plan.snr_db
                settings = settings.replace(snr_db=snr)
            m = Migration(hologram, z_p, medium, settings)
            whole, glare = m.image(hologram.data), m.image(removed.data)
    except ValueError:
        return None
    # the pixel of the brightest voxel on this plane's grid (the same grid, made alike)
    jx = int(np.argmin(np.abs(whole.x - image.x[ix])))
    jy = int(np.argmin(np.abs(whole.y - image.y[iy])))
    i_p, g_p = complex(whole.data[jy, jx]), complex(glare.data[jy, jx])
    total = float(np.sum(np.abs(hologram.data) ** 2))
    direct_energy = 0.0
    if rep.direct_removed_db is not None:
        left = float(np.sum(np.abs(clean.data) ** 2))
        direct_energy = left * 10 ** (rep.direct_removed_db / 10)
    return GlareShare(
        peak=(float(image.x[ix]), float(image.y[iy]), z_p),
        share=abs(g_p) / max(abs(i_p), 1e-300),
        over_rest=abs(g_p) / max(abs(i_p - g_p), 1e-300),
        dominates=abs(g_p) > abs(i_p - g_p),
        mirror_position=tuple(float(v) for v in (rep.mirror_position or (np.nan,) * 3)),
        direct=direct_energy >= DIRECT_SHARE * total,
        glare_db=float(rep.glare_removed_db) if rep.glare_removed_db is not None else np.nan)


def dominance_message(found: GlareShare, what: str = "the image", fix: str | None = None
                      ) -> str:
    """The warning's text for a :class:`GlareShare` that dominates."""
    x, y, z = (100 * v for v in found.peak)
    fix = fix or ("remove it first: holoradar.suppress_surface(hologram, medium"
                  + ("" if found.direct else ", direct=False") + "), then image the result")
    return (f"{what}: the brightest point (x={x:.1f} y={y:.1f} z={z:.1f} cm) is the surface "
            f"glare, the horn's reflection in the ground, not an object (there the fitted "
            f"glare's image is {found.over_rest:.1f} times the rest's); {fix}")


def warn_if_glare_dominates(hologram: Hologram, image: Image, medium: Medium | None, *,
                            what: str = "the image", fix: str | None = None,
                            stacklevel: int = 2, **migrate_options: Any) -> GlareShare | None:
    """:func:`glare_share`, warning (:class:`GlareWarning`) when the glare dominates.

    Parameters
    ----------
    hologram, image, medium, **migrate_options
        As for :func:`glare_share`.
    what : str
        How the message names the image (a file name).
    fix : str, optional
        The remedy the message names (default: :func:`holoradar.suppress_surface`).
    stacklevel : int
        Of the warning, counted from the caller of this function.

    Returns
    -------
    GlareShare or None
    """
    found = glare_share(hologram, image, medium, **migrate_options)
    if found is not None and found.dominates:
        warnings.warn(dominance_message(found, what, fix), GlareWarning,
                      stacklevel=stacklevel + 1)
    return found
