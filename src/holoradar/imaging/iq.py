"""Which I/Q sign a device delivers, told from the data themselves.

holoradar reads a complex sample as ``I + iQ`` of a field under ``exp(-i*omega*t)``.
A device whose Q has the other sign (the engineering convention ``exp(+j*omega*t)``,
``I - jQ``, or a mixer on the other sideband) delivers the complex conjugate. The
two are told apart by physics: with the right sign the scene focuses in front of
the aperture; the conjugate is the field of the mirror scene behind it, so
back-propagated to the same ranges it spreads out instead. The image with the
sharper focus (larger peak-to-mean intensity) wins. What is the same at every position
of a scanned transceiver (its coupling, the flat surface's echo) and a receiver
array's direct wave are taken out first: they are not compact, and either convention
may put them in front.

:func:`iq_convention` always answers; :func:`check_iq_sign` answers only when the
difference is decisive (otherwise ``None``), cheaply (a few planes and
frequencies), and :func:`warn_if_conjugated` turns a decisive ``"I-iQ"`` into an
:class:`IQSignWarning` that names the fix. :func:`holoradar.load` calls it on a
device's file whose layout does not declare ``iq_sign``, and ``holoradar image``
at the ranges and through the ground it images.
"""

from __future__ import annotations

import warnings
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from ..data.hologram import Hologram
from ..data.wideband import conjugate
from .migrate import migrate

__all__ = ["IQSignCheck", "IQSignWarning", "check_iq_sign", "iq_convention",
           "warn_if_conjugated"]

DECISIVE_RATIO = 3.0
"""How much sharper (peak-to-mean intensity) one side must focus than the other for
:func:`check_iq_sign` to decide. Data in which nothing focuses are speckle on both
sides: the peak-to-mean intensity of N independent cells is ``ln N + 0.58`` with a
spread of 1.28 (the Gumbel law of the largest of N exponential intensities), so one
side reaches 3 times the other's ``ln N + 0.58`` with probability about
``exp(-2 ln N - 1.2) = 0.3/N^2``: below 1e-3 from N = 18 cells on (at each of the
check's two stages: twice that for both). A focused point
is tens to hundreds of times sharper than its conjugate (tests/test_iq_sign.py)."""

PAD = 2.0
"""Zero padding of the check's images: one grid for every frequency, so that their
intensities add."""

MAX_PLANES = 8
"""Planes the check images on each side (spread over the ranges given)."""

MAX_FREQUENCIES = 4
"""Frequencies the check images (spread over the band); each is imaged alone and the
intensities add, so a device's phase response across the band does not matter."""

MAX_ELEMENTS = 128
"""Elements along each axis the check looks at (the central ones): a larger array's
centre still focuses what lies in front of it, and the check stays a few FFTs of at
most 256 x 256 whatever the array."""

MAX_FRAMES = 4
"""Frames (views, repeats) the check looks at, spread over those the data hold."""

MAX_BAND = 64
"""Frequencies of the second stage, the band's coherent image (spread over the band)."""


class IQSignWarning(UserWarning):
    """The data focus behind the array: recorded as ``I - iQ`` (their complex conjugate)."""


@dataclass(frozen=True)
class IQSignCheck:
    """What :func:`check_iq_sign` found.

    Attributes
    ----------
    sign : {"I+iQ", "I-iQ"} or None
        The convention the data follow, or None when the two sides focus alike
        (nothing compact in the ranges looked at, or mostly noise).
    ratio : float
        Peak-to-mean intensity of the data as recorded over that of their
        conjugate (the mirror scene behind the aperture): >> 1 for ``I + iQ``,
        << 1 for ``I - iQ``; of the stage that decided (the frequencies alone, or
        the band's coherent image), or of the first when neither did.
    z : tuple of float
        The ranges imaged, metres.
    reason : str
        Why there is no verdict (empty with one): what the check saw, and what to try.
    """

    sign: Literal["I+iQ", "I-iQ"] | None
    ratio: float
    z: tuple[float, ...]
    reason: str = ""


def _sharpness(data: np.ndarray) -> float:
    """Peak over mean intensity (double precision: a single-precision image's mean may
    underflow the floor; all-zero data are 0, not NaN)."""
    a = np.abs(np.asarray(data)).astype(np.float64) ** 2
    mean = float(a.mean()) if a.size else 0.0
    return float(a.max()) / mean if mean > 0 else 0.0


def _spread(values: np.ndarray, n: int) -> np.ndarray:
    """At most ``n`` of ``values``, evenly spread and including both ends."""
    if values.size <= n:
        return values
    return values[np.unique(np.round(np.linspace(0, values.size - 1, n)).astype(int))]


def _reduced(hologram: Hologram) -> Hologram:
    """One frequency's data cut to what the check needs: at most :data:`MAX_FRAMES` frames
    and the central :data:`MAX_ELEMENTS` x :data:`MAX_ELEMENTS` elements."""
    ny, nx = hologram.data.shape[-2:]
    data = hologram.data.reshape((-1, ny, nx))
    data = data[_spread(np.arange(data.shape[0]), MAX_FRAMES)]
    y0, x0 = max(0, (ny - MAX_ELEMENTS) // 2), max(0, (nx - MAX_ELEMENTS) // 2)
    y1, x1 = min(ny, y0 + MAX_ELEMENTS), min(nx, x0 + MAX_ELEMENTS)
    data = data[:, y0:y1, x0:x1]
    # a scale changes no sharpness, and unit data cannot overflow an intensity
    peak = float(np.max(np.abs(data))) if data.size else 0.0
    return hologram.replace(data=data / peak if peak > 0 else data, x=hologram.x[x0:x1],
                            y=hologram.y[y0:y1])


def _reduced_band(hologram: Hologram) -> Hologram:
    """The band's data cut as :func:`_reduced` cuts one frequency's: at most
    :data:`MAX_BAND` frequencies (spread over the band), :data:`MAX_FRAMES` frames and
    the central :data:`MAX_ELEMENTS` x :data:`MAX_ELEMENTS` elements."""
    nf, ny, nx = hologram.data.shape[-3:]
    keep = _spread(np.arange(nf), MAX_BAND)
    data = hologram.data.reshape((-1, nf, ny, nx))
    data = data[_spread(np.arange(data.shape[0]), MAX_FRAMES)][:, keep]
    y0, x0 = max(0, (ny - MAX_ELEMENTS) // 2), max(0, (nx - MAX_ELEMENTS) // 2)
    y1, x1 = min(ny, y0 + MAX_ELEMENTS), min(nx, x0 + MAX_ELEMENTS)
    data = data[..., y0:y1, x0:x1]
    peak = float(np.max(np.abs(data))) if data.size else 0.0
    return hologram.replace(data=data / peak if peak > 0 else data, x=hologram.x[x0:x1],
                            y=hologram.y[y0:y1], frequency=hologram.frequencies[keep])


def _band_sides(hologram: Hologram, zs: np.ndarray, opts: dict[str, Any]) -> list[float]:
    """The sharpness of the band's coherent image, as recorded and conjugated (the
    frequencies weighted alike, ``equalize=True``): a point focuses in range too, so
    data each of whose frequencies is too faint to decide alone may decide together
    (the coherent sum's gain, ``10 log10(nf)`` dB over one frequency)."""
    band = _without_scan_mean(_reduced_band(hologram))
    out = []
    for flip in (False, True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            img = migrate(conjugate(band) if flip else band, zs, upsample=1, pad=PAD,
                          progress=False, combine="coherent", dtype=np.complex64, **opts)
        a = np.abs(np.asarray(img.data)) ** 2
        out.append(_sharpness(np.sqrt(a.reshape((-1, *a.shape[-3:])).sum(axis=0))))
    return out


def _without_direct_wave(hologram: Hologram) -> Hologram:
    """The data less their part along the radiator's direct wave and its conjugate.

    A horn just behind the array sends its own wave into the elements, often the
    strongest part of the data: it focuses behind the array, on the horn, so its
    conjugate focuses in front and blurs the comparison. Removing both the wave
    and its conjugate (least squares, free complex amplitudes) treats the two
    conventions alike. Without a known point radiator the data stay as they are.
    """
    from .glare._common import Radiator, direct_wave, recorded_polarization

    src = hologram.source
    if hologram.monostatic or not isinstance(src, Radiator):  # a plane wave: no focus
        return hologram
    shape = hologram.data.shape
    D = direct_wave(src, hologram.k, hologram.points, recorded_polarization(hologram, src))
    basis = np.stack([D, np.conj(D)], axis=1)
    d = hologram.data.reshape(-1, D.size).T
    coef, *_ = np.linalg.lstsq(basis, d, rcond=None)
    return hologram.with_data((d - basis @ coef).T.reshape(shape))


def _without_scan_mean(hologram: Hologram) -> Hologram:
    """A scanned transceiver's data less their mean over the scan positions (per
    frequency and frame).

    What is the same at every position (the antenna's coupling and ringing, the flat
    surface's echo under a level scan) is often the strongest part of a scan, near
    the antenna; it is flat, not compact, and it may sit where either convention
    focuses it (a delay behind the antenna as well as in front), so it must not
    decide. Its mean over the positions is all of it; a compact reflector's is a
    small part of its own energy. Receiver arrays are left as they are (their
    radiator's direct wave is :func:`_without_direct_wave`'s)."""
    if not hologram.monostatic:
        return hologram
    d = hologram.data
    return hologram.with_data(d - d.mean(axis=(-2, -1), keepdims=True))


def default_ranges(hologram: Hologram) -> np.ndarray:
    """Ranges where a scene in front of an aperture of width A focuses: A/4 to 2A, metres.

    Nearer than A/4 the radiator's own wave may focus (a horn just behind the
    array: its conjugate focuses as far in front); beyond 2A an aperture's focus
    is too long in range to stand out.
    """
    a = max(hologram.aperture_size)
    return np.geomspace(a / 4, 2 * a, MAX_PLANES)


def check_iq_sign(hologram: Hologram, z: float | Sequence[float] | np.ndarray | None = None,
                  **migrate_options: Any) -> IQSignCheck:
    """Whether the data focus in front of the aperture (``I + iQ``) or behind it (``I - iQ``).

    Back-propagates the data and their conjugate (the field of the mirror scene
    behind the aperture) to the same ranges and compares the sharpness of their
    foci; decides only when one is :data:`DECISIVE_RATIO` times sharper. First each
    of at most :data:`MAX_FREQUENCIES` frequencies alone (intensities added: a
    device's phase response across the band does not matter); where that does not
    decide, the band's coherent image (at most :data:`MAX_BAND` frequencies), whose
    range focus and coherent gain decide on fainter or more extended scenes, as
    :func:`iq_convention` does. Cheap: at most :data:`MAX_PLANES` planes,
    :data:`MAX_FRAMES` frames and the central :data:`MAX_ELEMENTS` x
    :data:`MAX_ELEMENTS` elements, one pixel per element.

    Parameters
    ----------
    hologram : Hologram
        One or several frequencies (each imaged alone, intensities added).
    z : float or sequence of float, optional
        Ranges where the scene is, metres (the planes of an image to be made);
        default :func:`default_ranges` in free space (a line scan: no default, no
        verdict without them).
    **migrate_options
        Passed to :func:`holoradar.migrate` (``medium=``, ``frame=``).

    Returns
    -------
    IQSignCheck
        ``sign`` None when undecided, or when the hologram cannot be imaged so.

    Examples
    --------
    >>> import holoradar as hr
    >>> ap = hr.Aperture.grid(32, 0.0125)
    >>> h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))]), ap, 9.9e9)
    >>> check_iq_sign(h).sign, check_iq_sign(conjugate(h)).sign
    ('I+iQ', 'I-iQ')
    """
    import inspect

    unknown = sorted(set(migrate_options) - set(inspect.signature(migrate).parameters))
    if unknown:
        raise TypeError(f"check_iq_sign: {', '.join(map(repr, unknown))} is not an option of "
                        "holoradar.migrate (e.g. medium=, frame=)")
    if z is not None:
        try:
            z_given = np.atleast_1d(np.asarray(z, float))
        except (TypeError, ValueError):
            raise ValueError(f"z must be ranges in metres (a number or a sequence), got "
                             f"{z!r}") from None
        if not (z_given.size and np.all(np.isfinite(z_given)) and np.all(z_given > 0)):
            raise ValueError(f"z must be finite ranges in front of the aperture (> 0 m), got "
                             f"{z!r}")
    if z is None and hologram.is_line:
        return IQSignCheck(None, float("nan"), (), "a line scan: its length says nothing of "
                           "the depths its scene lies at; give z (the ranges imaged)")
    try:
        zs = default_ranges(hologram) if z is None else z_given
        zs = _spread(np.unique(zs), MAX_PLANES)
        # Only what shapes the focus; the caller's other imaging options (upsampling,
        # windows, fields of view) do not change which side it lies on.
        opts = {k: v for k, v in migrate_options.items() if k in ("medium", "frame", "method")}
        # The whole padded grid: the glare's focus (the horn's mirror image) often lies
        # beside the array, and it focuses in front as any scatterer does. A level
        # ground frame images the footprint only.
        # A transmitter beside the receiver (tx_offset) has its own two-leg kernel, on the
        # footprint only.
        opts["fov"] = "aperture" if opts.get("frame") == "ground" or \
            hologram.tx_offset is not None else "full"
        views = [_without_scan_mean(_without_direct_wave(_reduced(
            hologram.at_frequency(int(i))))) for i in _spread(np.arange(hologram.nf),
                                                                MAX_FREQUENCIES)]
        sides = []
        for flip in (False, True):
            total: Any = 0.0
            for h in views:
                with warnings.catch_warnings():
                    # the aliasing of the pitch and the like: the user's own imaging says so
                    warnings.simplefilter("ignore")
                    img = migrate(conjugate(h) if flip else h, zs, upsample=1, pad=PAD,
                                  progress=False, dtype=np.complex64, **opts)
                total = total + np.abs(img.data) ** 2
            sides.append(_sharpness(np.sqrt(total)))
    except ValueError as exc:  # a grid or geometry the imaging refuses: no verdict
        return IQSignCheck(None, float("nan"), (), f"the hologram cannot be imaged so: {exc}")
    planes = tuple(float(v) for v in zs)
    if not (sides[0] > 0 and sides[1] > 0):  # data all zero: nothing to compare
        return IQSignCheck(None, float("nan"), planes, "the data are zero")
    ratio = sides[0] / sides[1]
    sign = _verdict(ratio)
    band_ratio = None
    if sign is None and hologram.nf > 1:
        # Second stage: the band's coherent image (range focus; the coherent gain).
        try:
            band = _band_sides(hologram, zs, opts)
        except ValueError:
            band = [0.0, 0.0]
        if band[0] > 0 and band[1] > 0:
            band_ratio = band[0] / band[1]
            sign = _verdict(band_ratio)
            if sign is not None:
                return IQSignCheck(sign, float(band_ratio), planes)
    coherent = "" if band_ratio is None else (
        f", and the band's {min(hologram.nf, MAX_BAND)} frequencies imaged together "
        f"{band_ratio:.2f} (a device whose phase response across the band is not "
        "calibrated blurs that image on both sides)")
    why = "" if sign is not None else (
        f"the data and their conjugate focus alike at {min(planes):.3g} to {max(planes):.3g} m "
        f"(sharpness ratio {ratio:.2f} with each of {min(hologram.nf, MAX_FREQUENCIES)} "
        f"frequencies judged alone{coherent}; a verdict needs {DECISIVE_RATIO:g} or "
        f"1/{DECISIVE_RATIO:g}): nothing compact there, or mostly noise; give z where a "
        "compact reflector (or the radiating antenna) lies")
    return IQSignCheck(sign, float(ratio), planes, why)


def _verdict(ratio: float) -> Literal["I+iQ", "I-iQ"] | None:
    if ratio >= DECISIVE_RATIO:
        return "I+iQ"
    if ratio <= 1 / DECISIVE_RATIO:
        return "I-iQ"
    return None


def iq_convention(hologram: Hologram, z: float | Sequence[float] | np.ndarray,
                  **migrate_options: Any) -> Literal["I+iQ", "I-iQ"]:
    """``"I+iQ"`` if the data focus as recorded, ``"I-iQ"`` if their conjugate does.

    Parameters
    ----------
    hologram : Hologram
        Data holding at least one compact reflector (a metal plate or sphere at a
        known range is the classic check).
    z : float or sequence of float
        Ranges where it lies, metres.
    **migrate_options
        Passed to :func:`holoradar.migrate` (``medium=...``).

    Returns
    -------
    str
        ``"I-iQ"`` means: take :func:`holoradar.data.wideband.conjugate` of the
        data before imaging.

    Examples
    --------
    >>> import holoradar as hr
    >>> ap = hr.Aperture.grid(24, 0.0062, monostatic=True)
    >>> h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.2))]), ap,
    ...                 [9e9, 10e9, 11e9])
    >>> iq_convention(h, [0.18, 0.2, 0.22]), iq_convention(conjugate(h), [0.18, 0.2, 0.22])
    ('I+iQ', 'I-iQ')
    """
    from .migrate import IlluminationWarning

    with warnings.catch_warnings():
        # Both images assume the same illumination where the source is not given: the
        # comparison does not depend on it, and nothing was asked about it.
        warnings.simplefilter("ignore", IlluminationWarning)
        h = _without_scan_mean(hologram)
        as_is = _sharpness(migrate(h, z, **migrate_options).data)
        flipped = _sharpness(migrate(conjugate(h), z, **migrate_options).data)
    return "I+iQ" if as_is >= flipped else "I-iQ"


def conjugated_message(result: IQSignCheck, what: str = "hologram",
                       fix: str | None = None) -> str:
    """The warning's text for a decisive ``"I-iQ"`` of :func:`check_iq_sign`."""
    zs = result.z
    where = (f"{zs[0] * 100:.0f} cm" if len(zs) == 1
             else f"{zs[0] * 100:.0f}-{zs[-1] * 100:.0f} cm")
    fix = fix or ("declare iq_sign=I-iQ in the layout when loading, or image "
                  "hr.conjugate(hologram)")
    return (f"{what}: the data focus behind the array, not in front (their complex "
            f"conjugate focuses {1 / result.ratio:.1f} times sharper at {where}): they look "
            "recorded as I - iQ, the engineering convention exp(+j omega t), and holoradar, "
            "which reads I + iQ under exp(-i omega t), images them as a blur. Fix: " + fix)


# The data arrays already warned about (id -> weak reference, result): a hologram that
# load() warned about is not warned about again by the imaging that follows.
_WARNED: dict[int, tuple[Any, IQSignCheck]] = {}


def _remember(data: np.ndarray, result: IQSignCheck) -> None:
    key = id(data)
    try:
        ref = weakref.ref(data, lambda _: _WARNED.pop(key, None))
    except TypeError:  # an object without weak references: nothing remembered
        return
    _WARNED[key] = (ref, result)


def _warned(data: np.ndarray) -> IQSignCheck | None:
    entry = _WARNED.get(id(data))
    return entry[1] if entry is not None and entry[0]() is data else None


def warn_if_conjugated(hologram: Hologram, z: float | Sequence[float] | np.ndarray | None = None,
                       *, what: str = "hologram", fix: str | None = None, stacklevel: int = 2,
                       **migrate_options: Any) -> IQSignCheck:
    """:func:`check_iq_sign`, warning (:class:`IQSignWarning`) when it decides ``"I-iQ"``.

    Parameters
    ----------
    hologram, z, **migrate_options
        As for :func:`check_iq_sign`.
    what : str
        How the message names the data (a file name).
    fix : str, optional
        The remedy the message names (default: the layout's ``iq_sign=I-iQ`` or
        :func:`holoradar.conjugate`).
    stacklevel : int
        Of the warning, counted from the caller of this function.

    Returns
    -------
    IQSignCheck

    Examples
    --------
    >>> import warnings, holoradar as hr
    >>> ap = hr.Aperture.grid(32, 0.0125)
    >>> h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))]), ap, 9.9e9)
    >>> with warnings.catch_warnings(record=True) as said:
    ...     warnings.simplefilter("always")
    ...     _ = warn_if_conjugated(conjugate(h))
    >>> said[0].category.__name__
    'IQSignWarning'
    """
    said = _warned(hologram.data)
    if said is not None:  # warned about already (by load): once is enough
        return said
    result = check_iq_sign(hologram, z, **migrate_options)
    if result.sign == "I-iQ":
        warnings.warn(conjugated_message(result, what, fix), IQSignWarning,
                      stacklevel=stacklevel + 1)
        _remember(hologram.data, result)
    return result
