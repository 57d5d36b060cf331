"""``holoradar info FILE``: a table of what a file holds."""

from __future__ import annotations

import json
import sys
import textwrap
from pathlib import Path
from typing import Any

import click
import numpy as np

from .common import Reporter, output_options

__all__ = ["COMMANDS", "describe"]


def _span(v: np.ndarray) -> str:
    v = np.asarray(v, float)
    if v.size == 1:
        return f"{v[0]:.6g}"
    return f"{v[0]:.6g} .. {v[-1]:.6g} ({v.size}, step {(v[-1] - v[0]) / (v.size - 1):.6g})"


def describe(obj: Any) -> dict[str, Any]:
    """The facts ``info`` prints about a Hologram or Image."""
    from ...data.hologram import Hologram
    from ...data.plausibility import plausibility_problems

    f = np.atleast_1d(np.asarray(obj.frequency, float))
    d: dict[str, Any] = {
        "kind": type(obj).__name__,
        "shape": list(obj.data.shape),
        "dtype": str(obj.data.dtype),
        "x_m": [float(obj.x[0]), float(obj.x[-1]), int(obj.x.size)],
        "y_m": [float(obj.y[0]), float(obj.y[-1]), int(obj.y.size)],
        "frequency_hz": f.tolist(),
        "max_amplitude": float(np.abs(obj.data).max()),
    }
    if isinstance(obj, Hologram):
        d.update(pitch_m=list(obj.pitch), monostatic=obj.monostatic,
                 source=None if obj.source is None else repr(obj.source),
                 pose=None if obj.pose.is_identity else {
                     "center_m": list(obj.pose.center), "tilt_deg":
                     float(np.degrees(obj.pose.tilt)),
                     "azimuth_deg": float(np.degrees(obj.pose.azimuth))},
                 polarization=None if obj.polarization is None
                 else [float(v) for v in obj.polarization],
                 problems=plausibility_problems(obj))
    else:
        d.update(z_m=np.asarray(obj.z, float).tolist(), method=obj.method)
    return d


@click.command()
@click.argument("file", type=click.Path(exists=True, path_type=Path))
@click.option("--layout", default=None, metavar="KEY=VALUE,...",
              help="For a user's file: where the hologram is (see holoradar image --help).")
@output_options
def info(file: Path, layout: str | None, report: Reporter) -> None:
    """Show what FILE holds: its variables, and the hologram or image read from it.

    FILE may also be a survey store (a .zarr folder written by holoradar batch): its
    frames stored and missing, planes, grid and settings; a store with damaged frames
    (a chunk missing or failing its checksum) is described, its damaged frames named,
    and the command exits with code 2.
    """
    if file.is_dir():
        from .batch import store_info

        summary, lines = store_info(file)
        if not summary["damaged"]:
            report.done(summary, lines)
            return
        # Described, the damage said as the answer (one line on stderr), exit code 2;
        # with --json one object on stdout: the description with the error in it.
        names = ", ".join(m["name"] for m in summary["damaged"])
        msg = (f"store {file.name!r}: {len(summary['damaged'])} damaged frame(s): {names}: "
               "image them again with holoradar batch (a rerun repairs them)")
        report.done({**summary, "error": msg, "exit_code": 2}, lines)
        click.echo(f"error: {msg}", err=True)
        sys.exit(2)
    from ...io import load, read_history
    from ...io.readers import read_variables

    summary: dict[str, Any] = {"file": str(file), "bytes": file.stat().st_size}
    lines = [f"{file.name} ({file.stat().st_size} bytes)"]
    from ...io import is_holoradar_netcdf

    is_ours = file.suffix.lower() in (".nc", ".nc4") and is_holoradar_netcdf(file)
    obj, reason = None, None
    try:
        obj = load(file, layout=layout, check=False)
    except ValueError as exc:
        if is_ours:  # a damaged holoradar file: its error is the answer
            raise
        reason = str(exc)
    from ...io.gpr import GPR_SUFFIXES
    from ...io.layout import Layout

    wide = layout is not None and Layout.parse(layout).wide is not None
    gpr = file.suffix.lower() in GPR_SUFFIXES    # a GPR vendor's traces: no variables
    if (obj is None or not is_ours) and not wide and not gpr:   # nor a wide table
        variables = read_variables(file)
        summary["variables"] = {k: {"shape": list(v.shape), "dtype": str(v.dtype)}
                                for k, v in variables.items() if not k.startswith("__")}
        lines.append("  variables:")
        lines += [f"    {k:24s} {tuple(v.shape)!s:18s} {v.dtype}"
                  for k, v in variables.items() if not k.startswith("__")]
        if "__other__" in variables:
            lines.append(f"    (not numeric: {', '.join(map(str, variables['__other__']))})")
    if obj is None:
        summary["readable_as"] = None
        summary["reason"] = reason
        lines.append(f"  not readable as a hologram yet: {reason}")
        report.done(summary, lines)
        return
    d = describe(obj)
    summary["readable_as"] = d
    f = np.asarray(d["frequency_hz"])
    rows = [("kind", d["kind"]), ("shape", f"{tuple(d['shape'])} {d['dtype']}"),
            ("x (m)", _span(obj.x)), ("y (m)", _span(obj.y)),
            ("frequency (GHz)", _span(f / 1e9))]
    if d["kind"] == "Hologram":
        rows += [("pitch (mm)", f"{d['pitch_m'][0] * 1e3:.4g} x {d['pitch_m'][1] * 1e3:.4g}"),
                 ("monostatic", str(d["monostatic"])), ("source", str(d["source"])),
                 ("pose", str(d["pose"])),
                 ("polarization", "none (scalar model)" if d["polarization"] is None else
                  "E along (" + ", ".join(f"{v + 0.0:.4g}" for v in d["polarization"])
                  + ") (world axes)")]
    else:
        rows += [("z (m)", _span(np.asarray(d["z_m"]))), ("method", d["method"])]
    rows.append(("max |value|", f"{d['max_amplitude']:.4g}"))
    lines += [f"  {k:16s} {v}" for k, v in rows]
    for p in d.get("problems", []):
        lines.append(f"  implausible: {p}")
    if is_ours:
        try:
            hist = read_history(file)
        except (ValueError, OSError):
            hist = []
        summary["history"] = hist
        cut = False
        for step in hist:
            lines.append(f"  history: {step.get('step', step.get('name'))} "
                         f"{step.get('time', '')} "
                         f"(holoradar {step.get('holoradar', '?')})")
            text, short = _parameters(step)
            cut = cut or short
            lines += textwrap.wrap(text, 96, initial_indent=" " * 11,
                                   subsequent_indent=" " * 13, break_long_words=False)
        if cut:
            lines.append("  (--json shows every parameter whole)")
    report.done(summary, lines)


def _parameters(step: dict[str, Any]) -> tuple[str, bool]:
    """A history step's input and parameters on one line (unset ones left out), and
    whether a long value (a scene file's text) was shortened."""
    items = {"input": step.get("input"), **(step.get("parameters") or {})}
    parts, cut = [], False
    for key, value in items.items():
        if value is None:
            continue
        text = value if isinstance(value, str) else json.dumps(value)
        if "\n" in text:
            text, cut = f"<{len(text.splitlines())} lines>", True
        elif len(text) > 80:
            text, cut = text[:77] + "...", True
        parts.append(f"{key}={text}")
    return ", ".join(parts), cut


COMMANDS = [info]
