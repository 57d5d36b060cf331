"""``holoradar image``: migrate a hologram to one range or a depth sweep."""

from __future__ import annotations

import io
import time
import warnings
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
    resolve_upsample,
    upsample_option,
)

__all__ = ["COMMANDS", "write_image"]


def write_image(img: Any, out: Path, force: bool, history: list[dict[str, Any]],
                png: bool, title: str, z_surface: float | None = None) -> list[str]:
    """Write an image as .nc (with its history) or .npz, and a PNG of its brightest plane
    (a line scan's: its x-z section, with the depth below ``z_surface``)."""
    from ...analysis.metrics import peak_position
    from ...io import save
    from ..atomic import write_atomic

    if out.suffix.lower() in (".nc", ".nc4"):
        save(img, out, overwrite=force, history=history)
    else:
        buf = io.BytesIO()
        # holoradar_kind marks it as an image, so that reading it never mistakes it for
        # a hologram (plain numbers, no pickle)
        np.savez(buf, data=img.data, x=img.x, y=img.y, z=img.z, frequency=img.frequency,
                 holoradar_kind=np.array("Image"), method=np.array(img.method),
                 has_z_axis=np.array(img.has_z_axis))
        write_atomic(out, buf.getvalue())
    files = [str(out)]
    if png:
        from .. import plotting  # matplotlib: 0.3-0.6 s to import, only for the picture

        pk = peak_position(img)
        if img.y.size == 1 and img.has_z_axis and img.z.size > 1:
            fig = plotting.plot_section(img, along="x", at=float(img.y[0]),
                                        z_surface=z_surface, title=title)
        else:
            fig = plotting.plot_image([img.plane(pk[2])], [title])
        write_atomic(out.with_suffix(".png"), plotting.to_png(fig))
        files.append(str(out.with_suffix(".png")))
    return files


@click.command()
@click.argument("hologram_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--z", "z", required=True,
              help="Range(s) from the array plane in metres: 0.4, or a sweep start:stop:step "
                   "such as 0.3:0.5:0.005.")
@medium_options
@click.option("--method", type=click.Choice(["angular", "fresnel"]), default="angular",
              show_default=True, help="Exact angular spectrum, or the paper's Fresnel kernel.")
@frame_option
@upsample_option
@click.option("--double", is_flag=True,
              help="Compute in double precision (default single: within 1e-6 of the image's "
                   "peak, about twice as fast).")
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="Output image: .nc (NetCDF-4, holoradar.load reads it) or .npz.")
@click.option("--png/--no-png", default=True, show_default=True,
              help="Also write a PNG of the brightest plane beside --out.")
@click.option("--force", is_flag=True, help="Replace existing output files.")
@layout_option
@output_options
def image(hologram_file: Path, z: str, medium_spec: dict[str, Any], method: str, frame: str,
          upsample: int | str, double: bool, out: Path, png: bool, force: bool, layout: str | None,
          check: bool, report: Reporter) -> None:
    """Migrate a hologram to range(s) Z through air or a (layered, lossy) ground.

    HOLOGRAM_FILE: a holoradar .nc file, or a user's .npz, .npy (+ .json
    sidecar), .mat, .h5 or .csv with --layout saying where the field is.
    """
    from ...analysis.metrics import peak_position
    from ...imaging.migrate import migrate
    from ...io.output import check_output
    from .checks import check_image

    zs = depth_ranges(z)
    # Outputs are checked before any work: never an input, never replaced unasked.
    check_output(out, suffixes=[".nc", ".nc4", ".npz"], inputs=[hologram_file],
                 overwrite=force, name="--out")
    if png:
        check_output(out.with_suffix(".png"), suffixes=[".png"], inputs=[hologram_file],
                     overwrite=force, name="--out's PNG")
    # What was warned of on the way is said now and kept in the image's history (a
    # report of the image lists it).
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        # The I/Q sign is checked after imaging, at the planes imaged (check_image).
        holo = read_hologram(hologram_file, layout, check, iq_check=False)
        medium = medium_from_options(medium_spec, float(np.mean(holo.frequencies)))
        check_planes(holo, zs, z, medium, medium_spec, check)
        upsample = resolve_upsample(upsample, holo, zs, medium)
        _check_room(holo, zs, upsample, double, out, report)
        t0 = time.perf_counter()
        img = migrate(holo, zs, medium=medium, method=method, upsample=upsample, frame=frame,
                      progress=report.progress,
                      dtype=np.complex128 if double else np.complex64)
        seconds = time.perf_counter() - t0
        pk = peak_position(img)
        # data in the other I/Q convention, a picture of the glare: said, with the fix
        check_image(hologram_file, holo, img, medium, medium_spec, zs, layout=layout,
                    method=method, frame=frame, upsample=upsample)
    texts: list[str] = []
    for w in said:
        text = f"{w.category.__name__}: {' '.join(str(w.message).split())}"
        if text not in texts:
            texts.append(text)
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    ground = None if medium is None else {"z_interfaces": list(medium.z_interfaces),
                                           "eps": [str(e) for e in medium.eps]}
    history = [*input_history(hologram_file, layout), {
        "step": "migrate", "input": hologram_file.name,
        "parameters": {"z": z, "method": method, "frame": frame, "upsample": upsample,
                       "precision": "double" if double else "single",
                       "layout": layout, "medium": ground}, "warnings": texts}]
    surface = medium.z_interfaces[0] if medium is not None and medium.z_interfaces else None
    files = write_image(img, out, force, history, png, f"{hologram_file.name} ({method})",
                        z_surface=surface)
    report.done({"peak_m": pk, "out": str(out), "files": files, "planes": int(img.z.size),
                 "shape": list(img.data.shape), "seconds": seconds}, [
        f"imaged {hologram_file.name}: {img.z.size} plane(s), {img.x.size} x {img.y.size} "
        f"pixels, in {seconds:.1f} s",
        f"brightest point x={cm(pk[0])} y={cm(pk[1])} z={cm(pk[2])} cm",
        *[f"wrote {f}" for f in files],
    ], result=[f"wrote {f}" for f in files])


COMMANDS = [image]


#: An output past this size is announced before any work (as a survey's batch does).
ANNOUNCE_BYTES = 1e9


def _check_room(holo: Any, zs: Any, upsample: int, double: bool, out: Path,
                report: Reporter) -> None:
    """The image file's size (planes x pixels x I and Q) before any work: said when it
    passes :data:`ANNOUNCE_BYTES`, refused when the output's disk cannot hold it."""
    import shutil

    from ...survey.space import bytes_text

    ny, nx = holo.data.shape[-2:]
    frames = int(np.prod(holo.data.shape[:-3 if holo.is_wideband else -2]))
    planes = int(np.size(zs))
    pixels = (upsample * (ny - 1) + 1) * (upsample * (nx - 1) + 1)
    need = frames * planes * pixels * (16 if double else 8)
    free = shutil.disk_usage(out.resolve().parent).free
    shape = f"{planes} planes of {upsample * (nx - 1) + 1} x {upsample * (ny - 1) + 1} pixels"
    if need > free:
        raise click.BadParameter(
            f"the image would take {bytes_text(need)} ({shape}) but the disk of {out.name} "
            f"has {bytes_text(free)} free: fewer planes (--z), a smaller --upsample, or "
            "another disk", param_hint="--out")
    if need > ANNOUNCE_BYTES:
        report.line(f"the image will take {bytes_text(need)} ({shape}); "
                    f"{bytes_text(free)} free on its disk")
