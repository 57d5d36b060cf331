"""``holoradar batch`` (image every frame of a survey, on one or more worker processes) and
``holoradar mosaic``."""

from __future__ import annotations

import glob
import sys
from pathlib import Path
from typing import Any

import click
import numpy as np

from .common import (
    Reporter,
    array_of,
    check_ground,
    check_ranges,
    crs_option,
    depth_ranges,
    medium_from_options,
    medium_options,
    output_options,
    refuse_outside_planes,
    warn_above_ground,
)

__all__ = ["COMMANDS"]


def _expand(patterns: tuple[str, ...]) -> list[Path]:
    """Frame files from names or quoted glob patterns ('survey/*.nc'), in sorted order."""
    out: list[Path] = []
    for pat in patterns:
        if any(c in pat for c in "*?["):
            hits = sorted(glob.glob(pat))
            if not hits:
                raise click.BadParameter(f"{pat!r} matches no file", param_hint="FRAMES")
            out += [Path(h) for h in hits]
        else:
            out.append(Path(pat))
    return out


def _check_workers(ctx: click.Context, param: click.Parameter, value: str | None) -> int | None:
    """--workers N: a positive integer, or a usage error saying so."""
    if value is None:
        return None
    try:
        n = int(value.strip())
    except ValueError:
        n = 0
    if n < 1:
        raise click.BadParameter(f"must be a positive integer (the number of worker "
                                 f"processes), got {value!r}", ctx=ctx, param=param)
    return n


@click.command()
@click.argument("frames", nargs=-1, required=True)
@click.option("-o", "--out", required=True, type=click.Path(path_type=Path),
              help="The survey's Zarr store (a folder ending in .zarr).")
@click.option("--z", "z", required=True, help="Range(s) in metres: 0.4 or start:stop:step.")
@medium_options
@click.option("--method", type=click.Choice(["angular", "fresnel"]), default="angular",
              show_default=True)
@click.option("--upsample", default=1, show_default=True, type=click.IntRange(1, 32),
              help="Image pixels per element pitch.")
@click.option("--workers", default=None, metavar="N", callback=_check_workers,
              help="Worker processes on this machine: 1 images in this process, N >= 2 "
                   "starts a local cluster of N for the run. Default: this process, and a "
                   "cluster of one worker per core only when the frames left after the "
                   "first few would take over 10 s here.")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Instead of --workers: a dask.distributed scheduler (tcp://host:8786), or "
                   "Dask's local threads, processes or synchronous.")
@click.option("--strict", is_flag=True,
              help="Stop at the first bad frame instead of reporting and skipping it.")
@click.option("--force", is_flag=True,
              help="Start the store afresh (settings changed) instead of refusing.")
@click.option("--retry-bad", is_flag=True,
              help="Read again the frames an earlier run found bad (by default a bad frame "
                   "whose file has not changed is skipped without reading it).")
@click.option("--layout", default=None, metavar="KEY=VALUE,...",
              help="For frames in a user's format: where the hologram is in each file (see "
                   "holoradar image --help).")
@crs_option
@output_options
def batch(frames: tuple[str, ...], out: Path, z: str, medium_spec: dict[str, Any], method: str,
          upsample: int, workers: int | None, scheduler: str | None, strict: bool,
          force: bool, retry_bad: bool, layout: str | None, crs: Any,
          report: Reporter) -> None:
    """Image every frame of a survey with the same settings into one Zarr store.

    FRAMES: hologram files or quoted patterns ('survey/*.nc'). A frame's position
    is its pose's centre (or the centre of its coordinates). Bad frames are
    reported and skipped; a rerun resumes, imaging only frames not yet done.
    """
    from ...survey import BatchInterrupted, SettingsMismatchError, run_batch
    from ...survey.batch import bytes_text

    if workers is not None and scheduler is not None:
        raise click.UsageError("--workers starts a local cluster and --scheduler names "
                               "another: give one of them")
    files = _expand(frames)
    zs = depth_ranges(z)
    first = _first_frame(files, layout)
    freq = 1.0
    if medium_spec["sigma"] is not None:  # a conductivity needs the frequency
        from ...io import load

        freq = float(np.mean(load(files[0], layout=layout).frequencies))
    medium = medium_from_options(medium_spec, freq)
    if first is not None:  # the ranges against the survey's array, before any frame is imaged
        aperture, f_max = array_of(first)
        check_ranges(zs, z, "--z", aperture, f_max, medium, escape=None)
        check_ground(medium, medium_spec, aperture, f_max, escape=None)
    warn_above_ground(zs, medium, medium_spec)

    def started(plan: dict[str, Any]) -> None:
        report.line(f"imaging {_frames(plan['frames'])} into {out}: up to "
                    f"{bytes_text(plan['bytes'])} ({bytes_text(plan['bytes_per_frame'])} a "
                    f"frame before compression); {bytes_text(plan['free'])} free on its disk")

    try:
        s = run_batch(files, out, z=zs, medium=medium, method=method, upsample=upsample,
                      workers=workers, scheduler=scheduler, strict=strict, overwrite=force,
                      retry_bad=retry_bad,
                      # A bar redraws its line with carriage returns: in a log file (stderr
                      # not a terminal) those are hundreds of lines of noise.
                      progress=report.progress and not report.as_json and sys.stderr.isatty(),
                      layout=layout, on_start=started, crs=crs)
    except BatchInterrupted as exc:
        raise KeyboardInterrupt(f"{exc.stored} of {_frames(exc.frames)} "
                                f"{'is' if exc.frames == 1 else 'are'} stored in {out}; "
                                "run the same command again to resume") from None
    except SettingsMismatchError as exc:  # the library's message names its overwrite=True
        raise ValueError(f"{out} was made with other settings ({'; '.join(exc.differences)})"
                         ": pass --force to start it again (its frames are removed), or "
                         "choose another store") from None
    for w in s.get("warnings", []):  # raised in the workers: shown here once each
        category, _, message = w.partition(": ")
        click.echo(f"warning: {' '.join(message.split())} ({category})", err=True)
    for sk in s["skipped"]:
        again = " (found by an earlier run, not read again; --retry-bad reads it)" \
            if sk.get("remembered") else ""
        click.echo(f"warning: skipped {sk['name']}: {' '.join(sk['reason'].split())}{again}",
                   err=True)
    if s["done"] == 0:  # the store holds what it held: no "wrote"
        stored = f"{_frames(s['resumed'])} already stored in {out}"
        nothing = f"nothing imaged: {stored}, {len(s['skipped'])} skipped" if s["skipped"] \
            else f"nothing to do: {stored}"
        report.done(s, [nothing], result=[nothing])
        return
    report.done(s, [
        f"imaged {s['done']} frame(s), {s['resumed']} already done, {len(s['skipped'])} "
        f"skipped, in {s['seconds']:.1f} s ({_where(s)})",
        f"wrote {out}",
    ], result=[f"wrote {out}"])


def _where(s: dict[str, Any]) -> str:
    n = s["workers"]
    if s["scheduler"] in ("in-process", "local cluster"):
        return f"{s['scheduler']}, {n} worker{'s' if n != 1 else ''}"
    return str(s["scheduler"])


def _frames(n: int) -> str:
    return f"{n} frame" if n == 1 else f"{n} frames"


def store_info(path: Path) -> tuple[dict[str, Any], list[str]]:
    """``holoradar info`` of a folder: the summary and lines describing a survey store.

    A folder that is not a survey store is a ``ValueError`` naming what ``info`` reads.
    """
    from ...survey import describe_store
    from ...survey.batch import bytes_text
    from ...survey.store import is_survey

    if not is_survey(path):
        raise ValueError(f"{path} is a folder that is not a holoradar survey store: info "
                         "reads a file, or a survey store (.zarr) written by holoradar batch")
    d = describe_store(path)
    st, geo = d["settings"], d["geometry"]
    z = np.asarray(st["z_m"], float)
    oy, ox = d["image_shape"][1:]
    f = np.asarray(geo["frequency_hz"], float) / 1e9
    step = " x ".join("?" if v is None else f"{v * 1e3:.4g}" for v in d["pixel_m"])
    packed = f"compressed ({', '.join(d['compressors'])})" if d["compressors"] \
        else "uncompressed"
    rows = [
        ("frames", f"{d['frames_stored']} stored of {d['frames_expected']}"),
        ("planes z (m)", _span(z)),
        ("frame grid", f"{geo['ny']} x {geo['nx']} elements, pitch "
                       f"{geo['pitch_m'][0] * 1e3:.4g} x {geo['pitch_m'][1] * 1e3:.4g} mm, "
                       + ("scanned transceiver" if geo["monostatic"] else "receiver array")),
        ("frequency (GHz)", _span(f)),
        ("image", f"{oy} x {ox} pixels a plane, step {step} mm (upsample "
                  f"{st['upsample']}), I and Q as {d['dtype']}, {packed}"),
        ("ground", d["ground"]),
        ("method", st["method"]),
    ]
    if d["extent_m"] is not None:
        x0, x1, y0, y1 = d["extent_m"]
        rows.append(("frame centres", f"x {x0:.4g} .. {x1:.4g} m, y {y0:.4g} .. {y1:.4g} m"))
    rows.append(("positions", f"georeferenced, {d['georeferenced']}" if d["georeferenced"]
                 else "local metres (no CRS: holoradar batch --crs, or detect --origin)"))
    rows.append(("created", str(d["created"])))
    lines = [f"{path.name}: a holoradar survey store ({bytes_text(d['bytes_on_disk'])} "
             "on disk)"]
    lines += [f"  {k:16s} {v}" for k, v in rows]
    lines += [f"  not stored: {m['name']}: {' '.join(m['reason'].split())}"
              for m in d["not_stored"]]
    lines += [f"  damaged: {m['name']}: {m['reason']}" for m in d["damaged"]]
    return {"file": str(path), "kind": "survey store", **d}, lines


def _span(v: np.ndarray) -> str:
    if v.size == 1:
        return f"{v[0]:.6g}"
    return f"{v[0]:.6g} .. {v[-1]:.6g} ({v.size}, step {(v[-1] - v[0]) / (v.size - 1):.6g})"


def _first_frame(files: list[Path], layout: str | None) -> Any:
    """The first frame, to judge the ranges by its array; None when it cannot be read
    (the run reports it by name and skips it, as any bad frame)."""
    from ...io import load

    try:
        return load(files[0], layout=layout, check=False)
    except (ValueError, OSError):
        return None


def _check_mosaic_options(store: Path, depth: float, z_surface: float | None,
                          name: str = "--range") -> None:
    """Refuse a plane (``name``: --range or --depth) outside the stored planes (the
    nearest plane would be mapped silently) and a --z-surface no frame's array can
    focus; warn when the surface lies beyond the mapped plane."""
    from ...data.plausibility import PlausibilityWarning
    from ...survey.store import is_survey, stored_settings

    if not is_survey(store):
        return  # the mosaic names what the folder lacks
    settings, geometry = stored_settings(store)
    refuse_outside_planes(depth, settings.z, name, "stored planes")
    if z_surface is None:
        return
    aperture = max(geometry.nx * abs(geometry.pitch[0]), geometry.ny * abs(geometry.pitch[1]))
    check_ranges(z_surface, f"{z_surface:g}", "--z-surface", aperture, max(geometry.frequency),
                 what=f"a ground surface {z_surface:.4g} m", escape=None)
    nearest = float(settings.z[np.argmin(np.abs(settings.z - depth))])
    if z_surface > nearest:
        import warnings

        warnings.warn(f"--z-surface {z_surface:.4g} m lies beyond the mapped plane "
                      f"({nearest:.4g} m): its depth is labelled negative, in the air",
                      PlausibilityWarning, stacklevel=2)


@click.command()
@click.argument("store", type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--range", "range_m", type=float, default=None,
              help="Range of the plane from the arrays (m); the stored plane nearest to it "
                   "is used (one outside the stored planes is refused).")
@click.option("--depth", type=float, default=None,
              help="Or the plane's depth below the ground's surface (m): needs --z-surface "
                   "(the range is --z-surface + --depth).")
@click.option("--pitch", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Pixel step of the map, m (default: the frames' pixel step).")
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The map: .png (a picture) or .nc (an image holoradar.load reads).")
@click.option("--db", "db_range", type=click.FloatRange(min=1), default=None,
              help="Draw 20 log10 |E| over this many dB (with .png).")
@click.option("--z-surface", type=float, default=None,
              help="Ground surface range, m: label the plane with its depth below it.")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@output_options
def mosaic(store: Path, range_m: float | None, depth: float | None, pitch: float | None,
           out: Path, db_range: float | None, z_surface: float | None, force: bool,
           report: Reporter) -> None:
    """Stitch a survey store into one plan-view map at a range (or a depth below the
    surface), overlapping frames blended."""
    from ...io import save
    from ...io.output import check_output
    from ...survey import mosaic as run
    from .. import plotting
    from ..atomic import write_atomic

    if (range_m is None) == (depth is None):
        raise click.BadParameter("give the plane as --range R (from the arrays, m) or as "
                                 "--depth D (below the ground's surface, m, with "
                                 "--z-surface)", param_hint="--range/--depth")
    if depth is not None and z_surface is None:
        raise click.BadParameter("a depth is below the ground's surface: give --z-surface "
                                 "(its range from the arrays), or --range for a range from "
                                 "the arrays", param_hint="--depth")
    name = "--range" if depth is None else "--depth"
    plane = range_m if depth is None else z_surface + depth
    check_output(out, suffixes=[".png", ".nc"], inputs=[store], overwrite=force, name="--out")
    _check_mosaic_options(store, plane, z_surface, name)
    img = run(store, plane, pitch=pitch)
    if out.suffix.lower() == ".nc":
        save(img, out, overwrite=force, history=[{"step": "mosaic", "input": store.name,
                                                  "parameters": {"range": plane,
                                                                 "depth": depth,
                                                                 "pitch": pitch}}])
    else:
        fig = plotting.plot_planes(img, [float(img.z[0])], db_range=db_range,
                                   z_surface=z_surface, title=f"{store.name}: mosaic")
        write_atomic(out, plotting.to_png(fig))
    pk = img.peak()
    report.done({"out": str(out), "plane_m": float(img.z[0]), "peak_m": list(pk),
                 "shape": list(img.data.shape)}, [
        f"mosaic of {store.name} at z = {float(img.z[0]) * 100:.1f} cm: "
        f"{img.x.size} x {img.y.size} pixels, brightest at x={pk[0] * 100:.1f} "
        f"y={pk[1] * 100:.1f} cm",
        f"wrote {out}",
    ], result=[f"wrote {out}"])


COMMANDS = [batch, mosaic]
