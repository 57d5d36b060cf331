"""``holoradar calibrate fit`` and ``holoradar calibrate apply``: a device's calibration."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import click
import numpy as np

from .common import Reporter, input_history, output_options, triple

__all__ = ["COMMANDS"]


_DEVICE_KEYS = ("device", "@device", "serial", "@serial", "device_id", "@device_id")


def file_device(path: Path) -> str | None:
    """The device identity a raw file records (a text variable or attribute ``device``,
    ``serial`` or ``device_id``, or the same key in its JSON sidecar), if any."""
    from ...io.readers import read_variables

    variables = dict(read_variables(path))
    side = path.with_suffix(".json")
    if side.is_file():
        import json

        try:
            doc = json.loads(side.read_text(encoding="utf-8"))
        except (ValueError, UnicodeDecodeError, RecursionError):
            doc = {}
        for k in _DEVICE_KEYS:
            if isinstance(doc, dict) and isinstance(doc.get(k), str):
                return doc[k]
    for k in _DEVICE_KEYS:
        v = variables.get(k)
        if v is not None and v.dtype.kind in "SU" and v.size == 1:
            return str(v.reshape(()).item())
    return None


def _device(path: Path, declared: str | None) -> str:
    """The device that recorded ``path``: the file's own record, checked against
    ``--device``; ``--device`` alone where the file records none."""
    recorded = file_device(path)
    if recorded is not None and declared is not None and recorded != declared:
        raise ValueError(f"{path.name} was recorded by device {recorded!r}, not {declared!r} "
                         "(--device)")
    if recorded is None and declared is None:
        raise click.BadParameter(f"{path.name} does not record its device: give --device",
                                 param_hint="--device")
    return recorded or declared  # type: ignore[return-value]


def _raw(path: Path, layout: str | None, device: str | None, check: bool) -> Any:
    """Raw I and Q frames from any readable file (the field read as I + iQ, as recorded),
    with the source the file records (a holoradar file's), if any."""
    from ...calibrate import RawFrames
    from ...io import load

    device = _device(path, device)
    h = load(path, layout=layout, check=check)
    if not hasattr(h, "pose") or not hasattr(h, "monostatic"):
        raise ValueError(f"{path.name} holds an image, not raw frames")
    return RawFrames(h.data.real, h.data.imag, h.x, h.y, h.frequency, device, source=h.source,
                     pose=None if h.pose.is_identity else h.pose)


def _horn(horn: str | None, pattern: float | None, axis: str | None, recorded: Any,
          where: str) -> Any:
    """The horn: the options, each one not given taken from the ``recorded`` source (a
    file's or a calibration's, described by ``where``); None when nothing is given or
    recorded.

    A horn's pattern and boresight are never assumed: a cos^2 horn tilted 27 degrees
    taken as isotropic along +z calibrates the amplitudes 5% RMS (15% at worst) wrong
    across the test bench's array (docs/calibration.md).
    """
    from ...physics.sources import PointSource

    if horn is None and pattern is None and axis is None:
        return recorded
    rec = recorded if isinstance(recorded, PointSource) else None
    if horn is None and rec is None:
        raise click.BadParameter(f"{where} records no horn: give its position, --horn x,y,z, "
                                 "with --pattern and --horn-axis", param_hint="--horn")
    position = rec.position if horn is None else triple(horn, "--horn")
    if pattern is None:
        if rec is None:
            raise click.BadParameter(f"{where} records no horn pattern: give --pattern (the "
                                     "exponent m of cos^m; 0 for an isotropic horn)",
                                     param_hint="--pattern")
        pattern = rec.pattern_exponent
    if axis is not None:
        boresight = triple(axis, "--horn-axis")
    elif rec is not None:
        boresight = tuple(rec.axis)
    elif pattern == 0:
        boresight = (0.0, 0.0, 1.0)  # an isotropic horn: its axis does not matter
    else:
        raise click.BadParameter(f"{where} records no horn boresight: give --horn-axis with "
                                 f"--pattern {pattern:g}", param_hint="--horn-axis")
    return PointSource(position, pattern_exponent=pattern, axis=boresight)


_LAYOUT_HELP = ("Where I and Q are in the files (see holoradar image --help); the field is "
                "read as I + iQ as recorded.")


@click.group()
def calibrate() -> None:
    """Fit a device's calibration from reference measurements, or apply one.

    A calibration is a file of its own (NetCDF-4) holding the device's identity;
    it is applied only to frames of that device, array and frequencies.
    """


@calibrate.command(name="fit")
@click.option("--device", default=None,
              help="The device's identity (serial number); default: what the files record "
                   "(a text variable or attribute device, serial or device_id).")
@click.option("--plate", "plates", nargs=2, multiple=True, metavar="FILE RANGE",
              help="Repeats of a metal plate parallel to the array at RANGE metres (its "
                   "front face). Give two plates about lambda/8 apart to detect the I/Q sign.")
@click.option("--empty", "empties", multiple=True,
              type=click.Path(exists=True, dir_okay=False, path_type=Path),
              help="Repeats with nothing in front of the array (the horn's direct wave only).")
@click.option("--dark", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None, help="Dark frames (transmitter off) for the DC offsets.")
@click.option("--horn", default=None,
              help="The horn's position x,y,z in metres (default: what the reference files "
                   "record; a holoradar file records its source).")
@click.option("--horn-axis", default=None,
              help="The horn's boresight x,y,z (default: what the files record; needed with "
                   "a --pattern above 0).")
@click.option("--pattern", default=None, type=click.FloatRange(min=0),
              help="Horn pattern exponent m of cos^m, 0 for an isotropic horn (default: what "
                   "the files record; needed otherwise).")
@click.option("--iq-sign", type=click.Choice(["detect", "I+iQ", "I-iQ"]), default="detect",
              show_default=True, help="The I/Q sign if known; detect needs two references.")
@click.option("--layout", default=None, metavar="KEY=VALUE,...", help=_LAYOUT_HELP)
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The calibration file, .nc.")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@output_options
def fit(device: str | None, plates: tuple[tuple[str, str], ...], empties: tuple[Path, ...],
        dark: Path | None, horn: str | None, horn_axis: str | None, pattern: float | None,
        iq_sign: str,
        layout: str | None, out: Path, force: bool, report: Reporter) -> None:
    """Fit a calibration: DC offsets, I/Q imbalance and sign, element gains, dead and
    noisy elements, the response of each frequency."""
    from ...calibrate import Reference, fit_calibration
    from ...calibrate.fit import plus_minus
    from ...io.output import check_output

    plate_files = []
    for f, r in plates:
        p = Path(f)
        if not p.is_file():
            raise click.BadParameter(f"{f!r} is not a file", param_hint="--plate")
        try:
            rng = float(r)
        except ValueError:
            raise click.BadParameter(f"the plate's range must be metres, got {r!r}",
                                     param_hint="--plate") from None
        plate_files.append((p, rng))
    inputs = [p for p, _ in plate_files] + list(empties) + ([dark] if dark else [])
    if not plate_files and not empties:
        raise click.BadParameter("give at least one reference: --plate FILE RANGE or --empty "
                                 "FILE", param_hint="--plate/--empty")
    check_output(out, suffixes=[".nc"], inputs=inputs, overwrite=force, name="--out")
    refs = []
    for p, kind, r in ([(p, "plate", r) for p, r in plate_files]
                       + [(p, "empty", None) for p in empties]):
        raw = _raw(p, layout, device, True)
        src = _horn(horn, pattern, horn_axis, raw.source, p.name)
        if src is None:
            raise click.BadParameter(f"{p.name} records no horn: give --horn x,y,z and "
                                     "--pattern m (0: isotropic), with --horn-axis x,y,z for a "
                                     "pattern", param_hint="--horn")
        refs.append(Reference(raw, kind, plate_range=r, source=src))
    dark_raw = None if dark is None else _raw(dark, layout, device, False)
    cal = fit_calibration(refs, dark=dark_raw, iq_sign=None if iq_sign == "detect" else iq_sign,
                          notes=f"holoradar calibrate fit from {[p.name for p in inputs]}")
    cal.save(out, overwrite=force)
    mask = np.asarray(cal.mask)
    s = {"out": str(out), "device": cal.device, "iq_sign": cal.iq_sign,
         "iq_gain": cal.iq_gain, "iq_phase_rad": cal.iq_phase,
         "dead_elements": int(np.sum(cal.dead)), "noisy_elements": int(np.sum(cal.noisy)),
         "flagged": int(mask.sum()), "provenance": cal.provenance}
    iq = cal.provenance["iq_imbalance"]
    gain = plus_minus(float(np.ravel(cal.iq_gain)[0]), iq["stderr_gain"][0])
    phase = plus_minus(float(np.degrees(np.ravel(cal.iq_phase)[0])),
                       float(np.degrees(iq["stderr_phase_rad"][0])))
    report.done(s, [
        f"calibration of {cal.device}: I/Q sign {cal.iq_sign}, Q gain {gain}, Q phase {phase} "
        f"deg (standard errors), {s['dead_elements']} dead and {s['noisy_elements']} noisy "
        "element(s) flagged",
        f"wrote {out}",
    ])


@calibrate.command(name="apply")
@click.argument("raw_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--calibration", "cal_file", required=True,
              type=click.Path(exists=True, dir_okay=False, path_type=Path),
              help="The device's calibration file (from calibrate fit).")
@click.option("--device", default=None,
              help="The identity of the device that recorded RAW_FILE (must be the "
                   "calibration's); checked against what the file records, if it does.")
@click.option("--horn", default=None,
              help="The horn's position x,y,z for these frames (default: what RAW_FILE "
                   "records, else the calibration's).")
@click.option("--horn-axis", default=None,
              help="The horn's boresight x,y,z (default: the recorded horn's).")
@click.option("--pattern", default=None, type=click.FloatRange(min=0),
              help="Horn pattern exponent (default: the recorded horn's).")
@click.option("--layout", default=None, metavar="KEY=VALUE,...", help=_LAYOUT_HELP)
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The calibrated hologram, .nc.")
@click.option("--force", is_flag=True, help="Replace --out if it exists.")
@output_options
def apply_cmd(raw_file: Path, cal_file: Path, device: str | None, horn: str | None,
              horn_axis: str | None, pattern: float | None, layout: str | None, out: Path,
              force: bool, report: Reporter) -> None:
    """Calibrate RAW_FILE's frames into a hologram that the other commands image."""
    from ...calibrate import Calibration
    from ...io import save
    from ...io.output import check_output

    check_output(out, suffixes=[".nc", ".nc4"], inputs=[raw_file, cal_file], overwrite=force,
                 name="--out")
    cal = Calibration.load(cal_file)
    raw = _raw(raw_file, layout, device, True)
    recorded, where = ((raw.source, raw_file.name) if raw.source is not None
                       else (cal.source, cal_file.name))
    src = _horn(horn, pattern, horn_axis, recorded, where)
    if src is not raw.source:
        raw = dataclasses.replace(raw, source=src)
    holo = cal.apply(raw)
    save(holo, out, overwrite=force,
         history=[*input_history(raw_file, layout), cal.history_step()])
    report.done({"out": str(out), "device": raw.device, "calibration": str(cal_file),
                 "shape": list(holo.data.shape)},
                [f"calibrated {raw_file.name} with {cal_file.name} ({cal.device})",
                 f"wrote {out}"])


COMMANDS = [calibrate]
