"""``holoradar demo``, ``holoradar theory`` and ``holoradar plan-oblique``."""

from __future__ import annotations

import time
from pathlib import Path

import click
import numpy as np

from ..numbers import cm
from .common import Reporter, check_ranges, output_options, triple

__all__ = ["COMMANDS"]


@click.command()
@click.option("--out", default="demo_out", show_default=True,
              type=click.Path(file_okay=False, path_type=Path),
              help="Output folder (created if missing).")
@click.option("--upsample", default=8, show_default=True, type=click.IntRange(1, 32),
              help="Image pixels per element pitch.")
@click.option("--force", is_flag=True, help="Replace the demo's files in --out if they exist.")
@output_options
def demo(out: Path, upsample: int, force: bool, report: Reporter) -> None:
    """Simulate the paper's lab stand (letter R in sand) and image it.

    Writes figures, summary.json and the simulated hologram (hologram.nc) to
    OUT, so that `holoradar suppress OUT/hologram.nc ...` (its glare) and
    `holoradar image ...` can be tried next.
    """
    from ..demo import run_demo

    t0 = time.perf_counter()
    s = run_demo(out, upsample=upsample, overwrite=force)
    th = s["theory"]
    pc = s["image_peak_m"]["targets_only"]
    mf, me = s["glare"]["mirror_image_found_m"], s["glare"]["mirror_image_expected_m"]
    dz = th["longitudinal_resolution_m_in_ground"]
    wrote = f"wrote {len(s['files'])} files to {out}/ in {time.perf_counter() - t0:.1f} s"
    report.done({**s, "out": str(out), "seconds": time.perf_counter() - t0}, [
        "holoradar demo: paper lab stand, 16 x 16 array, 9.9 GHz, letter R 12 cm deep "
        "in sand (eps' 2.5, tan_delta 0.005)",
        f"  apparent distance L       {th['apparent_distance_m'] * 100:6.1f} cm "
        f"(true range {s['object']['range_m'] * 100:.1f} cm)",
        f"  lateral resolution        {th['lateral_resolution_m'] * 100:6.1f} cm (lambda*L/A)",
        f"  depth resolution (FWHM)   {dz * 100:6.1f} cm in the sand: at one frequency depth "
        "is barely resolved",
        f"  glare / object at array   {s['glare_to_object_ratio_db']:6.1f} dB",
        f"  image peak, targets only  x={cm(pc[0])} y={cm(pc[1])} "
        f"z={pc[2] * 100:.1f} cm",
        f"  glare: mirror image found x={cm(mf[0])} y={cm(mf[1])} cm at "
        f"z={mf[2] * 100:.0f} cm (expected x={cm(me[0])} y={cm(me[1])})",
        f"  array pitch exceeds lambda/2: waves beyond {th['max_unaliased_angle_deg']:.0f} "
        "degrees off axis alias",
        f"  {wrote}",
        # the glare first (the hologram holds no direct wave), else the image is the glare
        f"  next: holoradar suppress {out}/hologram.nc --eps 2.5+0.0125j --z-surface 0.30 "
        "--method image_source --no-direct -o clean.nc",
        "        holoradar image clean.nc --z 0.30:0.60:0.005 --eps 2.5+0.0125j "
        "--z-surface 0.30 -o img.nc",
    ], result=[wrote])


_POSITIVE = click.FloatRange(min=0, min_open=True)


@click.command(name="theory")
@click.option("--frequency", default=9.9e9, show_default=True, type=_POSITIVE, help="Hz (> 0).")
@click.option("--aperture", default=0.40, show_default=True, type=_POSITIVE,
              help="Full width of the array, m (> 0).")
@click.option("--distance", default=0.60, show_default=True, type=_POSITIVE,
              help="Range (apparent distance), m (> 0).")
@output_options
def theory_cmd(frequency: float, aperture: float, distance: float, report: Reporter) -> None:
    """Resolution and sampling figures for an aperture and range."""
    from ... import theory as th

    if frequency < 1e8:
        raise click.BadParameter(f"{frequency:g} Hz is below 100 MHz: given in GHz? (Hz "
                                 "expected, e.g. 9.9e9)", param_hint="--frequency")
    lam = th.wavelength(frequency)
    s = {
        "wavelength_m": lam,
        "lateral_resolution_m": th.lateral_resolution(lam, distance, aperture),
        "longitudinal_resolution_m": th.longitudinal_resolution(lam, distance, aperture),
        "fresnel_number": th.fresnel_number(aperture, lam, distance),
        "focal_shift_m": th.focal_shift(lam, distance, aperture),
    }
    report.done(s, [
        f"wavelength              {lam * 100:8.3f} cm",
        f"lateral resolution      {s['lateral_resolution_m'] * 100:8.3f} cm (lambda L / A)",
        f"longitudinal resolution {s['longitudinal_resolution_m'] * 100:8.3f} cm",
        f"Fresnel number          {s['fresnel_number']:8.3f}",
        f"focal shift             {s['focal_shift_m'] * 100:8.3f} cm",
    ])


@click.command(name="plan-oblique")
@click.option("--n", default=16, show_default=True, type=click.IntRange(2, 1024),
              help="Elements per side.")
@click.option("--pitch", default=0.025, show_default=True, type=_POSITIVE,
              help="Element pitch, m.")
@click.option("--center", default="0,-0.15,0.05", show_default=True,
              help="Array centre x,y,z (world, m; z the range below the reference plane).")
@click.option("--tilt", default=35.0, show_default=True, type=float, help="Degrees.")
@click.option("--azimuth", default=90.0, show_default=True, type=float, help="Degrees.")
@click.option("--horn", default="0,-0.08,0.25", show_default=True, help="Horn x,y,z (m).")
@click.option("--pattern", default=20.0, show_default=True, type=click.FloatRange(min=0),
              help="Horn pattern exponent m of cos^m.")
@click.option("--eps", default="2.5+0.0125j", show_default=True, help="Ground permittivity.")
@click.option("--z-surface", default=0.30, show_default=True, type=_POSITIVE,
              help="Ground surface range (m).")
@click.option("--target", default="0,0.05,0.42", show_default=True,
              help="Target x,y,z (m); the horn aims at it.")
@click.option("--frequency", default=9.9e9, show_default=True, type=_POSITIVE, help="Hz")
@click.option("--out", default=None, type=click.Path(dir_okay=False, path_type=Path),
              help="PNG of the layout with its rays.")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@output_options
def plan_oblique_cmd(n: int, pitch: float, center: str, tilt: float, azimuth: float, horn: str,
                     pattern: float, eps: str, z_surface: float, target: str, frequency: float,
                     out: Path | None, force: bool, report: Reporter) -> None:
    """Plan an oblique layout: where the horn's reflection falls, the glare fraction,
    the effective distance and resolution at the target."""
    from ...analysis.oblique_plan import plan_oblique
    from ...data.pose import Pose
    from ...io.output import check_output
    from ...model.scene import Aperture
    from ...model.scene_file import parse_complex
    from ...physics.medium import Medium
    from ...physics.sources import PointSource
    from .. import plotting
    from ..atomic import write_atomic

    c, hp, tg = triple(center, "--center"), triple(horn, "--horn"), triple(target, "--target")
    if out is not None:
        check_output(out, suffixes=[".png"], overwrite=force, name="--out")
    pose = Pose(c, tilt=np.radians(tilt), azimuth=np.radians(azimuth))
    ap = Aperture.grid(n, pitch, pose=pose)
    medium = Medium.half_space(z_surface, parse_complex(eps, "--eps"))
    # ranges from the array's centre, against its width (centimetres typed for metres)
    check_ranges(z_surface - c[2], f"{z_surface:g}", "--z-surface", n * pitch, frequency,
                 what=f"a ground surface {z_surface:.4g} m", escape=None)
    check_ranges(tg[2] - c[2], target, "--target", n * pitch, frequency, medium,
                 what=f"a target at range {tg[2]:.4g} m", escape=None)
    src = PointSource(hp, pattern_exponent=pattern, axis=tuple(np.subtract(tg, hp)))
    plan = plan_oblique(ap, src, medium, tg, frequency=frequency)
    if out is not None:
        fig = plotting.plot_oblique_plan(plan, ap, src, medium, tg)
        write_atomic(out, plotting.to_png(fig))
    s = {
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
    }
    sp = s["specular_point_m"]
    report.done(s, [
        f"specular point       x={cm(sp[0])} y={cm(sp[1])} z={cm(sp[2])} cm",
        f"miss distance        {s['miss_distance_m'] * 100:.1f} cm (> 0: the glare misses "
        "the array)",
        f"glare fraction       {s['glare_fraction']:.3f}",
        f"effective distance   {s['effective_distance_m'] * 100:.1f} cm",
        f"lateral resolution   {s['lateral_resolution_m'][0] * 100:.1f} x "
        f"{s['lateral_resolution_m'][1] * 100:.1f} cm",
        *([f"wrote {out}"] if out is not None else []),
    ])


COMMANDS = [demo, theory_cmd, plan_oblique_cmd]
