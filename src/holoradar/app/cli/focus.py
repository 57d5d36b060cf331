"""``holoradar autofocus``: the ground's permittivity from a buried object's focus."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..numbers import cm
from .common import (
    Reporter,
    array_of,
    check_ground,
    check_ranges,
    layout_option,
    medium_from_options,
    medium_options,
    output_options,
    read_hologram,
)

__all__ = ["COMMANDS"]


def _pair(text: str, name: str, form: str = "MIN,MAX") -> tuple[float, float]:
    try:
        a, b = (float(v) for v in text.split(","))
    except ValueError:
        raise click.BadParameter(f"expected two numbers {form}, got {text!r}",
                                 param_hint=name) from None
    return a, b


@click.command()
@click.argument("hologram_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@medium_options
@click.option("--eps-range", default="1.5,16", show_default=True, metavar="MIN,MAX",
              help="Ground permittivities eps' searched.")
@click.option("--depth-range", default=None, metavar="MIN,MAX",
              help="Depths below the surface where the object may lie, m (default: half a "
                   "wavelength to 1.5 aperture widths, at least 0.5 m).")
@click.option("--at", "position", default=None, metavar="X,Y",
              help="Lateral position of the object to use, m (default: the brightest).")
@click.option("--glare", "glare", is_flag=True,
              help="The data still hold the surface glare: estimate eps' from it too, remove "
                   "it and combine both estimates.")
@click.option("--glare-estimate", default=None, metavar="EPS,SIGMA",
              help="Combine with an eps' estimate made elsewhere and its 1-sigma.")
@click.option("--fit", type=click.Choice(["field", "phase"]), default="field",
              show_default=True, help="Match the complex field, or its phases only (for "
                                      "arrays whose element amplitudes are not calibrated).")
@click.option("--target", type=click.Choice(["point", "line", "sphere"]), default="point",
              show_default=True,
              help="The object fitted: a compact one (a point, or a conducting sphere where "
                   "its size shows), a horizontal bar or pipe, or a conducting sphere (line "
                   "and sphere need a polarised hologram and source).")
@click.option("--line-radius", default=0.006, show_default=True,
              type=click.FloatRange(0, min_open=True), metavar="M",
              help="The bar's radius for --target line, m.")
@click.option("--sphere-radius", default=None, type=click.FloatRange(0, min_open=True),
              metavar="M", help="The sphere's radius for --target sphere, m (default: fitted).")
@click.option("--confidence", default=0.95, show_default=True,
              type=click.FloatRange(0, 1, min_open=True, max_open=True))
@click.option("--plot", "plot_file", default=None,
              type=click.Path(dir_okay=False, path_type=Path),
              help="Write a PNG of the residual against the trial eps'.")
@click.option("--force", is_flag=True, help="Replace --plot if it exists.")
@layout_option
@output_options
def autofocus(hologram_file: Path, medium_spec: dict[str, Any], eps_range: str,
              depth_range: str | None, position: str | None, glare: bool,
              glare_estimate: str | None, fit: str, target: str, line_radius: float,
              sphere_radius: float | None, confidence: float, plot_file: Path | None,
              force: bool, layout: str | None, check: bool, report: Reporter) -> None:
    """Find the ground permittivity that focuses a buried object best.

    The ground is a half-space: --z-surface is its range from the array, --eps
    the starting value (its loss tangent is kept; --tan-delta or --sigma set
    the loss). Prints eps' with its confidence interval and the object's
    position, or "not determinable" with the reason (exit code 0 either way).
    """
    from ...imaging.autofocus import autofocus as run
    from ...io.output import check_output

    if sphere_radius is not None and target != "sphere":
        raise click.BadParameter("--sphere-radius needs --target sphere (without it a "
                                 "sphere's radius is fitted)", param_hint="--sphere-radius")
    eps_pair = _pair(eps_range, "--eps-range")
    depth_pair = None if depth_range is None else _pair(depth_range, "--depth-range")
    at = None if position is None else _pair(position, "--at", "X,Y")
    if glare and glare_estimate:
        raise click.BadParameter("give --glare or --glare-estimate, not both",
                                 param_hint="--glare")
    glare_arg: Any = None
    if glare:
        glare_arg = True
    elif glare_estimate:
        glare_arg = _pair(glare_estimate, "--glare-estimate", "EPS,SIGMA")
    if plot_file is not None:
        check_output(plot_file, suffixes=[".png"], inputs=[hologram_file], overwrite=force,
                     name="--plot")
    holo = read_hologram(hologram_file, layout, check)
    if medium_spec["eps"] is None and medium_spec["z_surface"] is not None:
        medium_spec = {**medium_spec, "eps": "3"}  # only a start: eps' is what is sought
    medium = medium_from_options(medium_spec, float(np.mean(holo.frequencies)))
    if medium is None or medium.n_regions != 2:
        raise click.BadParameter("autofocus needs a half-space ground: give --z-surface (and "
                                 "optionally --eps as the start, --tan-delta or --sigma)",
                                 param_hint="--z-surface")
    if check:
        aperture, f_max = array_of(holo)
        check_ground(medium, medium_spec, aperture, f_max)
        if depth_pair is not None and depth_range is not None:
            surface = float(medium.z_interfaces[0])
            check_ranges(depth_pair, depth_range, "--depth-range", aperture, f_max, medium,
                         what=f"depths {depth_pair[0]:.4g}..{depth_pair[1]:.4g} m below the "
                              f"surface at {surface:.4g} m", offset=surface)
    res = run(holo, medium_model=medium, eps_range=eps_pair, depth_range=depth_pair,
              position=at, glare=glare_arg, fit=fit, confidence=confidence,
              target=target, line_radius=line_radius, sphere_radius=sphere_radius,
              progress=report.progress)
    files = []
    lines = [str(res), *([res.model_note] if res.model_note else []),
             *([res.crb_note] if res.crb_note else [])]
    if plot_file is not None:
        if res.eps_grid.size > 1:
            _plot(res, plot_file, hologram_file.name)
            files.append(str(plot_file))
        else:
            lines.append(f"no plot: the search stopped before a sweep of eps' "
                         f"({plot_file} not written)")
    # -q keeps the answer and what became of the plot asked for
    result = [*lines, *[f"wrote {f}" for f in files]]
    summary = {
        "determinable": res.determinable, "eps": res.eps,
        "eps_interval": res.eps_interval, "confidence": res.confidence,
        "eps_crb": res.eps_crb, "crb_note": res.crb_note,
        "reason": res.reason, "position_m": res.position, "depth_m": res.depth,
        "range_interval_m": res.range_interval, "eps_focus": res.eps_focus,
        "eps_glare": res.eps_glare, "eps_glare_std": res.eps_glare_std,
        "handle": res.handle, "focus_fraction": res.focus_fraction, "target": target,
        "line_azimuth_deg": res.line_azimuth_deg, "line_length_m": res.line_length,
        "sphere_radius_m": res.sphere_radius, "model_note": res.model_note,
        "evaluations": res.evaluations, "seconds": res.seconds, "files": files,
    }
    if res.position is not None:
        x, y, z = res.position
        lines.append(f"object at x={cm(x)} y={cm(y)} cm, range {cm(z)} cm")
    if res.line_azimuth_deg is not None and res.line_length is not None:
        lines.append(f"line azimuth {res.line_azimuth_deg:.1f} deg from +x, length "
                     f"{100 * res.line_length:.1f} cm")
    lines += [f"{res.eps_grid.size} trial eps', {res.evaluations} responses in "
              f"{res.seconds:.1f} s", *[f"wrote {f}" for f in files]]
    report.done(summary, lines, result=result)


def _plot(res: Any, path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..atomic import write_atomic

    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    ax.semilogy(res.eps_grid, np.maximum(1 - res.profile, 1e-16), "o-", ms=3)
    if res.eps_interval is not None:
        ax.axvspan(*res.eps_interval, alpha=0.25,
                   label=f"{100 * res.confidence:.0f}% interval: {res.eps_interval[0]:.3g} .. "
                         f"{res.eps_interval[1]:.3g}")
        ax.legend()
    ax.set_xscale("log")
    lo, hi = float(res.eps_grid.min()), float(res.eps_grid.max())
    ticks = [t for t in (1, 1.5, 2, 3, 4, 6, 8, 10, 16, 20, 30, 50) if lo <= t <= hi]
    ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
    ax.minorticks_off()
    ax.set_xlabel("trial ground permittivity eps'")
    ax.set_ylabel("residual energy / hologram energy (1 - F)")
    ax.set_title(f"autofocus {title}: " + (f"eps' = {res.eps:.3g}" if res.determinable
                                           else "not determinable"))
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120)
    plt.close(fig)
    write_atomic(path, buf.getvalue())


COMMANDS = [autofocus]
