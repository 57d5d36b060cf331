"""``report``: the inspection report of images, holograms or surveys as one HTML file."""

from __future__ import annotations

import os
import time
from collections.abc import Mapping, Sequence
from typing import Any

from .sources import NAMES, Request, as_list, build_section

__all__ = ["report"]

_KINDS = ("point", "line", "area")


def _sources(sources: Any) -> list[Any]:
    if isinstance(sources, str | os.PathLike) or hasattr(sources, "data"):
        return [sources]
    if isinstance(sources, Sequence) and not isinstance(sources, bytes) and len(sources):
        return list(sources)
    raise ValueError("sources must be a path (image, hologram or survey store), an Image or "
                     f"a Hologram, or a non-empty sequence of them; got {sources!r}")


def _interval(eps_interval: Any, name: str) -> tuple[tuple[float, float] | None, str]:
    from ..analysis.detect.table import as_eps_interval

    if eps_interval is None:
        return None, ""
    how = "the autofocus's interval" if hasattr(eps_interval, "eps_focus") else \
        f"given as {name}"
    try:
        return as_eps_interval(eps_interval), how
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: expected an interval (lo, hi) of real permittivities >= 1 "
                         f"with lo <= hi, e.g. (2.2, 2.8), or an AutofocusResult; got "
                         f"{eps_interval!r} ({exc})") from None


def _false_alarm(value: Any) -> float:
    try:
        fa = float(value)
    except (TypeError, ValueError):
        fa = float("nan")
    if not 0 < fa <= 0.1:
        raise ValueError("false_alarm must be the expected number of false objects per "
                         f"resolution cell, a number in (0, 0.1] such as 1e-3; got {value!r}")
    return fa


def _kinds(kinds: Any) -> tuple[str, ...]:
    if isinstance(kinds, str) or not isinstance(kinds, Sequence) or not kinds \
            or any(k not in _KINDS for k in kinds):
        raise ValueError(f"kinds must be a non-empty sequence drawn from {_KINDS}, got "
                         f"{kinds!r}")
    return tuple(kinds)


def report(sources: Any, path: str | os.PathLike[str], *, medium: Any = None,
           eps_interval: Any = None, false_alarm: float = 1e-3,
           kinds: Sequence[str] = _KINDS, z: Any = None, hologram: Any = None,
           detections: Any = None, title: str = "Inspection report", force: bool = False,
           layout: Any = None, check: bool = True,
           names: Mapping[str, str] | None = None, min_cover: Any = None,
           meta: Any = None, progress: bool | None = None) -> dict[str, Any]:
    """Write the inspection report of images, holograms or surveys: one HTML file.

    Each source gets a section: its objects (found by :func:`holoradar.detect`, or
    the tables given) as a table numbered as ``holoradar detect`` numbers them;
    plan views at the objects' depths (a survey: its mosaic in survey coordinates)
    and, for a volume, vertical sections, the objects outlined and numbered; the
    ground (permittivities, how it was found, the permittivity interval); the
    detection's threshold and settings; the device and settings; the processing
    history stored with the source; and the warnings raised while it was read,
    imaged and searched (issued to the caller too). The file needs nothing else:
    the pictures are embedded PNGs, there is no script and no link outside it.

    Parameters
    ----------
    sources : path, Image or Hologram, or a sequence of them
        Image files (``holoradar image``, ``holoradar mosaic``), hologram files,
        survey stores (``.zarr`` from ``holoradar batch``), or objects.
    path : path
        The report, ending in ``.html``; never one of the sources.
    medium : Medium, optional
        The ground. Default: an image file's own (the ground its history says it was
        imaged through), a store's settings, else free space (ranges, no depths).
        Refused for a store.
    eps_interval : (float, float) or AutofocusResult, optional
        Interval of the ground's real permittivity: widens the depths' 95 % intervals
        (needs a ground).
    false_alarm : float
        Expected number of false objects per resolution cell on noise, in (0, 0.1].
    kinds : sequence of str
        Which kinds to report: ``"point"``, ``"line"``, ``"area"``.
    z : float or array_like, optional
        A hologram source's planes (ranges from the array, metres; imaged at four
        pixels per pitch); for an image volume or a store, the one plane to search
        from the image alone.
    hologram : path or Hologram, or a sequence (one per source, None where none)
        The hologram an image volume was imaged from: each object is its point
        response fitted to it (as ``holoradar detect --hologram``).
    detections : pandas.DataFrame, or a sequence (one per source)
        Tables ``hr.detect`` already gave (a survey's: ``holoradar detect``'s): used as
        they are, nothing is detected again.
    title : str
        The report's heading.
    force : bool
        Replace ``path`` if it exists.
    layout : Layout, dict or str, optional
        Where the hologram is in a user's files (:func:`holoradar.load`).
    check : bool
        :func:`holoradar.load`'s plausibility checks (default True).
    names : mapping, optional
        How messages name the arguments (the command line gives its options' names).
    min_cover : float or str, optional
        The specified minimum concrete cover: metres, or text with its unit
        (``"35mm"``). Each bar is checked against it (below, uncertain, ok) in the
        objects' table, the layers' table and the rebar plan.
    meta : mapping or path, optional
        The inspection's fields (``site``, ``element``, ``operator``, ``scan``, ...),
        or a TOML or JSON file of them: shown at the report's top.
    progress : bool, optional
        Progress bars over the detection's long work (an inversion's steps, a survey's
        frames); default: once the work has lasted a second; False: never.

    Returns
    -------
    dict
        ``path`` (the report), ``bytes`` (its size), ``sources`` (per source:
        ``name``, ``kind``, ``n_objects``, ``warnings``), ``n_objects`` (all sources)
        and ``seconds``.

    Raises
    ------
    ValueError
        A bad argument (named, with the form expected), a source that cannot be read
        or searched, an output that exists (without ``force``) or is a source, or
        whose folder is missing. Nothing is written then; the file is written
        atomically (readers see the old file or the new one).

    Examples
    --------
    >>> import pathlib, tempfile, numpy as np, holoradar as hr
    >>> sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    >>> scene = hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget((0.02, 0.0, 0.42))])
    >>> h = hr.simulate(scene, hr.Aperture.grid(16, 0.0125), 9.9e9,
    ...                 include_surface=False, snr_db=30, seed=1)
    >>> img = hr.migrate(h, 0.42, medium=sand, upsample=4)
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "report.html"
    >>> summary = hr.report(img, out, medium=sand, eps_interval=(2.3, 2.7))
    >>> summary["n_objects"], out.read_text().startswith("<!DOCTYPE html>")
    (1, True)
    """
    from .._version import __version__
    from ..io.output import check_output, write_atomic
    from .figures import pictures
    from .html import page
    from .inspection import as_length, as_meta

    t0 = time.perf_counter()
    n = {**NAMES, **dict(names or {})}
    cover = as_length(min_cover, n.get("min_cover", "min_cover"))
    fields = as_meta(meta, n.get("meta", "meta"))
    srcs = _sources(sources)
    files = [s for s in srcs if isinstance(s, str | os.PathLike)]
    holos = as_list(hologram, len(srcs), n["hologram"])
    tables = as_list(detections, len(srcs), n["detections"])
    target = check_output(path, suffixes=[".html"], inputs=[*files, *[
        h for h in holos if isinstance(h, str | os.PathLike)]], overwrite=force,
        name=n["path"], replace_word="--force" if n["path"].startswith("--") else "force=True")
    interval, how = _interval(eps_interval, n["eps_interval"])
    if medium is not None and not hasattr(medium, "z_interfaces"):
        raise ValueError(f"{n['medium']} must be a holoradar.Medium or None, got "
                         f"{type(medium).__name__}")
    req = Request(medium=medium, eps_interval=interval,
                  interval_how=how, false_alarm=_false_alarm(false_alarm),
                  kinds=_kinds(kinds), z=z, names=n, layout=layout, check=bool(check),
                  progress=progress)
    sections = [build_section(s, i, req, hologram=h, detections=d)
                for i, (s, h, d) in enumerate(zip(srcs, holos, tables, strict=True))]
    for s in sections:
        s.min_cover = cover
    pics = [pictures(s) for s in sections]
    created = time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime())
    text = page(str(title), sections, pics, created, __version__, fields)
    payload = text.encode("utf-8")
    write_atomic(target, payload)
    return {"path": str(target), "bytes": len(payload),
            "sources": [{"name": s.name, "kind": s.kind, "n_objects": len(s.table),
                         "warnings": s.warnings} for s in sections],
            "n_objects": sum(len(s.table) for s in sections),
            "seconds": time.perf_counter() - t0}
