"""``holoradar invert``: the reflectivity behind a hologram, by inverting the measurement."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..numbers import cm
from .common import (
    Reporter,
    check_planes,
    depth_ranges,
    frame_option,
    input_history,
    layout_option,
    medium_from_options,
    medium_options,
    output_options,
    read_hologram,
)
from .image import write_image

__all__ = ["COMMANDS"]


@click.command()
@click.argument("hologram_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--z", "z", required=True,
              help="Range(s) from the array plane in metres: 0.4, or a sweep start:stop:step "
                   "such as 0.3:0.5:0.01.")
@medium_options
@click.option("--method", type=click.Choice(["lsqr", "sparse"]), default="lsqr",
              show_default=True,
              help="Damped least squares stopped at the noise, or L1-sparse (a few "
                   "objects: resolves closer ones, no sidelobes; slower).")
@click.option("--noise", type=float, default=None,
              help="The receiver noise's standard deviation per sample, in the data's units "
                   "(default: estimated from the hologram, or 40 dB below its power).")
@click.option("--max-iter", type=click.IntRange(1, 100000), default=None,
              help="The most solver steps (default 100 lsqr, 1000 sparse).")
@frame_option
@click.option("--upsample", default=1, show_default=True, type=click.IntRange(1, 8),
              help="Voxels per element pitch.")
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="Output reflectivity: .nc (NetCDF-4, with the solver's history) or .npz.")
@click.option("--png/--no-png", default=True, show_default=True,
              help="Also write a PNG of the brightest plane beside --out.")
@click.option("--force", is_flag=True, help="Replace existing output files.")
@layout_option
@output_options
def invert(hologram_file: Path, z: str, medium_spec: dict[str, Any], method: str,
           noise: float | None, max_iter: int | None, frame: str, upsample: int, out: Path,
           png: bool, force: bool, layout: str | None, check: bool, report: Reporter) -> None:
    """Invert a hologram for the reflectivity on range(s) Z: each voxel's Born scattering
    amplitude, the illumination divided out, without the aperture's sidelobes.

    HOLOGRAM_FILE: one frame, a holoradar .nc file or a user's file with --layout; a
    receiver array must carry its source (the illumination is divided out).
    """
    from ...analysis.metrics import peak_position
    from ...imaging.inversion import invert as run
    from ...io.output import check_output

    zs = depth_ranges(z)
    check_output(out, suffixes=[".nc", ".nc4", ".npz"], inputs=[hologram_file],
                 overwrite=force, name="--out")
    if png:
        check_output(out.with_suffix(".png"), suffixes=[".png"], inputs=[hologram_file],
                     overwrite=force, name="--out's PNG")
    holo = read_hologram(hologram_file, layout, check)
    medium = medium_from_options(medium_spec, float(np.mean(holo.frequencies)))
    check_planes(holo, zs, z, medium, medium_spec, check)
    t0 = time.perf_counter()
    try:
        refl = run(holo, zs, medium=medium, method=method, noise=noise, max_iter=max_iter,
                   progress=report.progress, upsample=upsample, frame=frame)
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="HOLOGRAM_FILE") from None
    seconds = time.perf_counter() - t0
    step = refl.history[0]
    ground = None if medium is None else {"z_interfaces": list(medium.z_interfaces),
                                           "eps": [str(e) for e in medium.eps]}
    history = [*input_history(hologram_file, layout), {
        "step": "invert", "input": hologram_file.name,
        "parameters": {"z": z, "method": method, "noise": noise, "max_iter": max_iter,
                       "frame": frame, "upsample": upsample, "layout": layout,
                       "medium": ground}}]
    files = write_image(refl, out, force, history, png,
                        f"{hologram_file.name} (reflectivity, {method})")
    pk = peak_position(refl)
    report.done({"peak_m": pk, "out": str(out), "files": files, "seconds": seconds,
                 "iterations": step["iterations"], "stop": step["stop"],
                 "residual_over_noise": step["residual_over_noise"],
                 "noise": step["noise"], "shape": list(refl.data.shape)}, [
        f"inverted {hologram_file.name} ({method}): {refl.z.size} plane(s), {refl.x.size} x "
        f"{refl.y.size} voxels, {step['iterations']} steps in {seconds:.1f} s",
        f"stopped: {step['stop']}; residual {step['residual_over_noise']:.2f} x the noise "
        f"({step['noise']})",
        f"brightest voxel x={cm(pk[0])} y={cm(pk[1])} z={cm(pk[2])} cm",
        *[f"wrote {f}" for f in files],
    ], result=[f"wrote {f}" for f in files])


COMMANDS = [invert]
