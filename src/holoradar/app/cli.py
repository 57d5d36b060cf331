"""Command line: ``holoradar demo``, ``holoradar image`` and ``holoradar theory``."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import click
import numpy as np

__all__ = ["main"]


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="holoradar")
def main() -> None:
    """holoradar: holographic subsurface radar imaging and simulation."""


@main.command()
@click.option("--out", default="demo_out", show_default=True,
              type=click.Path(file_okay=False, path_type=Path), help="Output folder.")
@click.option("--upsample", default=8, show_default=True, type=click.IntRange(1, 32),
              help="Image pixels per element pitch.")
def demo(out: Path, upsample: int) -> None:
    """Simulate the paper's lab stand (letter R in sand) and image it."""
    from .demo import run_demo

    t0 = time.perf_counter()
    s = run_demo(out, upsample=upsample)
    th = s["theory"]
    pc = s["image_peak_m"]["targets_only"]
    mf, me = s["glare"]["mirror_image_found_m"], s["glare"]["mirror_image_expected_m"]
    click.echo("holoradar demo: paper lab stand, 16 x 16 array, 9.9 GHz, letter R 12 cm deep "
               "in sand (eps' 2.5, tan_delta 0.005)")
    click.echo(f"  apparent distance L       {th['apparent_distance_m'] * 100:6.1f} cm "
               f"(true range {s['object']['range_m'] * 100:.1f} cm)")
    click.echo(f"  lateral resolution        {th['lateral_resolution_m'] * 100:6.1f} cm "
               "(lambda*L/A)")
    dz = th["longitudinal_resolution_m_in_ground"]
    click.echo(f"  depth resolution (FWHM)   {dz * 100:6.1f} cm in the sand: at one frequency "
               "depth is barely resolved")
    click.echo(f"  glare / object at array   {s['glare_to_object_ratio_db']:6.1f} dB")
    click.echo(f"  image peak, targets only  x={pc[0] * 100:.1f} y={pc[1] * 100:.1f} "
               f"z={pc[2] * 100:.1f} cm")
    click.echo(f"  glare: mirror image found x={mf[0] * 100:.1f} y={mf[1] * 100:.1f} cm at "
               f"z={mf[2] * 100:.0f} cm (expected x={me[0] * 100:.1f} y={me[1] * 100:.1f})")
    click.echo(f"  array pitch exceeds lambda/2: waves beyond "
               f"{th['max_unaliased_angle_deg']:.0f} degrees off axis alias")
    click.echo(f"  wrote {len(s['files'])} files to {out}/ in {time.perf_counter() - t0:.1f} s")


@main.command()
@click.argument("hologram_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--z", "z", required=True, help="Range(s) in metres: 0.4 or 0.3:0.5:0.01.")
@click.option("--eps", default=None, help="Ground permittivity, e.g. 2.5+0.0125j.")
@click.option("--z-surface", type=float, default=None, help="Ground surface range (m).")
@click.option("--method", type=click.Choice(["angular", "fresnel"]), default="angular",
              show_default=True)
@click.option("--upsample", default=4, show_default=True, type=click.IntRange(1, 32))
@click.option("--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="Output image: .nc (NetCDF-4, holoradar.load reads it) or .npz; a PNG "
                   "of the brightest plane is written beside it.")
@click.option("--force", is_flag=True, help="Replace existing output files.")
def image(hologram_file: Path, z: str, eps: str | None, z_surface: float | None, method: str,
          upsample: int, out: Path, force: bool) -> None:
    """Migrate a hologram to range(s) Z.

    HOLOGRAM_FILE: a .nc file written by holoradar (holoradar.save, holoradar
    demo), or an .npz with the keys data (complex, ny x nx), x, y (metres) and
    frequency (Hz).
    """
    from ..data.hologram import Hologram
    from ..imaging.migrate import migrate
    from ..io import load, save
    from ..io.output import check_output
    from ..physics.medium import Medium
    from . import plotting
    from .atomic import write_atomic

    zs = _ranges(z)
    if (eps is None) != (z_surface is None):
        raise click.BadParameter("give both --eps and --z-surface, or neither",
                                 param_hint="--eps/--z-surface")
    try:
        # Outputs are checked before any work: never an input, never replaced unasked.
        check_output(out, suffixes=[".nc", ".npz"], inputs=[hologram_file], overwrite=force,
                     name="--out")
        check_output(out.with_suffix(".png"), suffixes=[".png"], inputs=[hologram_file],
                     overwrite=force, name="--out's PNG")
        if hologram_file.suffix.lower() == ".npz":
            with np.load(hologram_file, allow_pickle=False) as d:
                holo = Hologram(d["data"], d["x"], d["y"], float(d["frequency"]))
        else:
            holo = load(hologram_file)
            if not isinstance(holo, Hologram):
                raise ValueError(f"{hologram_file.name} holds an image, not a hologram")
        medium = None if eps is None else Medium.half_space(z_surface, complex(eps))
        img = migrate(holo, zs, medium=medium, method=method, upsample=upsample)
    except KeyError as exc:
        click.echo(f"error: {hologram_file.name} lacks the key {exc} (an .npz needs data, x, "
                   "y, frequency)", err=True)
        sys.exit(2)
    except ValueError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(2)
    from ..analysis.metrics import peak_position

    pk = peak_position(img)
    fig = plotting.plot_image([img.plane(pk[2])], [f"{hologram_file.name} ({method})"])
    if out.suffix.lower() == ".nc":
        save(img, out, overwrite=force,
             history=[{"step": "migrate", "parameters": {"z": z, "eps": eps,
                                                         "z_surface": z_surface,
                                                         "method": method,
                                                         "upsample": upsample},
                       "input": hologram_file.name}])
    else:
        import io

        buf = io.BytesIO()
        np.savez(buf, data=img.data, x=img.x, y=img.y, z=img.z, frequency=img.frequency)
        write_atomic(out, buf.getvalue())
    write_atomic(out.with_suffix(".png"), plotting.to_png(fig))
    click.echo(json.dumps({"peak_m": pk, "out": str(out)}))


def _ranges(text: str) -> float | np.ndarray:
    """``0.4`` or ``start:stop:step`` (metres, step > 0, stop >= start)."""
    try:
        if ":" not in text:
            return float(text)
        a, b, st = (float(v) for v in text.split(":"))
    except ValueError:
        raise click.BadParameter(f"expected a range in metres or start:stop:step, got {text!r}",
                                 param_hint="--z") from None
    if not (np.isfinite([a, b, st]).all() and st > 0 and b >= a):
        raise click.BadParameter(f"start:stop:step needs step > 0 and stop >= start, got "
                                 f"{text!r}", param_hint="--z")
    if (b - a) / st > 100000:
        raise click.BadParameter(f"{text!r} asks for more than 100000 planes",
                                 param_hint="--z")
    return np.arange(a, b + st / 2, st)


def _triple(text: str, name: str) -> tuple[float, float, float]:
    try:
        v = tuple(float(t) for t in text.split(","))
    except ValueError:
        v = ()
    if len(v) != 3:
        raise click.BadParameter(f"expected x,y,z in metres, got {text!r}", param_hint=name)
    return v  # type: ignore[return-value]


@main.command(name="plan-oblique")
@click.option("--n", default=16, show_default=True, type=click.IntRange(2, 1024),
              help="Elements per side.")
@click.option("--pitch", default=0.025, show_default=True, type=float, help="Element pitch, m.")
@click.option("--center", default="0,-0.15,0.05", show_default=True,
              help="Array centre x,y,z (world, m; z the range below the reference plane).")
@click.option("--tilt", default=35.0, show_default=True, type=float, help="Degrees.")
@click.option("--azimuth", default=90.0, show_default=True, type=float, help="Degrees.")
@click.option("--horn", default="0,-0.08,0.25", show_default=True, help="Horn x,y,z (m).")
@click.option("--pattern", default=20.0, show_default=True, type=float,
              help="Horn pattern exponent m of cos^m.")
@click.option("--eps", default="2.5+0.0125j", show_default=True, help="Ground permittivity.")
@click.option("--z-surface", default=0.30, show_default=True, type=float,
              help="Ground surface range (m).")
@click.option("--target", default="0,0.05,0.42", show_default=True,
              help="Target x,y,z (m); the horn aims at it.")
@click.option("--frequency", default=9.9e9, show_default=True, type=float, help="Hz")
@click.option("--out", default=None, type=click.Path(dir_okay=False, path_type=Path),
              help="PNG of the layout with its rays (not overwritten unless --force).")
@click.option("--force", is_flag=True, help="Overwrite --out if it exists.")
def plan_oblique_cmd(n: int, pitch: float, center: str, tilt: float, azimuth: float, horn: str,
                     pattern: float, eps: str, z_surface: float, target: str, frequency: float,
                     out: Path | None, force: bool) -> None:
    """Plan an oblique layout: where the horn's reflection falls, the glare fraction,
    the effective distance and resolution at the target (JSON; a figure with --out)."""
    from ..analysis.oblique_plan import plan_oblique
    from ..data.pose import Pose
    from ..model.scene import Aperture
    from ..physics.medium import Medium
    from ..physics.sources import PointSource
    from . import plotting
    from .atomic import write_atomic

    c, hp, tg = _triple(center, "--center"), _triple(horn, "--horn"), _triple(target, "--target")
    if out is not None and out.exists() and not force:
        raise click.BadParameter(f"{out} exists; pass --force to overwrite it",
                                 param_hint="--out")
    try:
        pose = Pose(c, tilt=np.radians(tilt), azimuth=np.radians(azimuth))
        ap = Aperture.grid(n, pitch, pose=pose)
        medium = Medium.half_space(z_surface, complex(eps))
        src = PointSource(hp, pattern_exponent=pattern,
                          axis=tuple(np.subtract(tg, hp)))
        plan = plan_oblique(ap, src, medium, tg, frequency=frequency)
    except ValueError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(2)
    if out is not None:
        fig = plotting.plot_oblique_plan(plan, ap, src, medium, tg)
        write_atomic(out, plotting.to_png(fig))
    click.echo(json.dumps({
        "specular_point_m": plan.specular_point.tolist(),
        "miss_distance_m": plan.miss_distance,
        "glare_fraction": plan.glare_fraction,
        "effective_distance_m": plan.effective_distance,
        "lateral_resolution_m": list(plan.lateral_resolution),
        "tilts_missing_deg": [float(np.degrees(plan.tilts_missing.min())),
                              float(np.degrees(plan.tilts_missing.max()))]
        if plan.tilts_missing.size else [],
        "horn_heights_missing_m": [float(plan.heights_missing.min()),
                                   float(plan.heights_missing.max())]
        if plan.heights_missing.size else [],
        **({"out": str(out)} if out is not None else {}),
    }, indent=2))


@main.command(name="theory")
@click.option("--frequency", default=9.9e9, show_default=True, type=float, help="Hz")
@click.option("--aperture", default=0.40, show_default=True, type=float, help="full width, m")
@click.option("--distance", default=0.60, show_default=True, type=float, help="range, m")
def theory_cmd(frequency: float, aperture: float, distance: float) -> None:
    """Print resolution and sampling figures for an aperture and range."""
    from ..analysis import theory as th

    lam = th.wavelength(frequency)
    click.echo(json.dumps({
        "wavelength_m": lam,
        "lateral_resolution_m": th.lateral_resolution(lam, distance, aperture),
        "longitudinal_resolution_m": th.longitudinal_resolution(lam, distance, aperture),
        "fresnel_number": th.fresnel_number(aperture, lam, distance),
        "focal_shift_m": th.focal_shift(lam, distance, aperture),
    }, indent=2))


if __name__ == "__main__":  # pragma: no cover
    main()
