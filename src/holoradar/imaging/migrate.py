"""Migration: back-propagation of a hologram to image planes (wave-front inversion).

``method="angular"`` applies the adjoint of exact forward propagation,
``IFFT2[FFT2[h] * conj(U(p, q; z))]`` (docs/imaging.md; through a medium
U includes each layer's kz and each interface's transmission, so a buried
object focuses at its true range). ``method="fresnel"`` is the paper's
paraxial Eq. 3 (through a medium: at the apparent distance).
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np

from .. import _threads
from .._lazy import lazy_module
from .._threads import pool
from .._validate import AliasingWarning, as_real, check_nonnegative_ranges, warn_if_aliased
from ..data.hologram import C0, Hologram, Image
from ..data.noise import estimate_snr
from ..physics.incident import incident_phasors
from ..physics.medium import FREE_SPACE, Medium
from ..physics.propagation import (
    DEFAULT_SNR_DB,
    AngularSpectrum,
    Fresnel,
    ifft2_cropped,
    padded_shape,
)
from ..physics.sources import PlaneWave
from . import columns, kspace, oblique, stolt

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

__all__ = ["IlluminationWarning", "check_fits", "migrate"]

_CHUNK = 8  # planes per batched inverse FFT
_THREADED_MULTIPLY = 1 << 19  # products (planes x components) worth sharing among threads
_CHECK_ABOVE = 1 << 26  # bytes of peak memory above which migrate asks what is available


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
    hologram : Hologram
        Field on a uniform grid of the aperture plane, shape (..., ny, nx), or
        (..., nf, ny, nx) with nf frequencies. A monostatic hologram (scanned
        transceiver) is back-propagated over the round trip (wavenumber 2k; in a
        medium each layer's round-trip kz and both legs' transmissions,
        :func:`~holoradar.physics.propagation.two_way_transfer`).
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
        Working precision: ``np.complex64`` for speed; default that of the data.
    progress : bool, optional
        Show a progress bar once the work has taken a second; default: only when
        the output exceeds 2e8 pixels.
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
        (:mod:`holoradar.imaging.kspace`, a NumPy recurrence: the reference).
        ``"auto"`` (default) computes that same sum where it applies, by a compiled
        loop over the spectral columns when numba is installed
        (:mod:`holoradar.imaging.columns`, equal to ``"kspace"`` to rounding), else
        by ``"kspace"``; elsewhere ``"frequency"``. ``"stolt"``: Stolt's migration,
        each column's plane waves interpolated onto a uniform kz grid, then one
        inverse FFT along z (:mod:`holoradar.imaging.stolt`): propagating waves
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
        (:mod:`holoradar.imaging.oblique`), then the same migration.
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
    if not isinstance(hologram, Hologram):
        raise ValueError(f"hologram must be a holoradar.Hologram, got {type(hologram).__name__}")
    if algorithm not in ("auto", "kspace", "frequency", "stolt"):
        raise ValueError("algorithm must be 'auto', 'kspace', 'frequency' or 'stolt', "
                         f"got {algorithm!r}")
    if frame not in ("aperture", "ground"):
        raise ValueError(f"frame must be 'aperture' or 'ground', got {frame!r}")
    if frame == "aperture" and (x is not None or y is not None):
        raise ValueError("x and y set the world grid of frame='ground'; frame='aperture' "
                         "images on the aperture's own grid (use upsample)")
    if medium is not None and not isinstance(medium, Medium):
        raise ValueError(f"medium must be a holoradar.Medium or None, got {type(medium).__name__}")
    pose = hologram.pose
    if frame == "aperture" and medium is not None and not medium.is_free_space \
            and not pose.is_level:
        raise ValueError("a tilted aperture (hologram.pose.tilt > 0) sees the layers "
                         "obliquely: image through a medium with frame='ground'")
    if hologram.is_wideband:
        return _migrate_wideband(hologram, z, medium=medium, method=method, pad=pad,
                                 upsample=upsample, compensate_loss=compensate_loss,
                                 snr_db=snr_db, fov=fov, dtype=dtype, progress=progress,
                                 combine=combine, equalize=equalize, algorithm=algorithm,
                                 frame=frame, x=x, y=y)
    zs = check_nonnegative_ranges(z, "z")
    scalar = np.ndim(z) == 0
    if algorithm == "stolt":
        raise ValueError("algorithm='stolt' sums several frequencies: this hologram has "
                         "one; use 'auto'")
    check_fits(hologram, zs.size, upsample, dtype, factor=1.5)
    if frame == "ground":
        return _migrate_ground(hologram, zs, scalar, medium, method=method, pad=pad,
                               upsample=upsample, compensate_loss=compensate_loss,
                               snr_db=snr_db, dtype=dtype, x=x, y=y, fov=fov)
    if medium is not None and pose.center[2] != 0.0 and not medium.is_free_space:
        # A level aperture at a height: the layers as seen from its plane.
        if pose.center[2] >= medium.z_interfaces[0]:
            raise ValueError(f"hologram.pose puts the aperture at z = {pose.center[2]:.4g} m, "
                             f"at or below the ground surface ({medium.z_interfaces[0]} m)")
        medium = oblique._shifted(medium, pose.center[2])
    if method not in ("angular", "fresnel"):
        raise ValueError(f"method must be 'angular' or 'fresnel', got {method!r}")
    if fov not in ("aperture", "full"):
        raise ValueError(f"fov must be 'aperture' or 'full', got {fov!r}")
    if not isinstance(upsample, int | np.integer) or upsample < 1:
        raise ValueError(f"upsample must be an integer >= 1, got {upsample!r}")
    if medium is not None and not isinstance(medium, Medium):
        raise ValueError(f"medium must be a holoradar.Medium or None, got {type(medium).__name__}")
    if method == "fresnel" and np.any(zs <= 0):
        raise ValueError("z must be > 0 with method='fresnel' (its kernel is singular at 0)")
    dx, dy = hologram.pitch
    # A transceiver's round trip doubles the transverse wavenumbers: lambda/4 sampling.
    warn_if_aliased(max(dx, dy), hologram.wavelength, "hologram",
                    round_trip=hologram.monostatic)
    work = np.dtype(dtype) if dtype is not None else (
        np.complex64 if hologram.data.dtype == np.complex64 else np.complex128)
    if work not in (np.complex64, np.complex128):
        raise ValueError(f"dtype must be numpy.complex64 or numpy.complex128, got {dtype!r}")
    med = medium if medium is not None else FREE_SPACE
    stepping = algorithm != "frequency" and np.size(zs) > 1 and kspace.applicable(
        hologram, zs, med, method=method, fov=fov, combine="coherent",
        compensate_loss=compensate_loss, phase_incident=False)
    if algorithm == "kspace" and not stepping:
        raise ValueError("algorithm='kspace' needs several uniformly spaced planes in the "
                         "deepest region, method='angular', fov='aperture' and no loss to "
                         "compensate; use 'auto'")
    if stepping and (algorithm == "kspace" or _too_big_to_cache(hologram, zs, pad, work)):
        # Uniform planes in the deepest region whose transfer functions could not all be
        # cached: one transfer, then a phase step from plane to plane (the same result;
        # no transfer function per plane to build on every call).
        return kspace.migrate_kspace(hologram, zs, med, np.ones(1), pad=pad, upsample=upsample,
                                     dtype=work, phase_incident=False)
    cls = AngularSpectrum if method == "angular" else Fresnel
    if snr_db is None:
        snr_db = _data_snr(hologram, medium, zs) if compensate_loss else DEFAULT_SNR_DB
    else:
        snr_db = as_real(snr_db, "snr_db")
    op = cls(hologram.data.shape[-2:], dx, dy, hologram.k, zs, medium, pad, work,
             compensate_loss=compensate_loss, snr_db=snr_db, monostatic=hologram.monostatic)
    H = op.spectrum(hologram.data)
    ny, nx = op.shape
    u = int(upsample)
    batch = H.shape[:-2]
    My, Mx = H.shape[-2:]
    if fov == "full":
        # The whole periodic grid, rolled so that the aperture sits in its middle.
        oy, ox = u * My, u * Mx
        sy, sx = u * ((My - ny) // 2), u * ((Mx - nx) // 2)
    else:
        oy, ox = u * (ny - 1) + 1, u * (nx - 1) + 1
        sy = sx = 0
    # Without crop or interpolation the products are computed in the output array itself
    # and transformed in place: one multiply and one inverse FFT per plane, no copies.
    in_place = u == 1 and (My, Mx) == (ny, nx) and fov == "aperture"
    out = (None if in_place and zs.size == 1
           else np.empty((*batch, zs.size, oy, ox), dtype=work))
    show = zs.size * oy * ox * math.prod(batch) > 2e8 if progress is None \
        else progress
    # delay: a bar only for work that lasts (progress=True shows it after a second)
    bar = None
    if show:
        from tqdm.auto import tqdm  # here, not at import: holoradar._lazy

        bar = tqdm(total=zs.size, desc="migrate", unit="plane", delay=1.0)
    chunk = zs.size if in_place else _CHUNK
    for c0 in range(0, zs.size, chunk):
        Ucs = op.adjoint_transfers[c0:c0 + chunk]
        if zs.size == 1:
            # One plane: multiply into the spectrum itself (ours, no longer needed) and
            # transform it in place; unpadded it is the image: no allocation.
            prod = H[..., None, :, :]
            if in_place:
                out = prod
        else:
            prod = out[..., c0:c0 + len(Ucs), :, :] if in_place else np.empty(
                (*batch, len(Ucs), My, Mx), dtype=work)
        _multiply_planes(H, Ucs, prod)
        if u > 1:
            prod = _zero_pad_spectrum(prod, u)
        if fov == "full" or in_place:
            planes = sfft.ifft2(prod, axes=(-2, -1), workers=op.workers, overwrite_x=True)
        else:
            planes = ifft2_cropped(prod, (oy, ox), op.workers, overwrite=True)
        if fov == "full":
            planes = np.roll(planes, (sy, sx), axis=(-2, -1))
        if not (in_place and np.may_share_memory(planes, out)):
            sl = planes[..., :oy, :ox]
            out[..., c0:c0 + len(Ucs), :, :] = sl * (u * u) if u > 1 else sl
        if bar is not None:
            bar.update(len(Ucs))
    if bar is not None:
        bar.close()
    x = hologram.x[0] + (np.arange(ox) - sx) * dx / u
    y = hologram.y[0] + (np.arange(oy) - sy) * dy / u
    data = out[..., 0, :, :] if scalar else out
    return Image(data, x, y, zs, hologram.frequency, method, has_z_axis=not scalar)


def _migrate_ground(hologram: Hologram, zs: np.ndarray, scalar: bool, medium: Medium | None, *,
                    method: str, pad: Any, upsample: Any, compensate_loss: bool,
                    snr_db: Any, dtype: Any, x: Any, y: Any, fov: Any) -> Image:
    """``frame="ground"``: horizontal world planes through the layers."""
    if method != "angular":
        raise ValueError("frame='ground' uses the exact angular spectrum: method must be "
                         f"'angular', got {method!r}")
    if fov != "aperture":
        raise ValueError("frame='ground' images the aperture's footprint or the x, y grids "
                         f"given: fov must be 'aperture', got {fov!r}")
    if not isinstance(upsample, int | np.integer) or isinstance(upsample, bool) \
            or upsample < 1:
        raise ValueError(f"upsample must be an integer >= 1, got {upsample!r}")
    if upsample != 1 and x is not None and y is not None:
        raise ValueError("upsample sets the step of the default ground grid; with both x "
                         "and y given it would be ignored: leave it at 1")
    if dtype is not None and np.dtype(dtype) not in (np.complex64, np.complex128):
        raise ValueError(f"dtype must be numpy.complex64 or numpy.complex128, got {dtype!r}")
    dx, dy = hologram.pitch
    warn_if_aliased(max(dx, dy), hologram.wavelength, "hologram",
                    round_trip=hologram.monostatic)
    med = medium if medium is not None else FREE_SPACE
    gain = None
    if compensate_loss and not med.is_lossless:
        gain = (as_real(snr_db, "snr_db") if snr_db is not None
                else _data_snr(hologram, med, zs))
    img = oblique.migrate_ground(hologram, zs, med, x=x, y=y, pad=pad,
                                 upsample=int(upsample), compensate_loss=gain, dtype=dtype)
    data = img.data[..., 0, :, :] if scalar else img.data
    return Image(data, img.x, img.y, zs, hologram.frequency, img.method,
                 has_z_axis=not scalar)


class IlluminationWarning(UserWarning):
    """Frequencies were combined with an assumed incident field."""


def _weights(hologram: Hologram, equalize: Any) -> np.ndarray:
    nf = hologram.nf
    if isinstance(equalize, bool | np.bool_):
        if not equalize:
            return np.ones(nf)
        rms = np.sqrt(np.mean(np.abs(np.moveaxis(hologram.data, -3, 0).reshape(nf, -1)) ** 2,
                              axis=1))
        return np.divide(1.0, rms, out=np.zeros(nf), where=rms > 0)
    try:
        w = np.array(equalize, dtype=float)
    except (TypeError, ValueError):
        w = np.full(0, np.nan)
    if w.shape != (nf,) or not np.all(np.isfinite(w)):
        raise ValueError(f"equalize must be True, False or {nf} finite weights (one per "
                         f"frequency), got {equalize!r}")
    return w


def _migrate_wideband(hologram: Hologram, z: Any, *, combine: str, equalize: Any,
                      medium: Medium | None, algorithm: str = "auto", **kw: Any) -> Image:
    """The exact per-frequency sum: each frequency migrated, phased, weighted, combined."""
    if combine not in ("coherent", "incoherent", "none"):
        raise ValueError(f"combine must be 'coherent', 'incoherent' or 'none', got {combine!r}")
    if medium is not None and not isinstance(medium, Medium):
        raise ValueError(f"medium must be a holoradar.Medium or None, got {type(medium).__name__}")
    w = _weights(hologram, equalize)
    zs_all = check_nonnegative_ranges(z, "z")
    med = medium if medium is not None else FREE_SPACE
    comp = kw.get("compensate_loss", True)
    method, fov = kw.get("method", "angular"), kw.get("fov", "aperture")
    fast = kw.get("frame") != "ground" and hologram.pose.is_identity and kspace.applicable(
        hologram, zs_all, med, method=method, fov=fov, combine=combine, compensate_loss=comp)
    if algorithm == "kspace" and not fast:
        raise ValueError("algorithm='kspace' needs uniformly spaced planes in the deepest "
                         "region, fov='aperture', combine='coherent', a transceiver or a "
                         "normal plane wave, and no loss to compensate; use 'auto'")
    if algorithm == "stolt":
        stolt.check_applicable(hologram, zs_all, med, method=method, fov=fov,
                               combine=combine, compensate_loss=comp,
                               frame=kw.get("frame", "aperture"))
    # Before any work: the volume must fit (the per-frequency sum holds ~3 volumes).
    check_fits(hologram, zs_all.size * (hologram.nf if combine == "none" else 1),
               kw.get("upsample", 1), kw.get("dtype"), factor=1.5 if fast else 3.0)
    if kw.get("snr_db") is None and kw.get("compensate_loss", True):
        kw["snr_db"] = _data_snr(hologram, medium, zs_all)
    if not hologram.monostatic and hologram.source is None and combine == "coherent":
        warnings.warn("combining frequencies without hologram.source: a plane wave at normal "
                      "incidence is assumed for each frequency's incident phase; give the "
                      "source for the true one", IlluminationWarning, stacklevel=3)
    warn_if_aliased(max(hologram.pitch), C0 / hologram.frequencies[-1], "hologram",
                    round_trip=hologram.monostatic)
    if fast and algorithm != "frequency":
        if algorithm == "stolt":
            img = stolt.migrate_stolt(hologram, zs_all, med, w, pad=kw.get("pad", True),
                                      upsample=kw.get("upsample", 1), dtype=kw.get("dtype"))
        elif algorithm == "auto" and columns.available():
            img = columns.migrate_columns(hologram, zs_all, med, w, pad=kw.get("pad", True),
                                          upsample=kw.get("upsample", 1),
                                          dtype=kw.get("dtype"))
        else:
            img = kspace.migrate_kspace(hologram, zs_all, med, w, pad=kw.get("pad", True),
                                        upsample=kw.get("upsample", 1), dtype=kw.get("dtype"))
        if np.ndim(z) == 0:
            return Image(img.data[..., 0, :, :], img.x, img.y, img.z, img.frequency,
                         img.method, has_z_axis=False)
        return img
    if kw.get("fov") == "full" and kw.get("pad", True) is True and kw.get("frame") != "ground":
        # The full field of view is the padded grid, whose size grows with the wavelength:
        # one padding factor for the whole band (the largest any frequency needs) gives
        # every frequency the same pixels to add.
        n = hologram.data.shape[-2:]
        need = [padded_shape(n, True, pitch=hologram.pitch, wavelength=C0 / f / (
            2 if hologram.monostatic else 1), z_max=float(zs_all.max()))
            for f in hologram.frequencies]
        kw["pad"] = max(m / s for shape in need for m, s in zip(shape, n, strict=True))
    acc: np.ndarray | None = None
    parts = []
    img = None
    for i, kf in enumerate(hologram.wavenumbers):
        with warnings.catch_warnings():  # said once above, for the highest frequency
            warnings.simplefilter("ignore", AliasingWarning)
            img = migrate(hologram.at_frequency(i), z, medium=medium, **kw)
        data = img.data if img.has_z_axis else img.data[..., None, :, :]
        if not hologram.monostatic and combine != "incoherent":
            data = data * _incident_phasor(hologram.source, kf, med, img,
                                           None if kw.get("frame") == "ground"
                                           else hologram.pose)
        data = w[i] * data
        if combine == "none":
            parts.append(data)
        elif combine == "coherent":
            acc = data if acc is None else acc + data
        else:
            acc = np.abs(data) ** 2 if acc is None else acc + np.abs(data) ** 2
    assert img is not None
    if combine == "none":
        out = np.stack(parts, axis=-4)
    else:
        out = np.sqrt(acc) if combine == "incoherent" else acc
    if not img.has_z_axis:
        out = out[..., 0, :, :]
    return Image(out, img.x, img.y, img.z, hologram.frequencies.copy(),
                 f"{img.method}:{combine}", has_z_axis=img.has_z_axis)


def _incident_phasor(source: Any, k: float, medium: Medium, img: Image,
                     pose: Any = None) -> np.ndarray:
    """``conj(E0)/|E0|`` on every image plane (nz, ny, nx); E0 = the transfer at normal
    incidence without a source. ``pose``: the image is in that aperture's own frame
    (planes parallel to it at distances z); the incident field is taken at the
    pixels' world positions."""
    # No source: a plane wave at normal incidence (phase 0 at z = 0).
    src = source if source is not None else PlaneWave()
    if pose is not None and not pose.is_identity:
        X, Y = np.meshgrid(img.x, img.y)
        pts = (pose.to_world(X, Y)[None] + img.z[:, None, None, None] * pose.normal)
        e0 = src.field(k, medium, pts.reshape(-1, 3)).reshape(pts.shape[:-1])
    elif isinstance(src, PlaneWave) and src.alpha == 0.0 and src.beta == 0.0:
        # At normal incidence the wave is the same across every plane (its lateral
        # factor is exactly 1): one pixel per plane, broadcast (read-only).
        one = incident_phasors([src], k, medium, img.x[:1], img.y[:1], img.z)[0]
        return np.broadcast_to(one, (img.z.size, img.y.size, img.x.size))
    else:
        return incident_phasors([src], k, medium, img.x, img.y, img.z)[0]
    mag = np.abs(e0)
    return np.divide(e0.conj(), mag, out=np.zeros_like(e0), where=mag > 0)


def _too_big_to_cache(hologram: Hologram, zs: np.ndarray, pad: Any, work: np.dtype) -> bool:
    """True when the planes' transfer functions would not fit in the transfer cache."""
    from ..physics.propagation import _CACHE

    lam = hologram.wavelength / (2 if hologram.monostatic else 1)
    shape = padded_shape(hologram.data.shape[-2:], pad, pitch=hologram.pitch, wavelength=lam,
                         z_max=float(zs.max()))
    return zs.size * shape[0] * shape[1] * np.dtype(work).itemsize > _CACHE.max_bytes // 2


def _data_snr(hologram: Hologram, medium: Medium | None, zs: np.ndarray) -> float:
    """The hologram's SNR where it can be estimated (only lossy ground needs it)."""
    if medium is None or all(complex(e).imag == 0 for e in medium.eps):
        return DEFAULT_SNR_DB
    z_min = min(float(zs.min()), medium.z_interfaces[0])
    est = estimate_snr(hologram, z_min)
    return DEFAULT_SNR_DB if est is None else est


def _multiply_planes(H: np.ndarray, Ucs: list[np.ndarray], prod: np.ndarray) -> None:
    """``prod[..., i, :, :] = H * Ucs[i]`` for every plane, on all cores when large.

    NumPy's multiply is single-threaded but releases the GIL, so a thread per core
    takes a share of the planes; on a volume this is most of the work besides FFTs.
    Below ``_THREADED_MULTIPLY`` products (one 512 x 512 plane: 0.10 ms in one thread,
    0.23 ms shared among two) the threads' hand-offs cost more than they share.
    """
    rows = H.shape[-2]
    if _threads.POOL_SIZE < 2 or len(Ucs) * H.size < _THREADED_MULTIPLY:
        for i, Uc in enumerate(Ucs):   # small: threads cost more than they share
            np.multiply(H, Uc, out=prod[..., i, :, :])
        return
    # Tasks: (plane, row block); a single plane is split in row blocks across cores.
    blocks = max(1, -(-_threads.POOL_SIZE // len(Ucs))) if rows >= 64 else 1
    edges = np.linspace(0, rows, blocks + 1).astype(int)
    tasks = [(i, slice(edges[b], edges[b + 1])) for i in range(len(Ucs)) for b in range(blocks)]

    def work(task: tuple[int, slice]) -> None:
        i, r = task
        np.multiply(H[..., r, :], Ucs[i][r, :], out=prod[..., i, r, :])

    if len(tasks) < 2 or _threads.POOL_SIZE < 2:
        for t in tasks:
            work(t)
        return
    list(pool().map(work, tasks))


def _zero_pad_spectrum(S: np.ndarray, u: int) -> np.ndarray:
    """Embed an FFT-ordered spectrum in a u-times larger grid (exact interpolation).

    The Nyquist bin of an even size is split in half between +/- frequencies so
    that a real band-limited signal stays real.
    """
    My, Mx = S.shape[-2:]
    out = np.zeros((*S.shape[:-2], u * My, u * Mx), dtype=S.dtype)
    hy, hx = (My + 1) // 2, (Mx + 1) // 2
    ys = [(slice(0, hy), slice(0, hy)), (slice(My - My // 2, My), slice(u * My - My // 2, None))]
    xs = [(slice(0, hx), slice(0, hx)), (slice(Mx - Mx // 2, Mx), slice(u * Mx - Mx // 2, None))]
    for sy_src, sy_dst in ys:
        for sx_src, sx_dst in xs:
            out[..., sy_dst, sx_dst] = S[..., sy_src, sx_src]
    if My % 2 == 0:  # split the Nyquist row
        out[..., My // 2, :] = out[..., u * My - My // 2, :] = 0.5 * out[..., u * My - My // 2, :]
    if Mx % 2 == 0:
        out[..., :, Mx // 2] = out[..., :, u * Mx - Mx // 2] = 0.5 * out[..., :, u * Mx - Mx // 2]
    return out


def available_memory() -> int:
    """Bytes of memory available to this process now (psutil where installed, else
    the free physical pages)."""
    try:
        import psutil
    except ImportError:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    return int(psutil.virtual_memory().available)


def check_fits(hologram: Hologram, planes: int, upsample: Any, dtype: Any, *,
               factor: float) -> None:
    """Refuse, before any work, an image volume that will not fit in memory.

    Parameters
    ----------
    hologram : Hologram
        The data (its leading axes and grid give the volume's shape).
    planes : int
        Planes per leading index (frequencies included for ``combine="none"``).
    upsample : int
        Output pixels per pitch.
    dtype : numpy dtype or None
        Working precision (None: complex64 for complex64 data, else complex128).
    factor : float
        Peak memory of the computation in units of the output volume.

    Raises
    ------
    MemoryError
        ``factor`` x the volume exceeds :func:`available_memory`; the message gives
        the volume's size and the ways out. Below 64 MiB it is not asked.
    """
    work = np.dtype(dtype) if dtype is not None else np.dtype(
        np.complex64 if hologram.data.dtype == np.complex64 else np.complex128)
    u = int(upsample) if isinstance(upsample, int | np.integer) and upsample >= 1 else 1
    ny, nx = hologram.data.shape[-2:]
    lead = hologram.data.shape[:-3] if hologram.is_wideband else hologram.data.shape[:-2]
    oy, ox = u * (ny - 1) + 1, u * (nx - 1) + 1
    size = math.prod(lead) * planes * oy * ox * work.itemsize
    if factor * size < _CHECK_ABOVE:
        return   # asking the system (~0.1-0.3 ms) would cost a small plane 5-10%
    avail = available_memory()
    if factor * size > avail:
        gib = 2.0**30
        cheaper = "" if work == np.complex64 else ", dtype=numpy.complex64 (half the size)"
        raise MemoryError(
            f"the image volume ({planes} planes x {oy} x {ox} pixels"
            f"{' x ' + str(int(np.prod(lead))) if lead else ''}, {work.name}) takes "
            f"{size / gib:.2f} GiB and about {factor * size / gib:.2f} GiB while it is "
            f"computed, more than the {avail / gib:.2f} GiB of memory available: image "
            f"fewer planes at a time{cheaper}, or store a survey frame by frame "
            "(holoradar batch writes a survey store)")
