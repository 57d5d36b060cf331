"""A source of the report (an image, a hologram or a survey store; a file or an object)
turned into a :class:`~.model.Section`: read, its ground found, its objects detected,
the warnings raised on the way kept.

The detection is ``holoradar detect``'s: the same readings of a file
(:mod:`holoradar.io.inputs`), the same ground from an image's history, the same fit
with the hologram (:mod:`holoradar.analysis.detect.sources`) and the same survey
gathering (:mod:`holoradar.survey.detect`), so that the report's table is the one
``holoradar detect`` writes for the same file and options.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .metadata import device_rows, file_attributes, history_of, store_rows
from .model import Ground, Section

__all__ = ["NAMES", "Request", "as_list", "build_section"]

NAMES = {"sources": "sources", "path": "path", "z": "z", "hologram": "hologram",
         "medium": "medium", "eps_interval": "eps_interval", "detections": "detections"}
"""How messages name the arguments (the command line passes its options' names)."""


@dataclass
class Request:
    """What to find in every source, and how the arguments are named in messages.

    Attributes
    ----------
    medium : Medium or None
        The ground given (None: an image's own history, a store's settings, or free
        space).
    eps_interval : (float, float) or None
        The ground's real permittivity interval (checked).
    interval_how : str
        Where the interval came from, in words.
    false_alarm : float
        Expected false objects per resolution cell (checked).
    kinds : tuple of str
        The kinds of object to report.
    z : float, ndarray or None
        A hologram's planes (ranges, m), or the one plane of a volume or store to
        search from the image alone.
    names : mapping
        The arguments' names for messages (:data:`NAMES`).
    layout : Layout, dict or str, optional
        Where the hologram is in a user's file (:func:`holoradar.load`).
    check : bool
        The plausibility checks of :func:`holoradar.load`.
    progress : bool or None
        The detection's progress bars (None: after a second of work).
    """

    medium: Any = None
    eps_interval: tuple[float, float] | None = None
    interval_how: str = ""
    false_alarm: float = 1e-3
    kinds: tuple[str, ...] = ("point", "line", "area")
    z: Any = None
    names: Mapping[str, str] = field(default_factory=lambda: dict(NAMES))
    layout: Any = None
    check: bool = True
    progress: bool | None = None


def _name(source: Any, index: int) -> str:
    if isinstance(source, str | os.PathLike):
        return Path(source).name or str(source)
    return f"{type(source).__name__.lower()} {index + 1}"


def _warning_text(w: warnings.WarningMessage) -> str:
    return f"{w.category.__name__}: {' '.join(str(w.message).split())}"


def build_section(source: Any, index: int, req: Request, *, hologram: Any = None,
                  detections: Any = None) -> Section:
    """Read one source, find its objects and gather what the report shows of it.

    Parameters
    ----------
    source : path or Image or Hologram
        An image file, a hologram file or a survey store (``.zarr``), or an object.
    index : int
        Its place among the sources (names an object source).
    req : Request
        The detection's settings.
    hologram : path or Hologram, optional
        The hologram an image source was imaged from (each object fitted to it).
    detections : pandas.DataFrame, optional
        The source's objects as ``hr.detect`` gave them: used as they are.

    Returns
    -------
    Section
        Its ``warnings`` hold those raised meanwhile (each once); they are also
        issued again to the caller.

    Raises
    ------
    ValueError
        A source that cannot be read or searched, with the argument to change.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        section = _build(source, index, req, hologram, detections)
    seen: list[str] = []
    for w in caught:
        text = _warning_text(w)
        if text not in seen:
            seen.append(text)
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    # What the steps that made the source warned of (kept in its history).
    for step in section.history:
        for text in step.get("warnings") or []:
            said = f"{text} (when {step.get('step', 'a step')} made it)"
            if said not in seen:
                seen.append(said)
    section.warnings = seen
    return section


def _build(source: Any, index: int, req: Request, hologram: Any, detections: Any) -> Section:
    from ..data.hologram import Hologram, Image

    n = req.names
    name = _name(source, index)
    if isinstance(source, str | os.PathLike):
        path = Path(source)
        if not path.exists():
            raise ValueError(f"{n['sources']}: {str(path)!r} does not exist")
        if path.is_dir():
            return _store_section(path, name, req, hologram, detections)
        from ..io import load

        obj = load(path, layout=req.layout, check=req.check)
        attrs = file_attributes(path)
    elif isinstance(source, Hologram | Image):
        path, obj, attrs = None, source, {}
    else:
        raise ValueError(f"{n['sources']}: each source must be a file path, a holoradar Image "
                         f"or a Hologram, got {type(source).__name__}")
    req = _interval_of(req, detections)
    ground = _ground(req, obj, path)
    args = {"false_alarm": req.false_alarm, "kinds": req.kinds,
            "eps_interval": req.eps_interval, "progress": req.progress}
    extra: list[tuple[str, str]] = []
    if isinstance(obj, Image):
        if hologram is not None:
            hologram, hattrs = _read_hologram(hologram, req)
            extra = [(f"hologram: {k}", v) for k, v in device_rows(hologram, hattrs)]
        draw, table = _image_objects(obj, name, ground.medium, args, req, hologram, detections)
        kind = "image"
    else:
        if hologram is not None:
            raise ValueError(f"{n['hologram']}: {name} is itself a hologram: give none")
        draw, table = _hologram_objects(obj, name, ground.medium, args, req, detections)
        kind = "hologram"
    # An object keeps its history (an Image read by hr.load, or made here); a file's is
    # in its attributes.
    history = history_of(attrs) or [dict(s) for s in getattr(obj, "history", ()) or ()
                                    if isinstance(s, dict)]
    return Section(name=name, kind=kind, image=draw, table=table, ground=ground,
                   detection=_detection(table, req), device=device_rows(obj, attrs) + extra,
                   history=history)


def _interval_of(req: Request, detections: Any) -> Request:
    """The permittivity interval a given table was found with (its ``eps_interval``
    attribute), where none is given to the report."""
    from dataclasses import replace

    got = (getattr(detections, "attrs", None) or {}).get("eps_interval")
    if req.eps_interval is not None or not got:
        return req
    return replace(req, eps_interval=(float(got[0]), float(got[1])),
                   interval_how="the one the objects' table was found with")


def _read_hologram(hologram: Any, req: Request) -> tuple[Any, dict[str, Any]]:
    """The hologram an image was imaged from, and its file's attributes."""
    from ..data.hologram import Hologram

    if isinstance(hologram, Hologram):
        return hologram, {}
    from ..io.inputs import read_hologram

    try:
        holo = read_hologram(Path(hologram), req.layout, req.check)
    except ValueError as exc:
        raise ValueError(f"{req.names['hologram']}: {exc}") from None
    return holo, file_attributes(hologram)


def _ground(req: Request, obj: Any, path: Path | None) -> Ground:
    from ..data.hologram import Image

    n = req.names
    medium, how = req.medium, f"given as {n['medium']}"
    if medium is None and isinstance(obj, Image):
        from ..io.inputs import history_medium, medium_of_history

        # A file's history, or the one an image read from a file carries in memory.
        medium = (history_medium(path) if path is not None else
                  medium_of_history(getattr(obj, "history", None)))
        how = "the image's history: the ground it was imaged through"
    if medium is None:
        how = "none: free space (ranges from the array, no depths)"
    if req.eps_interval is not None and (medium is None or not medium.z_interfaces):
        raise ValueError(f"{n['eps_interval']} needs a ground with a surface: give "
                         f"{n['medium']}, or an image made through one")
    return Ground(medium, how, req.eps_interval, req.interval_how)


def _one_plane(z: Any, planes: np.ndarray, req: Request, name: str) -> float:
    n = req.names
    zs = np.atleast_1d(np.asarray(z, dtype=float))
    if zs.size != 1 or not np.isfinite(zs[0]):
        raise ValueError(f"{n['z']}: expected one range in metres (the plane of {name} to "
                         f"search), got {z!r}")
    v = float(zs[0])
    step = float(np.min(np.diff(planes))) if planes.size > 1 else 1e-9
    if not planes.min() - step / 2 <= v <= planes.max() + step / 2:
        raise ValueError(f"{n['z']}: {v:g} m is outside {name}'s planes ({planes.min():g} to "
                         f"{planes.max():g} m)")
    return v


def _image_objects(img: Any, name: str, medium: Any, args: dict[str, Any], req: Request,
                   hologram: Any, detections: Any) -> tuple[Any, Any]:
    from ..analysis.detect.sources import detect_quietly, fit_hologram, options_of

    n = req.names
    planes = np.atleast_1d(np.asarray(img.z, dtype=float))
    volume = bool(img.has_z_axis) and planes.size > 1
    if hologram is not None:
        if req.z is not None:
            raise ValueError(f"give {n['hologram']} (the fit on every plane) or {n['z']} (one "
                             "plane, from the image alone), not both")
        if detections is not None:
            return img, detections
        return img, fit_hologram(img, hologram, medium, options_of(img), args, n["hologram"],
                                 f"give the hologram {name} was imaged from, or {n['z']} to "
                                 "search one plane from the image alone")
    if req.z is not None:
        plane = _one_plane(req.z, planes, req, name)
        img = img.plane(plane) if img.has_z_axis else img
    elif volume and detections is None and np.atleast_1d(img.frequency).size < 2:
        # One frequency does not focus in range (the library refuses such a volume too);
        # a wideband volume is searched plane by plane, as hr.detect does.
        raise ValueError(f"{name} is a volume of {planes.size} planes at one frequency: give "
                         f"{n['hologram']} (the hologram it was imaged from: objects found in "
                         f"3-D) or {n['z']} (one plane, from the image alone)")
    if detections is not None:
        return img, detections
    return img, detect_quietly(img, medium=medium, **args)


def _hologram_objects(holo: Any, name: str, medium: Any, args: dict[str, Any], req: Request,
                      detections: Any) -> tuple[Any, Any]:
    from ..analysis.detect.sources import fit_hologram
    from ..imaging.migrate import migrate

    n = req.names
    if req.z is None:
        raise ValueError(f"{name} is a hologram: give {n['z']}, the planes to image it on "
                         "(ranges from the array, metres)")
    zs = np.atleast_1d(np.asarray(req.z, dtype=float))
    if zs.ndim != 1 or not np.all(np.isfinite(zs)) or np.any(zs < 0):
        raise ValueError(f"{n['z']}: expected ranges in metres (>= 0), got {req.z!r}")
    if req.check:
        # holoradar detect's checks of ranges against the array (a unit slip is refused)
        from ..data.range_checks import RangeError, check_planes

        try:
            check_planes(holo, zs, ",".join(f"{v:g}" for v in zs), medium, {}, True,
                         name=n["z"])
        except RangeError as exc:
            raise ValueError(f"{exc.name or n['z']}: {exc}") from None
    img = migrate(holo, zs, medium=medium, upsample=4)
    if detections is not None:
        return img, detections
    return img, fit_hologram(img, holo, medium, {}, args, name,
                             f"image it first and report the image with {n['z']} (one plane)")


def _store_section(path: Path, name: str, req: Request, hologram: Any,
                   detections: Any) -> Section:
    from ..analysis.detect.errors import DetectionInputError
    from ..survey.detect import from_store
    from ..survey.store import is_survey, stored_settings

    n = req.names
    if not is_survey(path):
        raise ValueError(f"{n['sources']}: {str(path)!r} is a folder but not a survey store "
                         "(holoradar batch writes one)")
    if req.medium is not None:
        raise ValueError(f"{n['medium']}: a survey store keeps the ground its frames were "
                         "imaged through: give none")
    if hologram is not None:
        raise ValueError(f"{n['hologram']}: a survey store's frames are fitted with their own "
                         "holograms: give none")
    medium = stored_settings(path)[0].medium
    req = _interval_of(req, detections)
    if req.eps_interval is not None and (medium is None or not medium.z_interfaces):
        raise ValueError(f"{n['eps_interval']} needs a ground: the store {name} was imaged in "
                         "free space")
    ground = Ground(medium, "the survey store's settings: the ground its frames were imaged "
                            "through", req.eps_interval, req.interval_how)
    info: dict[str, Any] = {}
    if detections is not None:
        table = detections
    else:
        try:
            table, info, _ = from_store(path, _stored_plane(req), {
                "false_alarm": req.false_alarm, "kinds": req.kinds,
                "eps_interval": req.eps_interval, "progress": req.progress})
        except DetectionInputError as exc:
            raise ValueError(f"{n['z'] if exc.name == 'z' else n['sources']}: {exc}") from None
    detection = _detection(table, req)
    if info:
        detection.update({"frames": info.get("frames"), "model": info.get("model"),
                          "per_frame": info.get("per_frame")})
    return Section(name=name, kind="survey", image=None, table=table, ground=ground,
                   detection=detection, device=store_rows(path), history=_store_history(path),
                   store=str(path))


def _stored_plane(req: Request) -> float | None:
    """The one stored plane to search (m), or None: every frame fitted to its hologram."""
    if req.z is None:
        return None
    n = req.names
    zs = np.atleast_1d(np.asarray(req.z, dtype=float))
    if zs.size != 1:
        raise ValueError(f"{n['z']}: expected one range in metres (the stored plane to "
                         f"search), got {req.z!r}")
    plane = float(zs[0])
    if not math.isfinite(plane):
        # as the command line's --z text it would be ('nan', 'inf')
        text = repr(plane)
        raise ValueError(f"{n['z']}: expected a range in metres or start:stop:step, got "
                         f"{text!r}")
    return plane


def _store_history(path: Path) -> list[dict[str, Any]]:
    from ..survey.store import read_index, stored_settings

    idx = read_index(path)
    settings = stored_settings(path)[0].to_dict()
    return [{"step": "batch", "time": idx["attrs"].get("created"),
             "input": f"{int(idx['done'].sum())} frame(s)", "parameters": settings}]


def _detection(table: Any, req: Request) -> dict[str, Any]:
    attrs = dict(getattr(table, "attrs", {}) or {})
    cell = attrs.get("resolution_cell")
    return {"false_alarm": attrs.get("false_alarm", req.false_alarm),
            "kinds": list(req.kinds), "model": attrs.get("model"),
            "threshold": attrs.get("threshold"), "n_cells": attrs.get("n_cells"),
            "resolution_cell": None if cell is None else [
                float(c) if c is not None and math.isfinite(float(c)) else None for c in cell]}


def as_list(value: Any, count: int, name: str) -> list[Any]:
    """One value per source: ``None`` for all, one value for a single source, or a sequence
    of ``count`` (a DataFrame is one value)."""
    if value is None:
        return [None] * count
    if isinstance(value, Sequence) and not isinstance(value, str | bytes):
        if len(value) != count:
            raise ValueError(f"{name}: expected one per source ({count}), got {len(value)}")
        return list(value)
    if count != 1:
        raise ValueError(f"{name}: with {count} sources give a sequence of {count} (None for "
                         "a source without one)")
    return [value]
