"""``holoradar detect``: the objects in an image, a hologram or a survey, as a table.

FILE is one of

* an image file (what ``holoradar image`` or ``holoradar mosaic`` writes): with
  ``--hologram`` (the hologram it was imaged from) the objects are read off the
  reflectivity inverted from it; without, a plane is searched as it is, a wideband
  volume plane by plane (as ``hr.detect`` does), and a one-frequency volume needs
  ``--z`` (one plane of it);
* a hologram file: imaged first on the planes ``--z`` (required) through the ground
  flags, four pixels per pitch, then searched with the hologram's fit;
* a survey store (``.zarr`` from ``holoradar batch``): each frame searched with its
  own hologram (the frame's file, read again) on all stored planes, or with ``--z``
  on one stored plane from the images alone; the objects are placed in survey
  coordinates from the frames' positions, and an object seen by several
  overlapping frames is reported once (by the frame it lies nearest the centre of).

The table (``hr.detect``'s columns; a store's also ``frame``) goes to the terminal
and, with ``-o``, to a CSV, JSON or GeoJSON file chosen by its suffix.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click
import numpy as np

from .common import (
    Reporter,
    check_planes,
    crs_option,
    depth_ranges,
    layout_option,
    medium_from_options,
    medium_options,
    output_options,
    read_hologram,
)

__all__ = ["COMMANDS"]

_KINDS = ("point", "line", "area")
_OPTIONS = {"z": "--z", "source": "FILE"}
"""The options that give the library's arguments (its refusals name the argument)."""


# ---------------------------------------------------------------- option parsing

def _eps_interval(text: str | None) -> tuple[float, float] | None:
    from ...analysis.detect.table import as_eps_interval

    if text is None:
        return None
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        pair = (float(parts[0]), float(parts[1]))
        return as_eps_interval(pair)
    except ValueError:
        raise click.BadParameter(f"expected LO,HI: two real permittivities >= 1 with LO <= HI, "
                                 f"e.g. 2.2,2.8; got {text!r}", param_hint="--eps-interval") \
            from None


def _false_alarm(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = math.nan
    if not 0 < v <= 0.1:
        raise click.BadParameter("expected the expected number of false objects per resolution "
                                 f"cell, a number in (0, 0.1] such as 1e-3; got {text!r}",
                                 param_hint="--false-alarm")
    return v


def _kinds(text: str) -> tuple[str, ...]:
    ks = tuple(k.strip() for k in text.split(",") if k.strip())
    if not ks or any(k not in _KINDS for k in ks):
        raise click.BadParameter(f"expected a comma-separated list of {', '.join(_KINDS)}; "
                                 f"got {text!r}", param_hint="--kinds")
    return ks


def _ground_given(spec: dict[str, Any]) -> bool:
    return any(spec.get(k) is not None for k in ("eps", "z_surface", "layers", "medium_file",
                                                  "tan_delta", "sigma"))


def _one_plane(text: str, what: str) -> float:
    """``--z`` as one range (m): ``what`` names the plane in the refusal of several."""
    zs = depth_ranges(text)
    if np.ndim(zs) != 0:
        raise click.BadParameter(f"expected one range in metres ({what}), got {text!r}",
                                 param_hint="--z")
    return float(zs)


@contextlib.contextmanager
def _named() -> Iterator[None]:
    """The library's refusal of an argument as an error of the option that gave it."""
    from ...analysis.detect.errors import DetectionInputError

    try:
        yield
    except DetectionInputError as exc:
        raise click.BadParameter(str(exc), param_hint=_OPTIONS[exc.name]) from None


# ---------------------------------------------------------------- the inputs

def _from_store(path: Path, z: str | None, spec: dict[str, Any], args: dict[str, Any],
                report: Reporter) -> tuple[Any, dict[str, Any], Any]:
    """A survey store: every frame searched, the objects in survey coordinates, once."""
    from ...survey.detect import from_store
    from ...survey.store import stored_settings

    if args["eps_interval"] is not None:
        m = stored_settings(path)[0].medium
        if m is None or not m.z_interfaces:
            raise click.BadParameter("needs a ground: the store was imaged in free space",
                                     param_hint="--eps-interval")
    if _ground_given(spec):
        raise click.BadParameter("a survey store keeps the ground its frames were imaged "
                                 "through: give no ground flag", param_hint="--eps/--z-surface")
    plane = None if z is None else _one_plane(z, "the stored plane to search")
    with _named():
        return from_store(path, plane, args, log=report.line)


def _from_file(path: Path, z: str | None, spec: dict[str, Any], args: dict[str, Any],
               hologram: Path | None, layout: str | None, check: bool,
               report: Reporter) -> tuple[Any, dict[str, Any], Any]:
    """An image or a hologram file: its ground (the flags', or an image's history) and its
    objects."""
    from ...data.hologram import Image
    from ...io import load
    from ...io.inputs import history_medium

    obj = load(path, layout=layout, check=check)
    medium = medium_from_options(spec, float(np.mean(np.atleast_1d(obj.frequency))))
    is_image = isinstance(obj, Image)
    if medium is None and is_image and not _ground_given(spec):
        medium = history_medium(path)
        if medium is not None:
            report.line(f"ground from {path.name}'s history: the ground it was imaged "
                        "through")
    if args["eps_interval"] is not None and (medium is None or not medium.z_interfaces):
        raise click.BadParameter("needs a ground: --eps and --z-surface (or an image made "
                                 "through one)", param_hint="--eps-interval")
    if is_image:
        df, info = _from_image(path, obj, z, hologram, medium, layout, check, args)
    else:
        if hologram is not None:
            raise click.BadParameter(f"{path.name} is itself a hologram: give no "
                                     "--hologram", param_hint="--hologram")
        df, info = _from_hologram(path, obj, z, medium, spec, check, args, report)
    info.update(df.attrs)
    return df, info, medium


def _from_image(path: Path, img: Any, z: str | None, hologram: Path | None, medium: Any,
                layout: str | None, check: bool,
                args: dict[str, Any]) -> tuple[Any, dict[str, Any]]:
    from ...analysis.detect.sources import HOLOGRAM_OR_PLANE, from_image

    info: dict[str, Any] = {"input": "image"}
    if hologram is not None and z is not None:
        # refused before the hologram is read or --z parsed
        raise click.BadParameter(HOLOGRAM_OR_PLANE, param_hint="--z")
    holo = None
    if hologram is not None:
        holo = read_hologram(hologram, layout, check)
        info["hologram"] = str(hologram)
    plane = None if z is None else _one_plane(z, "the plane to search")
    with _named():
        return from_image(img, medium, args, hologram=holo, plane=plane, name=path.name), info


def _from_hologram(path: Path, holo: Any, z: str | None, medium: Any, spec: dict[str, Any],
                   check: bool, args: dict[str, Any],
                   report: Reporter) -> tuple[Any, dict[str, Any]]:
    from ...analysis.detect.sources import from_hologram

    zs = None
    if z is not None:
        zs = depth_ranges(z)
        check_planes(holo, zs, z, medium, spec, check)
    with _named():
        df = from_hologram(holo, zs, medium, args, progress=report.progress, name=path.name)
    return df, {"input": "hologram", "upsample": 4}


def detection_options(f: Any) -> Any:
    """The options that say what to search and how (``detect`` and ``report``): the
    planes of a hologram (``--z``), the ground, its permittivity interval, the
    false-alarm rate and the kinds."""
    for opt in reversed([
        click.option("--z", "z", default=None,
                     help="A hologram FILE: the planes to image it on (m: 0.4 or "
                          "start:stop:step). An image volume or a survey store: the one "
                          "plane to search from the image alone."),
        medium_options,
        click.option("--eps-interval", default=None, metavar="LO,HI",
                     help="Interval of the ground's real permittivity, e.g. 2.2,2.8: widens "
                          "the depth interval (needs a ground)."),
        click.option("--false-alarm", default="1e-3", show_default=True, metavar="P",
                     help="Expected false objects per resolution cell on noise: sets the "
                          "threshold from the image's own noise."),
        click.option("--kinds", default="point,line,area", show_default=True,
                     metavar="KIND,...",
                     help="Which kinds of object to report: point, line, area."),
    ]):
        f = opt(f)
    return f


# ---------------------------------------------------------------- the command

@click.command()
@click.argument("file", type=click.Path(exists=True, path_type=Path))
@detection_options
@click.option("--hologram", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None,
              help="An image FILE's hologram (the file it was imaged from): each object is "
                   "its point response fitted to it (unbiased position, with uncertainty).")
@click.option("-o", "--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="The table: .csv, .json (records and metadata) or .geojson (for GIS: "
                   "WGS 84 longitude and latitude, needs the positions' CRS: --crs or a "
                   "survey's own; a table of several kinds also as one file per kind).")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@crs_option
@click.option("--origin", default=None, metavar="E,N",
              help="A local survey placed in --crs: the easting and northing (the CRS's "
                   "units, metres) of its (0, 0); the positions written are then eastings "
                   "and northings.")
@click.option("--azimuth", type=float, default=0.0, show_default=True,
              help="With --origin: the bearing of the survey's +y axis, degrees clockwise "
                   "from north (0: +y north, +x east).")
@layout_option
@output_options
def detect(file: Path, z: str | None, medium_spec: dict[str, Any], eps_interval: str | None,
           false_alarm: str, kinds: str, hologram: Path | None, out: Path | None, force: bool,
           crs: Any, origin: str | None, azimuth: float, layout: str | None, check: bool,
           report: Reporter) -> None:
    """List the objects in an image, a hologram or a survey store.

    FILE: an image (holoradar image/mosaic), a hologram (imaged on --z first) or a
    survey store (.zarr from holoradar batch: objects in survey coordinates).
    Prints one line per object; -o writes the table (.csv, .json, .geojson).
    """
    from ...io.detections import SUFFIXES
    from ...io.output import check_output
    from ...survey.store import is_survey

    inputs = [file] + ([hologram] if hologram is not None else [])
    if out is not None:
        check_output(out, suffixes=SUFFIXES, inputs=inputs, overwrite=force, name="--out")
    interval = _eps_interval(eps_interval)
    args = {"false_alarm": _false_alarm(false_alarm), "kinds": _kinds(kinds)}
    full = {**args, "eps_interval": interval, "progress": report.progress}
    store = file.is_dir()
    if store and not is_survey(file):
        raise click.BadParameter(f"{file} is a folder but not a survey store (holoradar batch "
                                 "writes one)", param_hint="FILE")
    if store and hologram is not None:
        raise click.BadParameter("a survey store's frames are fitted with their own "
                                 "holograms: give no --hologram", param_hint="--hologram")
    crs = _positions_crs(file, store, crs, out)
    placed = _origin(origin, azimuth, crs)
    if store:
        df, info, medium = _from_store(file, z, medium_spec, full, report)
        frame = "survey: x, y are world metres (the frames' positions plus pixel offsets)"
    else:
        df, info, medium = _from_file(file, z, medium_spec, full, hologram, layout, check,
                                      report)
        frame = "scene: x, y are metres on the image's axes"
    if placed is not None:
        df = _placed(df, *placed)
        info["origin"] = {"easting_northing_m": list(placed[0]), "azimuth_deg": placed[1]}
        frame += f"; placed in the CRS: (0, 0) at E {placed[0][0]:.3f} N {placed[0][1]:.3f}, " \
                 f"+y at {placed[1]:g} degrees from north"
    _done(file, df, info, medium, args, interval, out, frame, report, crs, force)


def _origin(origin: str | None, azimuth: float, crs: Any
            ) -> tuple[tuple[float, float], float] | None:
    """``--origin E,N`` (and ``--azimuth``), checked: it needs a CRS."""
    if origin is None:
        if azimuth != 0.0:
            raise click.BadParameter("--azimuth turns a local survey placed by --origin: "
                                     "give --origin E,N too", param_hint="--azimuth")
        return None
    try:
        e, n = (float(v) for v in origin.split(","))
    except ValueError:
        raise click.BadParameter(f"expected E,N (easting and northing in metres), got "
                                 f"{origin!r}", param_hint="--origin") from None
    if crs is None:
        raise click.BadParameter("places the survey in a CRS: give --crs EPSG:... too",
                                 param_hint="--origin")
    if not (np.isfinite(e) and np.isfinite(n) and np.isfinite(azimuth)):
        raise click.BadParameter(f"must be finite, got {origin!r}", param_hint="--origin")
    return (e, n), float(azimuth)


def _placed(df: Any, origin: tuple[float, float], azimuth: float) -> Any:
    """The table with its positions (centres, line ends, outlines) as eastings and
    northings, and its azimuths as bearings turned with the grid."""
    from ...io.crs import from_local

    out = df.copy()
    for xk, yk in (("x", "y"), ("x_start", "y_start"), ("x_end", "y_end")):
        if xk in out and yk in out:
            out[xk], out[yk] = from_local(out[xk].to_numpy(float), out[yk].to_numpy(float),
                                          origin, azimuth)
    if "azimuth_deg" in out:
        # From +x towards +y, turned with the grid (a rotation by -azimuth).
        out["azimuth_deg"] = (out["azimuth_deg"] - azimuth) % 180.0
    outlines = df.attrs.get("outlines") or {}
    out.attrs = dict(df.attrs)
    if outlines:
        out.attrs["outlines"] = {k: [list(from_local([u], [v], origin, azimuth))
                                     for u, v in ring] for k, ring in outlines.items()}
        out.attrs["outlines"] = {k: [[float(p[0][0]), float(p[1][0])] for p in ring]
                                 for k, ring in out.attrs["outlines"].items()}
    return out


def _positions_crs(file: Path, store: bool, crs: Any, out: Path | None) -> Any:
    """The positions' CRS: ``--crs`` or a survey store's own (they must agree); GeoJSON
    without one is refused before any work."""
    from ...io.crs import crs_name

    if store:
        from ...survey.store import stored_crs

        have = stored_crs(file)
        if have is not None and crs is not None and not have.equals(crs):
            raise click.BadParameter(f"the store's frame positions are in {crs_name(have)}, "
                                     f"not {crs_name(crs)}: give no --crs (or the same)",
                                     param_hint="--crs")
        crs = crs if crs is not None else have
    if out is not None and out.suffix.lower() == ".geojson" and crs is None:
        where = ("the survey's frame positions carry no coordinate reference system "
                 "(holoradar batch --crs keeps one with the store)") if store else \
            "the image's axes are metres in no known coordinate reference system"
        raise click.BadParameter(f"GeoJSON (RFC 7946) is WGS 84 longitude and latitude, and "
                                 f"{where}: give --crs EPSG:... (the projected CRS of the "
                                 "positions), or write .csv or .json (metres)",
                                 param_hint="--out")
    return crs


def _done(file: Path, df: Any, info: dict[str, Any], medium: Any, args: dict[str, Any],
          interval: tuple[float, float] | None, out: Path | None, frame: str,
          report: Reporter, crs: Any = None, force: bool = False) -> None:
    """The table on the terminal (or as JSON) and, with ``--out``, in its file."""
    from ...io.detections import medium_dict, records, table_lines, write
    from ...io.plain import plain

    metadata = plain({"source": str(file), **info, "false_alarm": args["false_alarm"],
                      "kinds": list(args["kinds"]), "medium": medium_dict(medium),
                      "eps_interval": None if interval is None else list(interval),
                      "columns": [str(c) for c in df.columns], "units": "m, dB, deg",
                      "crs": None if crs is None else crs.to_string()})
    written: list[Path] = []
    if out is not None:
        try:
            written = write(out, df, metadata, frame, crs, overwrite=force)
        except ValueError as exc:
            raise click.BadParameter(str(exc).removeprefix("--out "),
                                     param_hint="--out") from None
    none = "no object above the threshold"
    if info.get("input") == "image" and "hologram" not in info:
        from ...analysis.detect.api import NOTHING_FROM_THE_IMAGE

        none = NOTHING_FROM_THE_IMAGE
    lines = table_lines(df) if len(df) else [none]
    counts = ", ".join(f"{int((df['kind'] == k).sum())} {k}(s)" for k in _KINDS
                       if (df["kind"] == k).any()) or "none"
    head = f"{file.name}: {len(df)} object(s) ({counts}), false alarm {args['false_alarm']:g} " \
           "per resolution cell"
    wrote = [f"wrote {p}" for p in written]
    multiples = df.attrs.get("multiples") or []
    if multiples:
        # Said, not listed: an object's echo again at twice its depth is not an object.
        from ..numbers import cm

        lines.append(f"{len(multiples)} surface multiple(s), not objects: " + "; ".join(
            f"{m['kind']} at x {cm(m['x'])} cm, depth {cm(m['depth'])} cm (twice the "
            f"{cm(m['of_depth'])} cm of the object at x {cm(m['of_x'])} cm)"
            for m in multiples))
    if not len(df):
        metadata["note"] = none
    report.done({"objects": records(df), "n_objects": len(df), "metadata": metadata,
                 "out": None if out is None else str(out),
                 "files": [str(p) for p in written]},
                [head, *lines, *wrote], result=[*lines, *wrote])


COMMANDS = [detect]
