"""Migration: back-propagation of a hologram to image planes (wave-front inversion).

``method="angular"`` applies the adjoint of exact forward propagation,
``IFFT2[FFT2[h] * conj(U(p, q; z))]`` (docs/imaging.md; through a medium
U includes each layer's kz and each interface's transmission, so a buried
object focuses at its true range). ``method="fresnel"`` is the paper's
paraxial Eq. 3 (through a medium: at the apparent distance).

:func:`migrate` is the adjoint of the migration operator
(:func:`holoradar.migration_operator`) with the settings given, applied to the
hologram: :mod:`holoradar.imaging.migration` holds the operator, its backends and
how one is chosen.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np

from ..data.hologram import Hologram, Image
from ..data.samples import SampledHologram
from ..physics.medium import Medium
from .migration.image import image_of
from .migration.memory import check_fits
from .migration.plan import IlluminationWarning
from .migration.settings import MigrationSettings

__all__ = ["IlluminationWarning", "check_fits", "migrate"]


def migrate(hologram: Hologram, z: float | Sequence[float] | np.ndarray, *,
            medium: Medium | None = None, method: Literal["angular", "fresnel"] = "angular",
            pad: bool | float = True, upsample: int = 1, compensate_loss: bool = True,
            snr_db: float | None = None, fov: Literal["aperture", "full"] = "aperture",
            dtype: type | None = None, progress: bool | None = None,
            combine: Literal["coherent", "incoherent", "none"] = "coherent",
            equalize: bool | Sequence[float] | np.ndarray = True,
            algorithm: Literal["auto", "kspace", "frequency", "stolt"] = "auto",
            frame: Literal["aperture", "ground"] = "aperture", x: Any = None,
            y: Any = None) -> Image:
    """Back-propagate a hologram to the planes at range ``z``.

    Parameters
    ----------
    hologram : Hologram or SampledHologram
        Field on a uniform grid of the aperture plane, shape (..., ny, nx), or
        (..., nf, ny, nx) with nf frequencies. A monostatic hologram (scanned
        transceiver) is back-propagated over the round trip (wavenumber 2k; in a
        medium each layer's round-trip kz and both legs' transmissions,
        :func:`~holoradar.physics.propagation.two_way_transfer`). Samples at
        scattered positions (:meth:`Hologram.from_samples`) are imaged onto the grid
        ``x``, ``y`` (default: their extent at the image band's Nyquist pitch) through
        non-uniform FFTs (:mod:`holoradar.imaging.samples`); ``pad``, ``upsample``,
        ``fov`` and ``frame`` then keep their defaults.
    z : float or sequence of float
        Image ranges from the aperture, metres (>= 0). A scalar gives one plane.
    medium : Medium, optional
        Layered ground; ``None`` means free space.
    method : {"angular", "fresnel"}
        Exact non-paraxial angular spectrum (default) or paraxial Fresnel (Eq. 3).
    pad : bool or float
        Zero padding before the FFT so that the periodic FFT does not wrap the
        image: ``True`` (default) pads to at least twice each size and enough to
        sample the transfer function at the farthest plane
        (:func:`~holoradar.physics.propagation.padded_shape`); a float is the factor.
    upsample : int
        Output pixels per element pitch. >1 interpolates the band-limited image
        exactly (zero padding of its spectrum); it adds no resolution.
    fov : {"aperture", "full"}
        Field of view: the aperture's extent (default), or the whole padded FFT
        grid centred on it (to see what lies beside the array, e.g. the mirror
        image of a horn held at its side).
    compensate_loss : bool
        In lossy layers, back-propagate each travelling component with its phase
        and transmissions but without a second absorption ``a = exp(-Im(kz)*h)``,
        as long as it stands above the noise; components attenuated below it are
        weighted as in the matched filter: the filter is
        ``conj(U) * (1/a0) * (1 + e)/(a/a0 + e)``, ``a0`` the vertical component's
        absorption, ``e = 10^(-snr_db/20)``
        (:func:`~holoradar.physics.propagation.absorption_gain`). The plain
        adjoint (False) is the matched filter, best in SNR, but its extra decay
        with depth pulls the focus towards the surface, by
        ``~ k*Im(n) * (FWHM/2.355)^2`` for a depth response of width FWHM (6 mm in
        the paper's sand with its 16 x 16 array). The trade-off: the compensated
        image's noise rises above the adjoint's by the absorption it undoes but
        never above that of a lossless back-propagation, and its SNR in a plane stays
        within the bound of the tests (a fraction of a dB in clay). Default True.
        No effect in lossless media.
    snr_db : float, optional
        Signal-to-noise ratio of the hologram, dB, that limits the loss
        compensation. Default: estimated from the part of its spectrum that is
        evanescent over the air gap (:func:`~holoradar.data.noise.estimate_snr`),
        which needs a pitch below half a wavelength; otherwise 40 dB.
    dtype : numpy dtype, optional
        Working precision and the image's type. Default ``np.complex64`` (single
        precision, about twice as fast: the image agrees with double precision to a
        relative 1e-6, far below any measured hologram's noise); ``np.complex128``
        for double.
    progress : bool, optional
        Show a progress bar once the work has taken a second; default: only when
        the output exceeds 2e8 pixels and standard error is a terminal.
    combine : {"coherent", "incoherent", "none"}
        Several frequencies: ``"coherent"`` (default) sums the complex images of
        all frequencies, which focuses in depth (range resolution
        ``c/(2 B Re(n))``, :func:`holoradar.theory.range_resolution`);
        ``"incoherent"`` returns ``sqrt(sum_f |w_f I_f|^2)`` (no range focusing,
        less speckle); ``"none"`` keeps them apart, shape (..., nf, nz, ny', nx').
        For a receiver array lit by a separate ``hologram.source``, each
        frequency's image is first multiplied by the unit phasor
        ``conj(E0)/|E0|`` of its incident field at every pixel (otherwise the
        frequencies add with the illumination's phases); without a source a
        plane wave at normal incidence is assumed, with a warning. A monostatic
        hologram needs no such step (the round trip is in the transfer).
    equalize : bool or array_like
        Weights ``w_f`` of the frequencies: True (default) normalises each
        frequency's hologram to unit RMS (the paper's equalising factor: the
        device's response varies across the band); False keeps the recorded
        amplitudes; an array gives nf weights.
    algorithm : {"auto", "kspace", "frequency", "stolt"}
        One frequency: ``"frequency"`` builds (and caches) the transfer function
        of every plane; ``"kspace"`` reaches uniformly spaced planes in the
        deepest region (lossless, or without loss compensation) by one transfer
        and a phase step from plane to plane (the same image); ``"auto"`` takes
        the latter when the planes' transfers would not fit in the cache.
        Several frequencies: ``"frequency"`` sums the per-frequency angular-spectrum
        migrations; ``"kspace"`` carries the coherent sum from plane to plane in the
        wavenumber domain (one inverse FFT per plane instead of one per frequency
        and plane; the same result to rounding), which needs uniformly spaced
        planes in the deepest region, ``fov="aperture"``, ``combine="coherent"``, a
        transceiver or a normal plane wave, and no loss to compensate
        (:mod:`~holoradar.imaging.migration.backends.kspace`, a NumPy recurrence:
        the reference). ``"auto"`` (default) computes that same sum where it
        applies, by a compiled loop over the spectral columns when numba is
        installed (:mod:`~holoradar.imaging.migration.backends.columns`, equal to
        ``"kspace"`` to rounding), else by ``"kspace"``; elsewhere ``"frequency"``.
        ``"stolt"``: Stolt's migration, each column's plane waves interpolated onto
        a uniform kz grid, then one inverse FFT along z
        (:mod:`~holoradar.imaging.migration.backends.stolt`): propagating waves
        only, no per-plane band limit, each plane wave's error at most 0.9% of
        its amplitude; it applies where ``"kspace"`` does, except a receiver array
        without ``hologram.source``, and raises a ``ValueError`` naming what
        blocks it elsewhere.
    frame : {"aperture", "ground"}
        ``"aperture"`` (default): planes parallel to the aperture at distances
        ``z`` from it, pixels in its own coordinates (a tilted aperture: its own
        depth sweep, in free space; a level one at a height ``pose.center[2]``:
        through the medium seen from there). ``"ground"``: horizontal planes at
        world ranges ``z`` (the medium's frame), through the layers with
        refraction, pixels in world coordinates over the aperture's footprint
        (or ``x``, ``y``): for a tilted aperture (``hologram.pose``). Method: an
        exact rotation of the angular spectrum onto a horizontal reference plane
        (:mod:`~holoradar.imaging.migration.backends.oblique`), then the same
        migration.
    x, y : array_like, optional
        ``frame="ground"``: uniform world grids of the image, metres (default:
        the footprint of the elements at their pitch / ``upsample``).
    Returns
    -------
    Image
        ``data`` of shape (..., nz, ny', nx') for a sequence of ranges and
        (..., ny', nx') for a scalar, with ny' = upsample*(ny - 1) + 1 (same for x);
        with ``combine="none"``, (..., nf, nz, ny', nx'). ``Image.frequency`` holds
        the frequencies of a wideband image.

    Raises
    ------
    ValueError
        Non-uniform grid, negative range, bad method or upsample.

    Notes
    -----
    A pitch above lambda/2 warns (:class:`~holoradar._validate.AliasingWarning`):
    waves steeper than ``arcsin(lambda/(2*pitch))`` alias.

    Examples
    --------
    >>> import holoradar as hr
    >>> scene = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.4))],
    ...                  source=hr.PlaneWave())
    >>> holo = hr.simulate(scene, hr.Aperture.grid(64, 0.01), 9.9e9)
    >>> img = hr.migrate(holo, [0.35, 0.40, 0.45])
    >>> round(img.peak()[2], 2)
    0.4
    """
    if dtype is None:
        dtype = np.complex64   # the default users run: single precision (see dtype)
    if isinstance(hologram, SampledHologram):   # scattered samples: imaging/samples.py
        from .samples import migrate_samples

        given = {k: v for k, v, default in (("pad", pad, True), ("upsample", upsample, 1),
                                             ("fov", fov, "aperture"),
                                             ("frame", frame, "aperture")) if v != default}
        return migrate_samples(hologram, z, x=x, y=y, equalize=equalize, medium=medium,
                               method=method, compensate_loss=compensate_loss,
                               snr_db=snr_db, dtype=dtype, progress=progress,
                               combine=combine, algorithm=algorithm, **given)
    options = (method, pad, upsample, compensate_loss, snr_db, fov, dtype, progress, combine,
               equalize, algorithm, frame)
    if x is None and y is None and _hashable(options):
        settings = _settings(*options)   # the same options again: checked once
    else:
        settings = MigrationSettings(
            method=method, pad=pad, upsample=upsample, compensate_loss=compensate_loss,
            snr_db=snr_db, fov=fov, dtype=dtype, progress=progress, combine=combine,
            equalize=equalize, algorithm=algorithm, frame=frame, x=x, y=y)
    return image_of(hologram, z, medium, settings)


@functools.lru_cache(maxsize=64, typed=True)
def _settings(method: Any, pad: Any, upsample: Any, compensate_loss: Any, snr_db: Any,
              fov: Any, dtype: Any, progress: Any, combine: Any, equalize: Any,
              algorithm: Any, frame: Any) -> MigrationSettings:
    """Validated settings, kept for the next call with the same options (they are
    immutable; a survey or a viewer images frame after frame with the same ones)."""
    return MigrationSettings(
        method=method, pad=pad, upsample=upsample, compensate_loss=compensate_loss,
        snr_db=snr_db, fov=fov, dtype=dtype, progress=progress, combine=combine,
        equalize=equalize, algorithm=algorithm, frame=frame)


def _hashable(options: tuple) -> bool:
    # Plain values only: numpy scalars of different types can hash alike yet validate
    # apart (True == 1), so the cache takes exactly bool, int, float, str, None, types.
    return all(type(v) in (bool, int, float, str, type(None), type) or isinstance(v, np.dtype)
               for v in options)
