"""``holoradar simulate SCENE.toml -o holo.nc``."""

from __future__ import annotations

import time
from pathlib import Path

import click
import numpy as np

from .common import Reporter, output_options

__all__ = ["COMMANDS"]


@click.command()
@click.argument("scene_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="Output hologram, .nc (NetCDF-4; holoradar.load reads it).")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@output_options
def simulate(scene_file: Path, out: Path, force: bool, report: Reporter) -> None:
    """Simulate the hologram of a scene described in a TOML file.

    SCENE_FILE: frequency (Hz), [aperture] (n, pitch), optional [ground]
    (surface, eps, tan_delta or sigma, or [[ground.layer]] tables), [source]
    (plane, point or gaussian), [[target]] tables (point, or a planar shape) and
    [simulate] options (include_surface, include_direct, snr_db, seed); lengths
    in metres, angles in degrees. See docs/cli.md for a complete example.
    """
    from ...io import save
    from ...io.output import check_output
    from ...model.scene_file import load_scene
    from ...model.simulate import simulate as run

    check_output(out, suffixes=[".nc", ".nc4"], inputs=[scene_file], overwrite=force,
                 name="--out")
    spec = load_scene(scene_file)
    t0 = time.perf_counter()
    holo = run(spec.scene, spec.aperture, spec.frequency, progress=report.progress,
               **spec.options)
    seconds = time.perf_counter() - t0
    save(holo, out, overwrite=force,
         history=[{"step": "simulate", "parameters": {"scene": scene_file.read_text()},
                   "input": scene_file.name}])
    f = holo.frequencies
    s = {"out": str(out), "shape": list(holo.data.shape), "frequency_hz": f.tolist(),
         "pitch_m": list(holo.pitch), "targets": len(spec.scene.targets),
         "max_amplitude": float(np.abs(holo.data).max()), "seconds": seconds}
    report.done(s, [
        f"simulated {holo.data.shape[-1]} x {holo.data.shape[-2]} elements at "
        f"{f.size} frequenc{'y' if f.size == 1 else 'ies'} ({f.min() / 1e9:.4g}"
        f"{'' if f.size == 1 else f'-{f.max() / 1e9:.4g}'} GHz), {s['targets']} target(s), "
        f"in {seconds:.1f} s",
        f"wrote {out}",
    ], result=[f"wrote {out}"])


COMMANDS = [simulate]
