"""A migration's plan: everything a backend needs, fixed before any work.

:func:`make_plan` checks the hologram, the planes and the ground against the
settings, and computes once what depends on the data: the frequencies' weights
(``equalize=True``: unit RMS per frequency) and the SNR that limits the loss
compensation. After that the map from data to image is linear, and the same plan
serves every hologram of the same geometry (a survey's frames, the residuals of a
fit, an iterative solver's vectors).
"""

from __future__ import annotations

import copy
import warnings
import weakref
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..._validate import check_nonnegative_ranges, outside_stacklevel, warn_if_aliased
from ...data.hologram import C0, Hologram
from ...data.noise import estimate_snr
from ...physics.medium import FREE_SPACE, Medium
from ...physics.propagation import DEFAULT_SNR_DB, padded_shape
from .settings import MigrationSettings

__all__ = ["IlluminationWarning", "MigrationPlan", "make_plan"]


class IlluminationWarning(UserWarning):
    """Frequencies were combined with an assumed incident field."""


@dataclass(frozen=True, eq=False)
class MigrationPlan:
    """A migration fixed for one geometry (see the module docstring).

    Attributes
    ----------
    geometry : Hologram
        The hologram the plan was made for, without its data (a zero-stride view of
        their shape and dtype): its grid, frequencies, source, pose and polarisation.
        A plan holds no data (an operator kept for a solver costs no memory for it).
    settings : MigrationSettings
    z : ndarray
        Ranges of the image planes, metres (``frame="ground"``: world ranges).
    scalar : bool
        ``z`` was one number: the image has no plane axis.
    medium : Medium
        The ground in the world frame (free space for None).
    local : Medium
        The ground as seen from the aperture's plane (a level aperture at a height:
        interfaces shifted by it).
    work : numpy.dtype
        Working precision.
    weights : ndarray
        One weight per frequency.
    compensates : bool
        The loss compensation applies (asked for, through a lossy ground); its SNR is
        :attr:`snr_db`.
    illumination : {"none", "phase", "field"}
        What each voxel is multiplied by before it propagates (a scanned
        transceiver: ``"none"``, its illumination is in the round trip).
    pad : bool or float
        The padding every frequency uses (``fov="full"`` on a band: one factor).
    nf : int
        Number of frequencies.
    wideband : bool
        The hologram has a frequency axis.
    grid : (int, int)
        ``(ny, nx)`` of the data.
    memo : dict
        What backends compute once per plan (grids, transfers' owners, phasors).
    data : weakref.ref
        The hologram whose data the SNR is estimated from, on first use.
    """

    geometry: Hologram
    settings: MigrationSettings
    z: np.ndarray
    scalar: bool
    medium: Medium
    local: Medium
    work: np.dtype
    weights: np.ndarray
    compensates: bool
    illumination: str
    pad: bool | float
    nf: int
    wideband: bool
    grid: tuple[int, int]
    data: Any = field(default=None, repr=False)
    memo: dict = field(default_factory=dict, repr=False)

    @property
    def snr_db(self) -> float | None:
        """The SNR limiting the loss compensation, dB (given, or estimated from the
        data once, on first use); None: the plain adjoint."""
        if not self.compensates:
            return None
        if "snr_db" not in self.memo:
            s = self.settings
            # The planes' ranges and the ground's as seen from the aperture's plane
            # (world ranges in the ground frame).
            ground = self.local if s.frame == "aperture" else self.medium
            source = self.data() if self.data is not None else None
            if s.snr_db is None and source is None:
                raise ValueError("the plan's hologram is gone: its SNR (for the loss "
                                 "compensation) can no longer be estimated; give snr_db")
            self.memo["snr_db"] = s.snr_db if s.snr_db is not None else data_snr(
                source, None if ground.is_free_space else ground, self.z)
        return self.memo["snr_db"]

    @property
    def wavenumbers(self) -> np.ndarray:
        """Wavenumbers in air, rad/m (nf,)."""
        ks = self.memo.get("wavenumbers")
        if ks is None:
            ks = self.memo["wavenumbers"] = self.geometry.wavenumbers
            ks.setflags(write=False)
        return ks

    @property
    def data_shape(self) -> tuple[int, ...]:
        """One frame's data: ``(nf, ny, nx)`` for a band, ``(ny, nx)`` for one frequency."""
        return ((self.nf,) if self.wideband else ()) + self.grid

    @property
    def separate(self) -> bool:
        """Each frequency keeps its own image (``combine`` "none" or "incoherent")."""
        return self.settings.combine != "coherent" and self.wideband

    @property
    def monostatic(self) -> bool:
        return self.geometry.monostatic


def make_plan(hologram: Any, z: Any, medium: Any, settings: MigrationSettings) -> MigrationPlan:
    """Check a migration's inputs and fix what depends on the data.

    Parameters
    ----------
    hologram : Hologram
    z : float or sequence of float
        Ranges of the image planes, metres (>= 0).
    medium : Medium or None
    settings : MigrationSettings

    Returns
    -------
    MigrationPlan

    Raises
    ------
    ValueError
        A bad argument, named, with the expected form.
    """
    if not isinstance(hologram, Hologram):
        raise ValueError(f"hologram must be a holoradar.Hologram, got {type(hologram).__name__}")
    if medium is not None and not isinstance(medium, Medium):
        raise ValueError(f"medium must be a holoradar.Medium or None, got {type(medium).__name__}")
    s = settings
    pose = hologram.pose
    if s.frame == "aperture" and medium is not None and not medium.is_free_space \
            and not pose.is_level:
        raise ValueError("a tilted aperture (hologram.pose.tilt > 0) sees the layers "
                         "obliquely: image through a medium with frame='ground'")
    zs = check_nonnegative_ranges(z, "z")
    if s.algorithm == "stolt" and not hologram.is_wideband:
        raise ValueError("algorithm='stolt' sums several frequencies: this hologram has "
                         "one; use 'auto'")
    if s.method == "fresnel" and np.any(zs <= 0):
        raise ValueError("z must be > 0 with method='fresnel' (its kernel is singular at 0)")
    world = medium if medium is not None else FREE_SPACE
    local = _local_medium(world, pose) if s.frame == "aperture" else world
    work = np.dtype(s.dtype) if s.dtype is not None else np.dtype(
        np.complex64 if hologram.data.dtype == np.complex64 else np.complex128)
    weights = _weights(hologram, s.equalize)
    illumination = _illumination(hologram, s)
    _warn(hologram, s, illumination)
    wide = hologram.is_wideband
    return MigrationPlan(without_data(hologram), s, zs, np.ndim(z) == 0, world, local, work,
                         weights, s.compensate_loss and not world.is_lossless, illumination,
                         _band_pad(hologram, zs, s), hologram.nf if wide else 1, wide,
                         tuple(hologram.data.shape[-2:]), weakref.ref(hologram))


def without_data(hologram: Hologram) -> Hologram:
    """The hologram's geometry: a copy whose ``data`` is a read-only zero-stride view of
    the data's shape and dtype (no memory)."""
    g = copy.copy(hologram)
    object.__setattr__(g, "data", np.broadcast_to(np.zeros((), hologram.data.dtype),
                                                  hologram.data.shape))
    return g


def warn(hologram: Hologram, s: MigrationSettings, illumination: str) -> None:
    """What a migration of ``hologram`` warns about (said again on every call)."""
    _warn(hologram, s, illumination)


def _local_medium(medium: Medium, pose: Any) -> Medium:
    """The layers seen from a level aperture's plane at a height ``pose.center[2]``."""
    height = float(pose.center[2])
    if height == 0.0 or medium.is_free_space or not pose.is_level:
        return medium
    if height >= medium.z_interfaces[0]:
        raise ValueError(f"hologram.pose puts the aperture at z = {height:.4g} m, "
                         f"at or below the ground surface ({medium.z_interfaces[0]} m)")
    return medium.seen_from(height)


_ONE = np.ones(1)
_ONE.setflags(write=False)


def _weights(hologram: Hologram, equalize: Any) -> np.ndarray:
    """The frequencies' weights: unit RMS each (True), 1 (False), or those given."""
    if not hologram.is_wideband:
        return _ONE
    nf = hologram.nf
    if isinstance(equalize, bool):
        if not equalize:
            return np.ones(nf)
        rms = np.sqrt(np.mean(np.abs(np.moveaxis(hologram.data, -3, 0).reshape(nf, -1)) ** 2,
                              axis=1))
        return np.divide(1.0, rms, out=np.zeros(nf), where=rms > 0)
    w = np.array(equalize, dtype=float)
    if w.shape != (nf,):
        raise ValueError(f"equalize must be True, False or {nf} finite weights (one per "
                         f"frequency), got {equalize!r}")
    return w


def data_snr(hologram: Hologram, medium: Medium | None, zs: np.ndarray) -> float:
    """The hologram's SNR where it can be estimated (only lossy ground needs it), dB.

    Estimated from the part of its spectrum evanescent over the air gap down to the
    nearest plane or the surface (:func:`holoradar.data.noise.estimate_snr`); where
    that cannot be done, 40 dB.
    """
    if medium is None or all(complex(e).imag == 0 for e in medium.eps):
        return DEFAULT_SNR_DB
    z_min = min(float(zs.min()), medium.z_interfaces[0])
    est = estimate_snr(hologram, z_min)
    return DEFAULT_SNR_DB if est is None else est


def _illumination(hologram: Hologram, s: MigrationSettings) -> str:
    if hologram.monostatic:
        return "none"
    if s.illumination is not None:
        return s.illumination
    return "phase" if hologram.is_wideband and s.combine != "incoherent" else "none"


def _warn(hologram: Hologram, s: MigrationSettings, illumination: str) -> None:
    if hologram.source is None and illumination == "field":
        warnings.warn("no hologram.source: a plane wave at normal incidence is assumed for "
                      "the incident field; give the source for the true one",
                      IlluminationWarning, stacklevel=outside_stacklevel())
    elif hologram.source is None and illumination == "phase" and hologram.is_wideband \
            and s.combine == "coherent":
        warnings.warn("combining frequencies without hologram.source: a plane wave at normal "
                      "incidence is assumed for each frequency's incident phase; give the "
                      "source for the true one", IlluminationWarning,
                      stacklevel=outside_stacklevel())
    # A transceiver's round trip doubles the transverse wavenumbers: lambda/4 sampling.
    top = float(hologram.frequency[-1]) if hologram.is_wideband else hologram.frequency
    warn_if_aliased(max(hologram.pitch), C0 / top, "hologram", round_trip=hologram.monostatic)


def _band_pad(hologram: Hologram, zs: np.ndarray, s: MigrationSettings) -> bool | float:
    """The padding of every frequency. The full field of view is the padded grid,
    whose size grows with the wavelength: one factor for the whole band (the largest
    any frequency needs) gives every frequency the same pixels to add."""
    if not (hologram.is_wideband and s.fov == "full" and s.pad is True
            and s.frame == "aperture"):
        return s.pad
    n = hologram.data.shape[-2:]
    need = [padded_shape(n, True, pitch=hologram.pitch, wavelength=C0 / f / (
        2 if hologram.monostatic else 1), z_max=float(zs.max())) for f in hologram.frequencies]
    return max(m / size for shape in need for m, size in zip(shape, n, strict=True))
