"""``holoradar report``: the inspection report of images, holograms or survey stores, as
one self-contained HTML file.

FILE... as for ``holoradar detect`` (an image, a hologram imaged on ``--z``, or a
survey store); several files make one report with a section per file. The options
that find the objects are ``holoradar detect``'s, parsed by its own parsers.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from .common import Reporter, layout_option, output_options
from .detect import detection_options

__all__ = ["COMMANDS"]

_NAMES = {"sources": "FILE", "path": "--out", "z": "--z", "hologram": "--hologram",
          "medium": "--eps/--z-surface", "eps_interval": "--eps-interval",
          "detections": "detections", "min_cover": "--min-cover", "meta": "--meta"}
_FIELDS = ("site", "element", "operator", "scan")


def _min_cover(ctx: Any, param: Any, value: str | None) -> float | None:
    from ...reporting.inspection import as_length

    try:
        return as_length(value, "--min-cover")
    except ValueError as exc:
        raise click.BadParameter(str(exc).removeprefix("--min-cover: "),
                                 param_hint="--min-cover") from None


def _meta(meta: Path | None, given: dict[str, str | None]) -> dict[str, str]:
    """``--meta FILE``'s fields, overridden by the options given."""
    from ...reporting.inspection import as_meta

    try:
        fields = dict(as_meta(meta, "--meta"))
    except ValueError as exc:
        raise click.BadParameter(str(exc).removeprefix("--meta: "), param_hint="--meta") \
            from None
    fields.update({k: v for k, v in given.items() if v})
    return fields


def _medium(files: list[Path], spec: dict[str, Any], layout: str | None, check: bool) -> Any:
    """The ground the flags describe, at the first file's (centre) frequency (it matters
    only for ``--sigma``); None when no flag is given."""
    from .common import ground_table_from_options, medium_from_options

    if ground_table_from_options(spec) is None:
        return None
    if any(f.is_dir() for f in files):
        raise click.BadParameter("a survey store keeps the ground its frames were imaged "
                                 "through: give no ground flag",
                                 param_hint="--eps/--z-surface")
    import numpy as np

    from ...io import load

    obj = load(files[0], layout=layout, check=check)
    return medium_from_options(spec, float(np.mean(np.atleast_1d(obj.frequency))))


@click.command()
@click.argument("files", nargs=-1, required=True,
                type=click.Path(exists=True, path_type=Path), metavar="FILE...")
@click.option("-o", "--out", type=click.Path(dir_okay=False, path_type=Path), required=True,
              help="The report: an .html file (one file, pictures embedded, no network).")
@detection_options
@click.option("--hologram", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None,
              help="An image FILE's hologram (the file it was imaged from): each object is "
                   "its point response fitted to it (one FILE only).")
@click.option("--title", default="Inspection report", show_default=True,
              help="The report's heading.")
@click.option("--min-cover", default=None, metavar="LENGTH", callback=_min_cover,
              help="The specified minimum concrete cover, e.g. 35mm or 3.5cm: bars below "
                   "it are marked in the tables and on the rebar plan.")
@click.option("--meta", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None,
              help="A TOML or JSON file of the inspection's fields (site, element, operator, "
                   "scan, date, ...), shown at the report's top.")
@click.option("--site", default=None, help="The site (overrides --meta's).")
@click.option("--element", default=None, help="The element scanned, e.g. 'slab S3, bay 2'.")
@click.option("--operator", default=None, help="Who scanned.")
@click.option("--scan", default=None, help="The scan's name or number.")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@layout_option
@output_options
def report(files: tuple[Path, ...], out: Path, z: str | None, medium_spec: dict[str, Any],
           eps_interval: str | None, false_alarm: str, kinds: str, hologram: Path | None,
           title: str, min_cover: float | None, meta: Path | None, site: str | None,
           element: str | None, operator: str | None, scan: str | None, force: bool,
           layout: str | None, check: bool, report: Reporter) -> None:
    """Write the inspection report of images, holograms or survey stores.

    FILE...: images (holoradar image/mosaic), holograms (imaged on --z first) or
    survey stores (.zarr from holoradar batch), one section each. The report holds
    the objects (numbered as holoradar detect numbers them) outlined on plan views
    at their depths, their table, the ground, the device and settings, the
    processing history and the warnings; bars are summarised per layer (count,
    spacing, cover against --min-cover) with a plan coloured by cover; -o names it
    (.html).
    """
    from ...io.output import check_output
    from ...reporting import report as write_report
    from .common import depth_ranges
    from .detect import _eps_interval, _false_alarm, _kinds

    paths = list(dict.fromkeys(files))
    inputs = [*paths, *([hologram] if hologram is not None else [])]
    check_output(out, suffixes=[".html"], inputs=inputs, overwrite=force, name="--out")
    interval = _eps_interval(eps_interval)
    fa, ks = _false_alarm(false_alarm), _kinds(kinds)
    if hologram is not None and len(paths) != 1:
        raise click.BadParameter(f"--hologram is the hologram of one image FILE; {len(paths)} "
                                 "FILEs given", param_hint="--hologram")
    fields = _meta(meta, {"site": site, "element": element, "operator": operator,
                          "scan": scan})
    zs = depth_ranges(z) if z is not None else None
    medium = _medium(paths, medium_spec, layout, check)
    summary = write_report(paths, out, medium=medium, eps_interval=interval, false_alarm=fa,
                           kinds=ks, z=zs, hologram=hologram, title=title, force=force,
                           layout=layout, check=check, names=_NAMES, min_cover=min_cover,
                           meta=fields, progress=report.progress)
    lines = []
    for s in summary["sources"]:
        lines.append(f"{s['name']}: {s['n_objects']} object(s)"
                     + (f", {len(s['warnings'])} warning(s)" if s["warnings"] else ""))
    wrote = f"wrote {out} ({summary['bytes'] / 1e3:.0f} kB, {summary['n_objects']} object(s))"
    report.done({**summary, "out": str(out)}, [*lines, wrote], result=[wrote])


COMMANDS = [report]
