"""The modelled field of a reference measurement at the elements.

Two references are modelled (time dependence ``exp(-i*omega*t)``; a source of
amplitude 1 sets the field's unit, so a calibrated hologram is in the model's
units):

``"plate"``
    A flat metal plate (reflection coefficient -1) parallel to the array at a
    known range ``plate_range``, lit by the horn. An infinite plate reflects the
    field of the horn's mirror image (the image-source closed form:
    ``-amplitude*exp(i*k*R')/R'`` times the horn's pattern along the unfolded ray,
    R' the distance from the image at range ``2*plate_range - z_horn``; for a
    plane wave or Gaussian beam, the field reflected by a perfect conductor). A
    finite plate (``plate_size``) is modelled by the project's Kirchhoff planar
    target (:class:`holoradar.PlanarTarget`, reflection -1) through
    :func:`holoradar.simulate`; the two differ by the plate edges' diffraction
    (a 0.8 m plate at 0.3 m, horn 0.25 m off centre: 2.5% RMS on a 16 x 16 array).
    With ``include_direct`` the horn's own field at the array is added (a horn
    whose direct wave reaches the elements).
``"empty"``
    Nothing in front of the array (an absorber, or the open sky): the elements
    see only the horn's direct field, ``source.field`` at the element positions.
    Useful where the horn's direct wave reaches the array with a known pattern
    (a horn facing the array).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from ..data.hologram import C0, frequency_axis
from ..model.scene import Aperture, Scene
from ..model.simulate import simulate
from ..model.targets import PlanarTarget
from ..physics.conductor import PEC_EPS
from ..physics.green import free_space_green
from ..physics.medium import Medium
from ..physics.sources import PointSource

__all__ = ["KINDS", "PEC_EPS", "reference_field"]

KINDS = ("plate", "empty")


def _image_plate(source: Any, k: float, plate_range: float, pts: np.ndarray) -> np.ndarray:
    """Field reflected by an infinite perfectly conducting plate at ``plate_range``."""
    pec = Medium.half_space(plate_range, PEC_EPS)
    if isinstance(source, PointSource):
        # Closed form of the Sommerfeld integral for reflection -1: the mirror image.
        img = source.mirror_position(pec)
        g = -free_space_green(k, img, pts)
        if source.has_pattern:
            d = pts - img
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            d[:, 2] *= -1  # unfold the reflection: the ray leaves the real horn downwards
            g = g * source.pattern(d)
        return source.amplitude * g
    return source.reflected(k, pec, pts)


def reference_field(kind: Literal["plate", "empty"], x: Any, y: Any, frequency: Any,
                    source: Any, *, plate_range: float | None = None,
                    plate_size: tuple[float, float] | None = None,
                    include_direct: bool | None = None) -> np.ndarray:
    """The field a perfect array records in a reference measurement (module text).

    Parameters
    ----------
    kind : {"plate", "empty"}
        A metal plate at a known range, or nothing in front of the array.
    x, y : array_like
        Element coordinates, metres (the array on the plane z = 0).
    frequency : float or array_like
        Hz; an array gives one field per frequency.
    source : PointSource, PlaneWave or GaussianBeam
        The horn as mounted during the measurement.
    plate_range : float
        ``"plate"``: range of the plate's front face from the array, metres.
    plate_size : (float, float), optional
        ``"plate"``: its width along x and height along y, metres, centred on the
        array's axis; default: an infinite plate.
    include_direct : bool, optional
        Add the horn's direct field at the elements (always for ``"empty"``;
        default False for ``"plate"``).

    Returns
    -------
    ndarray, complex, shape (ny, nx) or (nf, ny, nx)

    Examples
    --------
    >>> import holoradar as hr
    >>> x = (np.arange(4) - 1.5) * 0.025
    >>> m = reference_field("plate", x, x, 9.9e9, hr.PointSource((0, 0, -0.1)),
    ...                     plate_range=0.3)
    >>> m.shape, round(float(abs(m[0, 0]) * 0.7), 2)        # |E| ~ 1/R', R' = 0.7 m
    ((4, 4), 1.0)
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if not (hasattr(source, "field") and hasattr(source, "reflected")):
        raise ValueError("source must be a PlaneWave, PointSource or GaussianBeam (the horn "
                         f"during the reference measurement), got {type(source).__name__}")
    aperture = Aperture(x, y)
    shape = (aperture.y.size, aperture.x.size)
    if np.ndim(frequency) == 0:
        freqs, wide = np.atleast_1d(frequency_axis(frequency, shape)), False
    else:
        freqs, wide = np.asarray(frequency_axis(frequency, (np.size(frequency), *shape))), True
    pts = aperture.points
    free = Medium.free_space()
    if kind == "empty":
        if plate_range is not None or plate_size is not None:
            raise ValueError("an 'empty' reference has no plate: leave plate_range and "
                             "plate_size out")
        if include_direct is False:
            raise ValueError("an 'empty' reference is the horn's direct field: include_direct "
                             "cannot be False")
        rows = [source.field(2 * np.pi * f / C0, free, pts) for f in freqs]
    else:
        try:
            zp = float(plate_range)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            zp = np.nan
        if not np.isfinite(zp) or zp <= 0:
            raise ValueError(f"a 'plate' reference needs plate_range, the plate's range from "
                             f"the array in metres (> 0), got {plate_range!r}")
        if plate_size is None:
            rows = [_image_plate(source, 2 * np.pi * f / C0, zp, pts) for f in freqs]
        else:
            w, h = (float(v) for v in plate_size)
            if not (w > 0 and h > 0):
                raise ValueError(f"plate_size must be (width, height) > 0 in metres, got "
                                 f"{plate_size!r}")
            pixel = C0 / freqs.max() / 8
            plate = PlanarTarget.from_shape("rectangle", zp, reflection=-1, pixel=pixel,
                                            width=w, height=h, extent=max(w, h) + 4 * pixel)
            holo = simulate(Scene(free, source, [plate]), aperture, freqs)
            rows = list(holo.data.reshape(freqs.size, -1))
        if include_direct:
            rows = [r + source.field(2 * np.pi * f / C0, free, pts)
                    for r, f in zip(rows, freqs, strict=True)]
    out = np.stack(rows).reshape(freqs.size, *shape)
    return out if wide else out[0]
