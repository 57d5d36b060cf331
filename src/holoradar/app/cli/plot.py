"""``holoradar plot FILE``: a labelled picture of a hologram or an image."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import click
import numpy as np

from .common import Reporter, array_of, check_ranges, output_options

__all__ = ["COMMANDS"]


@click.command()
@click.argument("file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The picture, .png.")
@click.option("--z", "zs", multiple=True, type=float,
              help="Image plane(s) to show, range in metres (repeat for several panels); "
                   "default the brightest plane.")
@click.option("--db", "db_range", type=click.FloatRange(min=1), default=None,
              help="Draw 20 log10 |E| over this many dB instead of a linear scale.")
@click.option("--scale", type=click.Choice(["shared", "each"]), default="shared",
              show_default=True,
              help="One colour scale for all panels, or each panel to its own maximum.")
@click.option("--z-surface", type=float, default=None,
              help="Ground surface range, m: label planes with their depth below it.")
@click.option("--section", type=click.Choice(["none", "x", "y"]), default="none",
              show_default=True,
              help="Draw a vertical section (x-z or y-z through the brightest point) instead "
                   "of planes (a line scan's image: its x-z section, always).")
@click.option("--layout", default=None, metavar="KEY=VALUE,...",
              help="For a user's hologram file (see holoradar image --help).")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@output_options
def plot(file: Path, out: Path, zs: tuple[float, ...], db_range: float | None, scale: str,
         z_surface: float | None, section: str, layout: str | None, force: bool,
         report: Reporter) -> None:
    """Plot a hologram (amplitude and phase) or an image (planes or a section)."""
    from ...analysis.metrics import peak_position
    from ...data.hologram import Hologram
    from ...io import load
    from ...io.output import check_output
    from .. import plotting
    from ..atomic import write_atomic

    check_output(out, suffixes=[".png"], inputs=[file], overwrite=force, name="--out")
    obj = load(file, layout=layout, check=False)
    if isinstance(obj, Hologram):
        if zs or section != "none":
            raise click.BadParameter("--z and --section apply to images; FILE holds a "
                                     "hologram", param_hint="--z/--section")
        fig = plotting.plot_hologram(obj, file.name)
        shown: list[float] = []
    else:
        if z_surface is not None:
            _check_surface(obj, z_surface)
        pk = peak_position(obj)
        if section == "none" and obj.y.size == 1 and obj.has_z_axis and obj.z.size > 1:
            section = "x"   # a line scan's image is its x-z section
        if section != "none":
            if not obj.has_z_axis or obj.z.size < 2:
                raise click.BadParameter("a section needs an image with several planes",
                                         param_hint="--section")
            fig = plotting.plot_section(obj, along=section, at=pk[1 if section == "x" else 0],
                                        db_range=db_range, z_surface=z_surface,
                                        title=file.name)
            shown = [float(v) for v in obj.z]
        else:
            shown = list(zs) or [pk[2]]
            outside = [z for z in shown if not obj.z.min() - 1e-9 <= z <= obj.z.max() + 1e-9]
            if outside:
                raise click.BadParameter(f"{outside} m outside the image's ranges "
                                         f"{obj.z.min():.4g}..{obj.z.max():.4g} m",
                                         param_hint="--z")
            fig = plotting.plot_planes(obj, shown, db_range=db_range,
                                       shared=scale == "shared", z_surface=z_surface,
                                       title=file.name)
    write_atomic(out, plotting.to_png(fig))
    report.done({"out": str(out), "kind": type(obj).__name__,
                 "planes_m": [float(v) for v in np.atleast_1d(shown)]}, [f"wrote {out}"])


def _check_surface(img: Any, z_surface: float) -> None:
    """Refuse a --z-surface the image's array cannot focus (centimetres for metres);
    warn when it lies beyond every plane (every depth is labelled negative)."""
    from ...data.plausibility import PlausibilityWarning

    check_ranges(z_surface, f"{z_surface:g}", "--z-surface", *array_of(img),
                 what=f"a ground surface {z_surface:.4g} m", escape=None)
    if z_surface > float(np.max(img.z)):
        warnings.warn(f"--z-surface {z_surface:.4g} m lies beyond every plane of the image "
                      f"(the last at {float(np.max(img.z)):.4g} m): every depth is labelled "
                      "negative, in the air", PlausibilityWarning, stacklevel=2)


COMMANDS = [plot]
