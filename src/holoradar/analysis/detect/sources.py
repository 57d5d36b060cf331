"""The objects in an image or a hologram as ``holoradar detect`` and the report find them.

:func:`from_image` searches an image: fitted to the hologram it was imaged from, on
one of its planes, or (a plane) as it is; :func:`from_hologram` images a hologram
first. :func:`fit_hologram` is the fit with the hologram, its refusals worded for a
person and naming the argument (or the frame) that gave the hologram; the survey's
frames (:mod:`holoradar.survey.detect`) and the report use it too. Arguments are
values (ranges in metres, Hologram objects): reading files and parsing the command
line's text is the caller's.

The messages speak the command line's words (``--hologram``, ``--z RANGE``), as it
shows them; the refusals of an argument are :class:`~.errors.DetectionInputError`,
which name it.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

from .errors import DetectionInputError, HologramFitError

__all__ = ["HOLOGRAM_OR_PLANE", "detect_quietly", "fit", "fit_hologram", "from_array",
           "from_hologram", "from_image", "level", "options_of", "refuse_outside"]

HOLOGRAM_OR_PLANE = ("give --hologram (the fit on every plane) or --z (one plane, from the "
                     "image alone), not both")
"""The refusal of an image's hologram together with one plane of it."""

_IMAGE_ADVICE = ("give the hologram FILE was imaged from (with the ground flags it was imaged "
                 "through), or --z RANGE to search one plane from the image alone")
_HOLOGRAM_ADVICE = ("image it with holoradar image and search one plane of the image with "
                    "--z")


def options_of(img: Any) -> dict[str, Any]:
    """``migrate``'s settings an image shows: its method and working precision."""
    opts: dict[str, Any] = {}
    if getattr(img, "method", "angular") in ("angular", "fresnel"):
        opts["method"] = img.method
    if np.asarray(img.data).dtype == np.complex64:
        opts["dtype"] = np.complex64
    return opts


def detect_quietly(img: Any, **kwargs: Any) -> Any:
    """:func:`~holoradar.detect`, without the aliasing warnings of its own migrations (the
    user's data were warned of when imaged)."""
    from ..._validate import AliasingWarning
    from .api import detect

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AliasingWarning)
        return detect(img, **kwargs)


def fit(img: Any, holo: Any, medium: Any, opts: Mapping[str, Any], args: Mapping[str, Any],
        name: str, advice: str) -> Any:
    """:func:`detect_quietly` with the hologram's fit.

    Parameters
    ----------
    img : Image
        The image searched.
    holo : Hologram
        The hologram it was imaged from, as the fit takes it (:func:`level`).
    medium : Medium or None
        The ground as seen from the hologram's plane.
    opts : mapping
        ``migrate``'s other settings the image was made with (``migrate_options``).
    args : mapping
        ``detect``'s other keywords (``false_alarm``, ``kinds``, ``eps_interval``).
    name : str
        What gave the hologram (an option, a frame), starting each refusal.
    advice : str
        What to do instead, ending each refusal.

    Returns
    -------
    pandas.DataFrame
        ``detect``'s table.

    Raises
    ------
    ValueError
        The hologram does not fit the image: ``"NAME: the image is not this hologram's
        migration (...): ADVICE"`` and the like.
    """
    try:
        return detect_quietly(img, hologram=holo, medium=medium, migrate_options=dict(opts),
                              **args)
    except HologramFitError as exc:
        raise ValueError(_refusal(exc, holo, name, advice)) from None


def _refusal(exc: HologramFitError, holo: Any, name: str, advice: str) -> str:
    """``detect``'s refusal of a hologram, in the terms of the one who gave it."""
    if exc.reason == "mismatch":
        differ = "" if exc.difference is None else \
            f" (they differ by {exc.difference:.2g} of the peak)"
        return f"{name}: the image is not this hologram's migration{differ}: {advice}"
    if exc.reason == "grid":
        return (f"{name}: the image's grid is not this hologram's elements at a whole "
                f"upsampling: {advice}")
    if exc.reason == "frames":
        return (f"{name}: the hologram holds several frames (data shape "
                f"{np.shape(holo.data)}); {advice}")
    if exc.reason == "tilted":
        return (f"{name}: the hologram's array is tilted (its pose), which the point fit "
                f"does not support yet; {advice}")
    return f"{name}: {exc}"


def level(holo: Any, medium: Any) -> tuple[Any, Any]:
    """A level hologram at a height as the fit takes it: on its own plane (identity pose)
    with the ground seen from that plane, as ``migrate`` images it (ranges from the
    array); its position across is left to the caller."""
    from dataclasses import replace

    from ...data.pose import IDENTITY

    return replace(holo, pose=IDENTITY), from_array(medium, float(holo.pose.center[2]))


def from_array(medium: Any, height: float) -> Any:
    """The ground seen from an array at world height ``height`` (m; ``migrate``'s shift):
    interfaces at ranges from the array, so that depths below the surface come out."""
    if medium is None or height == 0.0:
        return medium
    return medium.seen_from(height)


def fit_hologram(img: Any, holo: Any, medium: Any, opts: Mapping[str, Any],
                 args: Mapping[str, Any], name: str, advice: str) -> Any:
    """:func:`fit` with a hologram as it was recorded: a level one is fitted on its own
    plane (:func:`level`), the image being on its axes with ranges from the array."""
    if holo.pose.is_level:
        holo, medium = level(holo, medium)
    return fit(img, holo, medium, opts, args, name, advice)


def refuse_outside(value: float, planes: Any, what: str) -> None:
    """Refuse a plane (m) outside ``planes`` (the nearest would be taken silently), with
    the likely unit slip and the metres meant (as ``--z``).

    Raises
    ------
    DetectionInputError
        Named ``"z"``.
    """
    from ...data.range_checks import RangeError, refuse_outside_planes

    try:
        refuse_outside_planes(value, planes, "--z", what)
    except RangeError as exc:
        raise DetectionInputError(str(exc), "z") from None


def from_image(img: Any, medium: Any, args: Mapping[str, Any], *, hologram: Any = None,
               plane: float | None = None, name: str = "the image") -> Any:
    """The objects in an image: fitted to its hologram, on one of its planes, or as it is
    (a plane).

    Parameters
    ----------
    img : Image
        The image (a plane or a volume).
    medium : Medium or None
        The ground it was imaged through (None: free space).
    args : mapping
        ``detect``'s other keywords (``false_alarm``, ``kinds``, ``eps_interval``).
    hologram : Hologram, optional
        The hologram it was imaged from: each object is its point response fitted to it.
    plane : float, optional
        The one plane to search (range, m), from the image alone.
    name : str
        The image's name in messages (its file's name).

    Returns
    -------
    pandas.DataFrame
        ``detect``'s table.

    Raises
    ------
    DetectionInputError
        Both ``hologram`` and ``plane``, or a plane outside the image's (``"z"``); a
        volume at one frequency with neither (``"source"``).
    ValueError
        A hologram that did not make the image (:func:`fit`, as ``--hologram``).
    """
    if hologram is not None:
        if plane is not None:
            raise DetectionInputError(HOLOGRAM_OR_PLANE, "z")
        return fit_hologram(img, hologram, medium, options_of(img), args, "--hologram",
                            _IMAGE_ADVICE)
    planes = np.asarray(img.z)
    if plane is not None:
        refuse_outside(plane, planes, f"{name}'s planes")
        img = img.plane(plane)
    elif bool(img.has_z_axis) and planes.size > 1 and np.atleast_1d(img.frequency).size < 2:
        # One frequency does not focus in range: the library refuses such a volume too.
        raise DetectionInputError(
            f"{name} is a volume of {planes.size} planes at one frequency (its range focus "
            "is tens of centimetres long): give --hologram HOLO.nc (the hologram it was "
            "imaged from: objects found in 3-D) or --z RANGE (one plane, from the image "
            "alone)", "source")
    # A wideband volume is searched as the library searches it: plane by plane, each
    # object's range from its range profile.
    return detect_quietly(img, medium=medium, **args)


def from_hologram(holo: Any, zs: Any, medium: Any, args: Mapping[str, Any], *,
                  progress: bool = False, name: str = "the hologram") -> Any:
    """The objects in a hologram: imaged on the planes ``zs`` (ranges from the array, m;
    four pixels per pitch), then fitted to it.

    Parameters
    ----------
    holo : Hologram
        One frame.
    zs : float or array_like or None
        The planes to image it on.
    medium : Medium or None
        The ground (None: free space).
    args : mapping
        ``detect``'s other keywords (``false_alarm``, ``kinds``, ``eps_interval``).
    progress : bool
        ``migrate``'s progress bar.
    name : str
        The hologram's name in messages (its file's name).

    Returns
    -------
    pandas.DataFrame
        ``detect``'s table.

    Raises
    ------
    DetectionInputError
        No planes (``"z"``).
    ValueError
        The fit refuses the hologram (:func:`fit`, as ``FILE``).
    """
    from ...imaging.migrate import migrate

    if zs is None:
        raise DetectionInputError(f"{name} is a hologram: give --z, the planes to image it on "
                                  "(range(s) from the array in metres, e.g. 0.3:0.5:0.01)", "z")
    img = migrate(holo, zs, medium=medium, upsample=4, progress=progress)
    # The image is on the array's own axes, its planes ranges from the array.
    return fit_hologram(img, holo, medium, {}, args, "FILE", _HOLOGRAM_ADVICE)
