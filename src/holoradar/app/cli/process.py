"""``holoradar suppress`` (the surface glare) and ``holoradar synthesize`` (several views)."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..numbers import cm
from .common import (
    Reporter,
    array_of,
    check_ground,
    check_planes,
    depth_ranges,
    frame_option,
    input_history,
    layout_option,
    medium_from_options,
    medium_options,
    output_options,
    read_hologram,
    resolve_upsample,
    triple,
    upsample_option,
)
from .image import write_image

__all__ = ["COMMANDS"]


def _sources(horns: tuple[str, ...], plane_waves: tuple[str, ...], pattern: float,
             n: int) -> list[Any] | None:
    """Sources given on the command line, one per input (or one for all); None if none."""
    from ...physics.sources import PlaneWave, PointSource

    if horns and plane_waves:
        raise click.BadParameter("give --horn or --plane-wave, not both",
                                 param_hint="--horn/--plane-wave")
    out: list[Any] = []
    for h in horns:
        out.append(PointSource(triple(h, "--horn"), pattern_exponent=pattern))
    for p in plane_waves:
        try:
            a, b = (math.radians(float(v)) for v in p.split(","))
        except ValueError:
            raise click.BadParameter(f"expected alpha,beta in degrees, got {p!r}",
                                     param_hint="--plane-wave") from None
        out.append(PlaneWave(a, b))
    if not out:
        return None
    if len(out) == 1:
        return out * n
    if len(out) != n:
        raise click.BadParameter(f"give one source for all {n} inputs or one per input, got "
                                 f"{len(out)}", param_hint="--horn/--plane-wave")
    return out


_SOURCE_HELP = ("The radiator (horn) position x,y,z in metres, for files that do not carry "
                "their source (repeat once per input, in order, or give it once for all).")


@click.command()
@click.argument("hologram_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@medium_options
@click.option("--method", type=click.Choice(["gaussian", "image_source", "cut", "background"]),
              default="gaussian", show_default=True,
              help="Glare model: a fitted Gaussian beam, the horn's exact mirror image, a "
                   "mask in the mirror plane, or subtraction of an empty-scene hologram.")
@click.option("--background", "background_file", default=None,
              type=click.Path(exists=True, dir_okay=False, path_type=Path),
              help="The empty-scene hologram for --method background.")
@click.option("--horn", "horns", multiple=True, help=_SOURCE_HELP)
@click.option("--pattern", default=0.0, show_default=True, type=click.FloatRange(min=0),
              help="Horn pattern exponent m of cos^m (with --horn).")
@click.option("--no-direct", is_flag=True,
              help="The data hold no direct wave from the horn (a calibrated device).")
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The cleaned hologram, .nc.")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@layout_option
@output_options
def suppress(hologram_file: Path, medium_spec: dict[str, Any], method: str,
             background_file: Path | None, horns: tuple[str, ...], pattern: float,
             no_direct: bool, out: Path, force: bool, layout: str | None, check: bool,
             report: Reporter) -> None:
    """Remove the glare of the ground surface (and the horn's direct wave) from a hologram.

    The ground (--eps/--z-surface, --layers or --medium) sets the mirror plane;
    its permittivity is the fit's starting value and is estimated from the glare.
    """
    from ...imaging.glare import suppress_surface
    from ...io import save
    from ...io.output import check_output

    inputs = [hologram_file, *([background_file] if background_file else [])]
    check_output(out, suffixes=[".nc", ".nc4"], inputs=inputs, overwrite=force, name="--out")
    holo = read_hologram(hologram_file, layout, check)
    medium = medium_from_options(medium_spec, float(np.mean(holo.frequencies)))
    if medium is None:
        raise click.BadParameter("the glare needs a ground: give --eps and --z-surface, "
                                 "--layers or --medium", param_hint="--eps/--z-surface")
    if check:
        check_ground(medium, medium_spec, *array_of(holo))
    if method == "background" and background_file is None:
        raise click.BadParameter("--method background needs --background FILE",
                                 param_hint="--background")
    background = read_hologram(background_file, layout, check) if background_file else None
    src = _sources(horns, (), pattern, 1)
    t0 = time.perf_counter()
    # The printed eps comes from the exact glare fit, with its uncertainty, whichever
    # method removes the glare (the Gaussian's own estimate is rough).
    clean, rep = suppress_surface(holo, medium, None if src is None else src[0], method,
                                  background=background, direct=not no_direct,
                                  exact_eps=method == "gaussian")
    seconds = time.perf_counter() - t0
    save(clean, out, overwrite=force, history=[*input_history(hologram_file, layout), {
        "step": "suppress_surface", "input": hologram_file.name,
        "parameters": {"method": method, "direct": not no_direct, "layout": layout,
                       "background": None if background_file is None else
                       background_file.name}}])
    from ..eps_text import eps_summary, eps_text

    rough = ("" if rep.eps_std is not None else
             f"from the {method} fit's glare strength; --method image_source fits the exact "
             "glare with its uncertainty")
    rough_gaussian = rep.parameters.get("eps_gaussian")
    extra = {} if rough_gaussian is None else {
        "eps_from": "the exact glare fit (image_source)",
        "eps_gaussian_rough": [rough_gaussian.real, rough_gaussian.imag]}
    s = {"out": str(out), "method": method, "glare_suppression_db": rep.glare_suppression_db,
         "glare_removed_db": rep.glare_removed_db, **eps_summary(rep.eps, rep.eps_std, rough),
         **extra,
         "mirror_position_m": rep.mirror_position, "converged": rep.converged,
         "seconds": seconds}
    how = "" if rough_gaussian is None else " (exact glare fit)"
    eps_line = [] if rep.eps is None else [
        f"ground permittivity from the glare{how}: "
        f"{eps_text(rep.eps, rep.eps_std, rough=rough)}"]
    report.done(s, [
        f"glare suppressed by {rep.glare_suppression_db:.1f} dB at its mirror spot "
        f"({method}{'' if rep.converged else ', fit did not converge'}) in {seconds:.1f} s",
        *eps_line, f"wrote {out}",
    ], result=[*eps_line, f"wrote {out}"])


@click.command()
@click.argument("hologram_files", nargs=-1, required=True,
                type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--z", "z", required=True, help="Range(s) in metres: 0.4 or start:stop:step.")
@medium_options
@click.option("--mode", type=click.Choice(["coherent", "quasi-coherent", "amplitude"]),
              default="coherent", show_default=True,
              help="How the views add: complex sum with each view's incident phase removed, "
                   "phase-aligned sum, or sum of amplitudes.")
@frame_option
@upsample_option
@click.option("--horn", "horns", multiple=True, help=_SOURCE_HELP)
@click.option("--plane-wave", "plane_waves", multiple=True, metavar="ALPHA,BETA",
              help="A plane-wave view's angles from z towards x and y, degrees (repeat once "
                   "per input).")
@click.option("--pattern", default=0.0, show_default=True, type=click.FloatRange(min=0),
              help="Horn pattern exponent m of cos^m (with --horn).")
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The synthesised image, .nc or .npz.")
@click.option("--png/--no-png", default=True, show_default=True,
              help="Also write a PNG of the brightest plane beside --out.")
@click.option("--force", is_flag=True, help="Replace existing output files.")
@layout_option
@output_options
def synthesize(hologram_files: tuple[Path, ...], z: str, medium_spec: dict[str, Any],
               mode: str, frame: str, upsample: int | str, horns: tuple[str, ...],
               plane_waves: tuple[str, ...], pattern: float, out: Path, png: bool, force: bool,
               layout: str | None, check: bool, report: Reporter) -> None:
    """Image several views of one scene (different illuminations) into one image.

    Each HOLOGRAM_FILE is one view with its source: holoradar files carry it;
    for others give --horn or --plane-wave once per file.
    """
    from ...analysis.metrics import peak_position
    from ...imaging.synthesis import synthesize as run
    from ...io.output import check_output

    zs = depth_ranges(z)
    check_output(out, suffixes=[".nc", ".nc4", ".npz"], inputs=hologram_files,
                 overwrite=force, name="--out")
    if png:
        check_output(out.with_suffix(".png"), suffixes=[".png"], inputs=hologram_files,
                     overwrite=force, name="--out's PNG")
    views = [read_hologram(p, layout, check) for p in hologram_files]
    srcs = _sources(horns, plane_waves, pattern, len(views))
    if srcs is not None:
        views = [v.replace(source=s) for v, s in zip(views, srcs, strict=True)]
    missing = [p.name for p, v in zip(hologram_files, views, strict=True) if v.source is None]
    if missing:
        raise click.BadParameter(f"{', '.join(missing)} carr{'ies' if len(missing) == 1 else 'y'}"
                                 " no source: give --horn or --plane-wave per view",
                                 param_hint="--horn/--plane-wave")
    medium = medium_from_options(medium_spec, float(np.mean(views[0].frequencies)))
    check_planes(views[0], zs, z, medium, medium_spec, check)
    upsample = resolve_upsample(upsample, views[0], zs, medium)
    t0 = time.perf_counter()
    img = run(views, zs, medium=medium, mode=mode, upsample=upsample, frame=frame)
    seconds = time.perf_counter() - t0
    pk = peak_position(img)
    made = [s for p in hologram_files for s in input_history(p, layout)]
    files = write_image(img, out, force, [*made, {
        "step": "synthesize", "input": [p.name for p in hologram_files],
        "parameters": {"z": z, "mode": mode, "frame": frame, "upsample": upsample}}],
        png, f"{len(views)} views ({mode})")
    report.done({"peak_m": pk, "out": str(out), "files": files, "views": len(views),
                 "seconds": seconds}, [
        f"synthesised {len(views)} views ({mode}) in {seconds:.1f} s",
        f"brightest point x={cm(pk[0])} y={cm(pk[1])} z={cm(pk[2])} cm",
        *[f"wrote {f}" for f in files],
    ], result=[f"wrote {f}" for f in files])


COMMANDS = [suppress, synthesize]
