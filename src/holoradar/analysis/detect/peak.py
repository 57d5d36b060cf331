"""The brightest object where it is, not where its image peaks: :func:`unbiased_peak`.

The image's amplitude maximum is biased along the line of sight: at one
frequency the focus is tens of centimetres long and the adjoint's ``1/r``
weighting pulls its maximum towards the array (a point 10 cm deep in sand
under a level 32 x 32 array 50 cm above the sand images brightest 9 cm short
of it). :func:`unbiased_peak` finds it from the hologram the image came from:

* under a level array, the exact point response fitted to the hologram from the
  image's brightest pixel (:class:`~.model.HologramModel`, the maximum of the
  normalised matched filter), with its Cramer-Rao standard deviations;
* under a tilted array (an image in the ground frame), the strongest object of
  the inverted reflectivity (:func:`holoradar.detect` with the hologram: no
  ``1/r`` pull, the illumination divided out), its position the object's
  centroid, its standard deviations a peak's of the resolution cell at the
  object's SNR.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .grid import as_volume, refine_peak

__all__ = ["PeakPosition", "unbiased_peak"]


class PeakPosition(tuple):
    """``(x, y, z)`` in metres, with the fit's standard deviations and amplitude.

    A plain 3-tuple to unpack (``x, y, z = hr.unbiased_peak(img, h)``)
    that also carries:

    Attributes
    ----------
    std : tuple of float
        Standard deviations of x, y, z, metres (Cramer-Rao bound of the fit, the
        noise per element estimated from what the fitted point leaves of the
        hologram: everything else in it counts as noise, so it is conservative
        when the hologram holds further objects).
    amplitude : complex
        The fitted scattering amplitude (the first frequency's, for a band).
    focus_fraction : float
        The share of the hologram's energy the fitted point explains (0..1).

    Examples
    --------
    >>> p = PeakPosition((0.01, 0.0, 0.6), (1e-4, 1e-4, 5e-4), 1 + 0j, 0.9)
    >>> x, y, z = p
    >>> z, p.std[2]
    (0.6, 0.0005)
    """

    std: tuple[float, float, float]
    amplitude: complex
    focus_fraction: float

    def __new__(cls, xyz: Any, std: Any, amplitude: complex = 0j,
                focus_fraction: float = np.nan) -> PeakPosition:
        obj = super().__new__(cls, tuple(float(v) for v in xyz))
        obj.std = tuple(float(v) for v in std)  # type: ignore[assignment]
        obj.amplitude = complex(amplitude)
        obj.focus_fraction = float(focus_fraction)
        return obj

    def __repr__(self) -> str:
        x, y, z = self
        sx, sy, sz = self.std
        return (f"PeakPosition(x={x:.5g} +- {sx:.2g}, y={y:.5g} +- {sy:.2g}, "
                f"z={z:.5g} +- {sz:.2g} m)")


def unbiased_peak(image: Any, hologram: Any, medium: Any = None,
                  migrate_options: Mapping[str, Any] | None = None) -> PeakPosition:
    """The position of the image's brightest object by the point-response fit.

    Parameters
    ----------
    image : Image
        One frame: a plane or a volume, ``migrate(hologram, z, medium=medium,
        upsample=u, **migrate_options)``.
    hologram : Hologram
        The hologram the image was migrated from (one frame; a level array at z = 0
        with the identity pose, or a posed array with the image in the ground frame).
    medium : Medium, optional
        The ground the image was formed through (None: free space).
    migrate_options : mapping, optional
        ``migrate``'s other keyword arguments the image was made with
        (``method``, ``dtype``...).

    Returns
    -------
    PeakPosition
        ``(x, y, z)`` metres, with ``.std``. Even from one plane the range ``z``
        is the fit's (the hologram's wave front fixes it), not the plane's.

    Raises
    ------
    ValueError
        No hologram, a hologram that did not make the image, several frames, no
        object above the noise (a posed array).

    Examples
    --------
    A point 10 cm deep in sand under an array 30 cm above it, one frequency:
    the brightest voxel lies short of it (the focus is long and the adjoint's
    weighting pulls it towards the array); the fit finds the point.

    >>> import holoradar as hr
    >>> sand = hr.Medium.half_space(0.30, 2.5)
    >>> h = hr.simulate(hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget((0.0, 0.0, 0.40))]),
    ...                 hr.Aperture.grid(16, 0.02), 9.9e9, include_surface=False,
    ...                 snr_db=40, seed=0)
    >>> img = hr.migrate(h, [0.34, 0.37, 0.40, 0.43], medium=sand)
    >>> x, y, z = hr.unbiased_peak(img, h, sand)
    >>> abs(z - 0.40) < 0.005
    True
    """
    if hologram is None:
        raise ValueError("unbiased_peak needs hologram= (the hologram the image was "
                         "migrated from): the fit of the point response is made on it")
    from ...data.hologram import Hologram
    from .model import HologramModel

    if isinstance(hologram, Hologram) and not hologram.pose.is_identity:
        return _strongest_reflector(image, hologram, medium, migrate_options)
    vol = as_volume(image)
    model = HologramModel(hologram, vol, medium, dict(migrate_options or {}))
    # The image only gives the fit its start: a loose check that it is this hologram's
    # (a plane cut from a volume differs from the plane's own migration by ~2 % through
    # a lossy ground, where the loss compensation depends on the planes).
    scale = float(np.max(np.abs(vol.data))) or 1.0
    err = float(np.max(np.abs(model.image(model.res) - vol.data))) / scale
    if not err < 0.1:
        raise ValueError(f"image is not the migration of hologram (through medium, with "
                         f"upsample={model.options['upsample']}): they differ by {err:.2g} of "
                         "the peak; pass the hologram it was made from (and migrate_options= "
                         "for other settings such as method)")
    p = np.abs(vol.data) ** 2
    index = tuple(int(i) for i in np.unravel_index(int(np.argmax(p)), p.shape))
    frac, _ = refine_peak(p, index)  # type: ignore[arg-type]
    start = vol.coords(*frac)
    r = model.add_point(start)
    a = model.objects[0]["a"]
    std = model.uncertainty()[0]
    # The share of the hologram's energy the point explains: what it took out of it.
    F = model.energy(model.h) - float(np.vdot(model.res, model.res).real)
    return PeakPosition(r, std, complex(a[0]), F / model.energy(model.h))


def _strongest_reflector(image: Any, hologram: Any, medium: Any,
                         migrate_options: Mapping[str, Any] | None) -> PeakPosition:
    """A posed array's brightest object: the strongest of the inverted reflectivity."""
    from .api import detect

    table = detect(image, hologram=hologram, medium=medium, max_objects=1,
                   migrate_options=dict(migrate_options or {}) or None)
    if table.empty:
        raise ValueError("no object above the noise in the reflectivity inverted from "
                         "hologram on the image's grid: there is no brightest object")
    row = table.iloc[0]
    return PeakPosition((row.x, row.y, row["range"]), (row.x_std, row.y_std, row.range_std),
                        complex(10 ** (row.amplitude_db / 20)), np.nan)
