"""How to migrate, as one validated value shared by every part that images.

:class:`MigrationSettings` holds every option of :func:`holoradar.migrate` that is
not the data, the planes or the ground; it is checked once, when made, with errors
that name the argument. ``migrate``, :func:`holoradar.migration_operator`, the
survey batch and the viewer build one and pass it on, so the checks live here only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from ..._validate import as_axis, as_real, uniform_step

__all__ = ["ALGORITHMS", "ILLUMINATIONS", "PRESETS", "MigrationSettings", "check_choice",
           "check_upsample", "preset_options"]

#: ``algorithm=`` values: ``"auto"`` or a backend's name.
ALGORITHMS = ("auto", "frequency", "kspace", "columns", "stolt", "fresnel", "ground-direct",
              "ground-nufft", "offset")

#: ``illumination=`` values: what the forward model multiplies a reflectivity by.
ILLUMINATIONS = ("none", "phase", "field")

#: The one table of defaults: what each purpose sets over :class:`MigrationSettings`'
#: own field defaults (which are :func:`holoradar.migrate`'s).
#:
#: * ``"imaging"``: the image :func:`holoradar.migrate` makes (loss compensated,
#:   frequencies equalised, a receiver array's incident phase divided out); the
#:   adjoint of :func:`holoradar.migration_operator` with this preset is ``migrate``.
#: * ``"forward"``: the physics a hologram holds (the source's incident field, no loss
#:   compensation, unit frequency weights): :func:`holoradar.migration_operator`'s
#:   default, the forward model of ``simulate``'s planar targets.
#: * ``"inversion"``: the forward model with each voxel a point scatterer's Born
#:   amplitude, no progress bar per application (:func:`holoradar.invert` adds, in the
#:   aperture's frame, the smooth band limit and a grid padded 3x or more: an accurate
#:   model for a solver).
PRESETS: dict[str, dict[str, Any]] = {
    "imaging": {},
    "forward": {"compensate_loss": False, "equalize": False, "illumination": "field"},
    "inversion": {"compensate_loss": False, "equalize": False, "illumination": "field",
                  "scatterer": "point", "progress": False},
}


def check_choice(value: Any, name: str, choices: tuple[str, ...]) -> str:
    """``value`` if it is one of ``choices``, else a ``ValueError`` naming ``name``.

    Examples
    --------
    >>> check_choice("full", "fov", ("aperture", "full"))
    'full'
    """
    if not isinstance(value, str) or value not in choices:
        listed = ", ".join(repr(c) for c in choices[:-1]) + f" or {choices[-1]!r}"
        raise ValueError(f"{name} must be {listed}, got {value!r}")
    return value


def check_upsample(value: Any, name: str = "upsample", top: int | None = None) -> int:
    """An integer number of output pixels per element pitch (>= 1, at most ``top``).

    Examples
    --------
    >>> check_upsample(4)
    4
    """
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1 \
            or (top is not None and value > top):
        bound = f"from 1 to {top}" if top is not None else ">= 1"
        raise ValueError(f"{name} must be an integer {bound}, got {value!r}")
    return int(value)


def _check_pad(pad: Any) -> bool | float:
    if isinstance(pad, bool | np.bool_):
        return bool(pad)
    try:
        factor = float(pad)
    except (TypeError, ValueError):
        factor = math.nan
    if not math.isfinite(factor) or factor < 1:
        raise ValueError(f"pad must be True, False or a factor >= 1, got {pad!r}")
    return factor


def _check_dtype(dtype: Any) -> np.dtype | None:
    if dtype is None:
        return None
    try:
        dt = np.dtype(dtype)
    except TypeError:
        dt = None
    if dt not in (np.complex64, np.complex128):
        raise ValueError(f"dtype must be numpy.complex64 or numpy.complex128, got {dtype!r}")
    return dt


def _check_equalize(equalize: Any) -> bool | tuple[float, ...]:
    if isinstance(equalize, bool | np.bool_):
        return bool(equalize)
    try:
        w = np.array(equalize, dtype=float)
    except (TypeError, ValueError):
        w = np.full(0, np.nan)
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)):
        raise ValueError(f"equalize must be True, False or finite weights (one per "
                         f"frequency), got {equalize!r}")
    return tuple(float(v) for v in w)


def _check_bool(value: Any, name: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"{name} must be True or False, got {value!r}")
    return bool(value)


@dataclass(frozen=True, eq=False)
class MigrationSettings:
    """The options of a migration (every field as in :func:`holoradar.migrate`).

    Parameters
    ----------
    method : {"angular", "fresnel"}
        Exact angular spectrum or the paraxial Fresnel kernel.
    pad : bool or float
        Zero padding of the FFT grid (True: the guard that keeps the periodic FFT
        from wrapping the image; a float: that factor).
    upsample : int
        Output pixels per element pitch.
    compensate_loss : bool
        Undo the back-propagation's absorption in lossy layers (a real gain on each
        plane wave; the forward model carries the same gain, so that the pair stays
        exactly adjoint).
    snr_db : float, optional
        The data's SNR that limits that gain, dB (None: estimated from the data).
    fov : {"aperture", "full"}
        The aperture's footprint, or the whole padded grid.
    dtype : numpy dtype, optional
        ``complex64`` or ``complex128`` (None: that of the data).
    combine : {"coherent", "incoherent", "none"}
        How several frequencies' images join.
    equalize : bool or tuple of float
        Frequency weights: True (unit RMS per frequency), False (1), or one weight
        per frequency.
    algorithm : str
        ``"auto"`` or a backend's name (:data:`ALGORITHMS`).
    frame : {"aperture", "ground"}
        Planes parallel to the aperture, or horizontal world planes.
    x, y : ndarray, optional
        ``frame="ground"``: the world grid of the image, metres (uniform).
    progress : bool, optional
        A progress bar (None: only for large outputs).
    band_limit : {"sharp", "smooth"}
        How the plane-by-plane angular spectrum drops the components that would wrap
        around its periodic grid: ``"sharp"`` (default, beyond half the grid) or
        ``"smooth"`` (a raised cosine from the aperture's extent to where an alias
        could reach it: an accurate forward model, for inversion, with ``pad`` 3 or
        more; :class:`~holoradar.AngularSpectrum`).
    scatterer : {"plane", "point"}
        The unit of the reflectivity the operator maps: ``"plane"`` (default) the
        reflection coefficient of a reflecting plane (Kirchhoff: the reflected field
        on the plane is ``r E0``; ``migrate``'s image); ``"point"`` the Born scattering
        amplitude of each voxel (a point target's ``amplitude``: the field it sends
        the elements is ``r E0 G``, ``G`` the Green's function of the layers), so that
        equal small objects give equal values wherever they lie.
    illumination : {"none", "phase", "field"}, optional
        What the forward model multiplies each voxel's reflectivity by before it
        propagates (and the adjoint by its conjugate): ``"field"`` the source's
        incident field ``E0``, ``"phase"`` its unit phasor ``E0/|E0|``, ``"none"``
        nothing. None (``migrate``'s default): ``"phase"`` for a receiver array's
        coherent or separate frequencies, else ``"none"``. A scanned transceiver's
        illumination is in its round-trip transfer: always ``"none"``.

    Examples
    --------
    >>> s = MigrationSettings(upsample=4)
    >>> s.upsample, s.replace(fov="full").fov
    (4, 'full')
    >>> MigrationSettings(fov="wide")
    Traceback (most recent call last):
    ...
    ValueError: fov must be 'aperture' or 'full', got 'wide'
    """

    method: str = "angular"
    pad: bool | float = True
    upsample: int = 1
    compensate_loss: bool = True
    snr_db: float | None = None
    fov: str = "aperture"
    dtype: Any = None
    combine: str = "coherent"
    equalize: bool | tuple[float, ...] = True
    algorithm: str = "auto"
    frame: str = "aperture"
    x: Any = None
    y: Any = None
    progress: bool | None = None
    illumination: str | None = None
    scatterer: str = "plane"
    band_limit: str = "sharp"

    def __post_init__(self) -> None:
        put = object.__setattr__
        put(self, "algorithm", check_choice(self.algorithm, "algorithm", ALGORITHMS))
        put(self, "frame", check_choice(self.frame, "frame", ("aperture", "ground")))
        if self.frame == "aperture" and (self.x is not None or self.y is not None):
            raise ValueError("x and y set the world grid of frame='ground'; frame='aperture' "
                             "images on the aperture's own grid (use upsample)")
        put(self, "method", check_choice(self.method, "method", ("angular", "fresnel")))
        put(self, "fov", check_choice(self.fov, "fov", ("aperture", "full")))
        put(self, "upsample", check_upsample(self.upsample))
        put(self, "pad", _check_pad(self.pad))
        put(self, "dtype", _check_dtype(self.dtype))
        put(self, "combine", check_choice(self.combine, "combine",
                                          ("coherent", "incoherent", "none")))
        put(self, "equalize", _check_equalize(self.equalize))
        put(self, "compensate_loss", _check_bool(self.compensate_loss, "compensate_loss"))
        if self.snr_db is not None:
            put(self, "snr_db", as_real(self.snr_db, "snr_db"))
        if self.progress is not None:
            put(self, "progress", _check_bool(self.progress, "progress"))
        if self.illumination is not None:
            check_choice(self.illumination, "illumination", ILLUMINATIONS)
        check_choice(self.scatterer, "scatterer", ("plane", "point"))
        check_choice(self.band_limit, "band_limit", ("sharp", "smooth"))
        if self.frame == "ground":
            self._check_ground()

    def _check_ground(self) -> None:
        if self.method != "angular":
            raise ValueError("frame='ground' uses the exact angular spectrum: method must be "
                             f"'angular', got {self.method!r}")
        if self.fov != "aperture":
            raise ValueError("frame='ground' images the aperture's footprint or the x, y "
                             f"grids given: fov must be 'aperture', got {self.fov!r}")
        if self.upsample != 1 and self.x is not None and self.y is not None:
            raise ValueError("upsample sets the step of the default ground grid; with both x "
                             "and y given it would be ignored: leave it at 1")
        for name in ("x", "y"):
            value = getattr(self, name)
            if value is not None:
                axis = as_axis(value, name)
                uniform_step(axis, name)
                axis.setflags(write=False)
                object.__setattr__(self, name, axis)

    def replace(self, **changes: Any) -> MigrationSettings:
        """A copy with ``changes`` (validated again)."""
        return replace(self, **changes)

    @classmethod
    def preset(cls, name: str, **options: Any) -> MigrationSettings:
        """The settings of a named purpose (:data:`PRESETS`), ``options`` over them.

        Examples
        --------
        >>> MigrationSettings.preset("forward").illumination
        'field'
        >>> MigrationSettings.preset("imaging").compensate_loss   # migrate's
        True
        """
        return cls.of(**{**preset_options(name), **options})

    @classmethod
    def of(cls, settings: MigrationSettings | None = None, **options: Any) -> MigrationSettings:
        """``settings`` with ``options`` replacing its fields (or new settings from them).

        A ``ValueError`` names an option that is not a migration setting.

        Examples
        --------
        >>> MigrationSettings.of(upsample=2).upsample
        2
        """
        names = {f.name for f in fields(cls)}
        bad = sorted(set(options) - names)
        if bad:
            raise ValueError(f"unknown migration option(s) {', '.join(bad)}; the options are "
                             f"{', '.join(sorted(names))}")
        if settings is None:
            return cls(**options)
        if not isinstance(settings, MigrationSettings):
            raise ValueError("settings must be a holoradar.MigrationSettings, got "
                             f"{type(settings).__name__}")
        return settings.replace(**options) if options else settings


def preset_options(name: str) -> dict[str, Any]:
    """The options a named purpose sets (:data:`PRESETS`), a copy.

    Examples
    --------
    >>> sorted(preset_options("forward"))
    ['compensate_loss', 'equalize', 'illumination']
    """
    return dict(PRESETS[check_choice(name, "preset", tuple(PRESETS))])
