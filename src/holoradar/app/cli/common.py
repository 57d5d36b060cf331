"""What every command shares: --json/--quiet reporting, reading a hologram with a layout,
the ground from flags or a TOML file, depth ranges, safe outputs."""

from __future__ import annotations

import functools
import json
import math
import re
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import click
import numpy as np

__all__ = ["Reporter", "array_of", "check_ground", "check_planes", "check_ranges", "depth_ranges",
           "input_history", "layout_option", "medium_from_options", "medium_options",
           "output_options", "read_hologram", "refuse_outside_planes", "scaled",
           "warn_above_ground"]


class Reporter:
    """What a command prints: its lines, or with ``--json`` only the JSON summary on stdout.

    ``--quiet`` hides progress bars and the narrative lines, never the result: the
    lines a command names as its result (the files it wrote, the answer it found)
    are printed all the same, so that ``-q`` still says what came out.
    """

    def __init__(self, as_json: bool, quiet: bool) -> None:
        self.as_json, self.quiet = as_json, quiet

    @property
    def progress(self) -> bool:
        """Whether progress bars are shown (on stderr)."""
        return not self.quiet

    def line(self, text: str) -> None:
        """A narrative line (hidden by ``--quiet`` and ``--json``)."""
        if not (self.quiet or self.as_json):
            click.echo(text)

    def done(self, summary: dict[str, Any], lines: Sequence[str] = (),
             result: Sequence[str] | None = None) -> None:
        """Print the outcome: ``summary`` as JSON with ``--json``, else ``lines``.

        Parameters
        ----------
        summary : dict
            The machine-readable summary (``--json``).
        lines : sequence of str
            Every line for a person, in order.
        result : sequence of str, optional
            The lines that are the command's result, printed even with ``--quiet``
            (default: all of ``lines``, for commands whose every line is the answer).
        """
        if self.as_json:
            click.echo(json.dumps(_plain(summary), indent=2))
            return
        for text in (lines if not self.quiet or result is None else result):
            click.echo(text)


def _plain(v: Any) -> Any:
    if isinstance(v, dict):
        return {str(k): _plain(e) for k, e in v.items()}
    if isinstance(v, list | tuple):
        return [_plain(e) for e in v]
    if isinstance(v, np.ndarray):
        return _plain(v.tolist())
    if isinstance(v, complex | np.complexfloating):
        return {"re": float(v.real), "im": float(v.imag)}
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, Path):
        return str(v)
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def output_options(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``--json`` and ``--quiet``; the command receives ``report: Reporter``."""

    @click.option("--json", "as_json", is_flag=True,
                  help="Print a machine-readable JSON summary on stdout (and nothing else).")
    @click.option("--quiet", "-q", is_flag=True,
                  help="Print nothing but errors and warnings; no progress bars.")
    @functools.wraps(fn)
    def wrapper(*args: Any, as_json: bool, quiet: bool, **kwargs: Any) -> Any:
        return fn(*args, report=Reporter(as_json, quiet), **kwargs)

    return wrapper


def layout_option(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``--layout`` and ``--no-check`` for reading users' files."""

    @click.option("--layout", default=None, metavar="KEY=VALUE,...",
                  help="Where the hologram is in a user's file and in what units, e.g. "
                       "'data=E[1],units=mm,frequency=9.9,frequency_unit=GHz' or "
                       "'i=I,q=Q,axes=fyx' (keys: data, i, q, amplitude, phase, x, y, "
                       "frequency, pitch, axes, units, frequency_unit, phase_unit, iq_sign, "
                       "monostatic). A JSON sidecar FILE.json may hold it as \"layout\".")
    @click.option("--no-check", is_flag=True,
                  help="Skip the plausibility checks of units (pitch against wavelength, "
                       "frequency in Hz, all-zero data, ranges and ground against the array).")
    @functools.wraps(fn)
    def wrapper(*args: Any, layout: str | None, no_check: bool, **kwargs: Any) -> Any:
        return fn(*args, layout=layout, check=not no_check, **kwargs)

    return wrapper


def read_hologram(path: Path, layout: str | None, check: bool) -> Any:
    """A hologram from any supported file; an image file is refused by name."""
    from ...data.hologram import Hologram
    from ...io import load

    obj = load(path, layout=layout, check=check)
    if not isinstance(obj, Hologram):
        raise ValueError(f"{path.name} holds an image, not a hologram")
    return obj


def input_history(path: Path, layout: str | None) -> list[dict[str, Any]]:
    """The steps that made an input: its stored history (a holoradar file), else its import."""
    from ...io import read_history

    if path.suffix.lower() in (".nc", ".nc4") and layout is None:
        try:
            return [s for s in read_history(path) if isinstance(s, dict)]
        except (ValueError, OSError):
            pass
    return [{"step": "import", "input": path.name, "parameters": {"layout": layout}}]


def medium_options(fn: Callable[..., Any]) -> Callable[..., Any]:
    """The ground: a half-space from flags, layers from flags, or a TOML file."""

    @click.option("--eps", default=None, metavar="EPS",
                  help="Ground permittivity eps' or eps'+eps''j (loss positive), e.g. 2.5 or "
                       "2.5+0.0125j.")
    @click.option("--z-surface", type=float, default=None,
                  help="Range of the ground surface from the array plane, m.")
    @click.option("--tan-delta", type=click.FloatRange(min=0), default=None,
                  help="Loss tangent: eps = eps' (1 + i tan_delta).")
    @click.option("--sigma", type=click.FloatRange(min=0), default=None,
                  help="Conductivity, S/m: adds i sigma / (omega eps0) at the (centre) "
                       "frequency.")
    @click.option("--layers", default=None, metavar="TOP:EPS,...",
                  help="Layered ground, top-down: each layer's top range (m) and "
                       "permittivity, e.g. '0.30:5+0.1j,0.315:8+0.2j,0.335:12+0.5j'.")
    @click.option("--medium", "medium_file", default=None,
                  type=click.Path(exists=True, dir_okay=False, path_type=Path),
                  help="The ground from a TOML file: surface, eps[, tan_delta, sigma], or "
                       "[[layer]] tables with top, eps.")
    @functools.wraps(fn)
    def wrapper(*args: Any, eps: str | None, z_surface: float | None, tan_delta: float | None,
                sigma: float | None, layers: str | None, medium_file: Path | None,
                **kwargs: Any) -> Any:
        spec = {"eps": eps, "z_surface": z_surface, "tan_delta": tan_delta, "sigma": sigma,
                "layers": layers, "medium_file": medium_file}
        return fn(*args, medium_spec=spec, **kwargs)

    return wrapper


def ground_table_from_options(spec: dict[str, Any]) -> dict[str, Any] | None:
    """The ground the flags describe, as a scene file's ``[ground]`` table (``surface`` and
    ``eps``, or ``layer`` tables; a ``--medium`` file's own table); None: free space.

    Checks how the flags combine and their forms; :func:`medium_from_options` builds
    the medium from it (and checks the values).
    """
    import tomllib

    from ...model.scene_file import parse_complex
    from ...physics.medium import ground_permittivity_problem

    def permittivity(text: str, name: str, where: str = "") -> complex:
        # The one check of a typed permittivity (scene files use it too), judged as
        # typed, before --tan-delta or --sigma adds the loss.
        value = parse_complex(text, name)
        problem = ground_permittivity_problem(value)
        if problem is not None:
            raise click.BadParameter(where + problem, param_hint=name)
        return value

    eps, zs, td, sg = spec["eps"], spec["z_surface"], spec["tan_delta"], spec["sigma"]
    layers, mfile = spec["layers"], spec["medium_file"]
    given = [n for n, v in (("--eps", eps), ("--z-surface", zs), ("--layers", layers),
                            ("--medium", mfile)) if v is not None]
    if mfile is not None:
        if len(given) > 1 or td is not None or sg is not None:
            raise click.BadParameter("--medium describes the whole ground: give no other "
                                     "ground flag", param_hint="--medium")
        try:
            doc = tomllib.loads(Path(mfile).read_text(encoding="utf-8"))
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise ValueError(f"{Path(mfile).name} is not valid TOML ({exc})") from None
        return doc.get("ground", doc)  # its form is checked with the medium it makes
    loss = {k: v for k, v in (("tan_delta", td), ("sigma", sg)) if v is not None}
    if layers is not None:
        if eps is not None or zs is not None:
            raise click.BadParameter("give --layers or --eps with --z-surface, not both",
                                     param_hint="--layers")
        items = []
        for part in layers.split(","):
            top, sep, value = part.partition(":")
            try:
                top_m = float(top)
            except ValueError:
                top_m = math.nan
            if not sep or not math.isfinite(top_m):
                raise click.BadParameter(f"each layer is TOP:EPS (m, permittivity), got "
                                         f"{part!r}", param_hint="--layers")
            items.append({"top": top_m, "eps": permittivity(value, "--layers",
                                                            f"layer {len(items) + 1}: "),
                          **loss})
        return {"layer": items}
    if eps is None and zs is None:
        if loss:
            raise click.BadParameter("--tan-delta/--sigma need a ground: --eps and --z-surface",
                                     param_hint="--tan-delta/--sigma")
        return None
    if eps is None or zs is None:
        raise click.BadParameter("give both --eps and --z-surface, or neither",
                                 param_hint="--eps/--z-surface")
    return {"surface": zs, "eps": permittivity(eps, "--eps"), **loss}


def medium_from_options(spec: dict[str, Any], frequency: float) -> Any:
    """The Medium the flags describe (None: free space)."""
    from ...model.scene_file import medium_from_mapping

    table = ground_table_from_options(spec)
    if table is None:
        return None
    where = (Path(spec["medium_file"]).stem if spec["medium_file"] is not None
             else "--layers" if spec["layers"] is not None else "ground")
    return medium_from_mapping(table, frequency, where=where)


def depth_ranges(text: str, name: str = "--z") -> float | np.ndarray:
    """``0.4`` or ``start:stop:step`` (metres, step > 0, stop >= start)."""
    try:
        if ":" not in text:
            v = float(text)
            if not math.isfinite(v):
                raise ValueError
            return v
        a, b, st = (float(v) for v in text.split(":"))
    except ValueError:
        raise click.BadParameter(f"expected a range in metres or start:stop:step, got {text!r}",
                                 param_hint=name) from None
    if not (np.isfinite([a, b, st]).all() and st > 0 and b >= a):
        raise click.BadParameter(f"start:stop:step needs step > 0 and stop >= start, got "
                                 f"{text!r}", param_hint=name)
    if (b - a) / st > 100000:
        raise click.BadParameter(f"{text!r} asks for more than 100000 planes", param_hint=name)
    return np.arange(a, b + st / 2, st)


def triple(text: str, name: str) -> tuple[float, float, float]:
    """``x,y,z`` in metres."""
    try:
        v = tuple(float(t) for t in text.split(","))
    except ValueError:
        v = ()
    if len(v) != 3 or not all(math.isfinite(e) for e in v):
        raise click.BadParameter(f"expected x,y,z in metres, got {text!r}", param_hint=name)
    return v  # type: ignore[return-value]


# --- ranges against the array: a unit slip in an option is refused like one in a file ----

def array_of(holo: Any) -> tuple[float, float]:
    """The larger full width (n * pitch, m) and the highest frequency (Hz) of a hologram's
    array (of an image: of its pixels, which span the array)."""

    def width(v: np.ndarray) -> float:
        v = np.asarray(v, dtype=float)
        return float(np.ptp(v) * v.size / (v.size - 1)) if v.size > 1 else 0.0

    return max(width(holo.x), width(holo.y)), float(np.max(holo.frequency))


def scaled(text: str, factor: float) -> str:
    """An option's numbers divided by a unit factor: ``35:55:0.5`` / 100 is
    ``0.35:0.55:0.005`` (the form a user should have typed)."""
    return "".join(p if p in (":", ",") else f"{float(p) / factor:.6g}"
                   for p in re.split(r"([:,])", text.strip()))


def check_ranges(ranges: Any, text: str, name: str, aperture: float, frequency: float,
                 medium: Any = None, *, what: str | None = None, offset: float = 0.0,
                 escape: str | None = "--no-check") -> None:
    """Refuse ranges that no array of this width can focus (most likely centimetres or
    millimetres typed for metres), naming the option and the metres meant.

    Parameters
    ----------
    ranges : float or array_like
        The ranges from the array plane the option asks for, metres.
    text : str
        The option's value as typed (for the corrected example).
    name : str
        The option, e.g. ``"--z"``.
    aperture, frequency : float
        The array's larger width (m) and highest frequency (Hz).
    medium : Medium, optional
        The ground: ranges below it are judged by their apparent range.
    what : str, optional
        How the message names the ranges (default their span in metres).
    offset : float, optional
        The surface's range, for values that are depths below it.
    escape : str or None
        The flag that skips the check, named in the message.

    Raises
    ------
    click.BadParameter
    """
    from ...data.plausibility import range_problem, unit_slip

    problem = range_problem(ranges, aperture, frequency, medium, what, offset)
    if problem is None:
        return
    factor = unit_slip(ranges, aperture, frequency, medium, offset)
    raise click.BadParameter(problem + _advice(
        None if factor is None else f"{name} {scaled(text, factor)}", escape), param_hint=name)


def _advice(example: str | None, escape: str | None) -> str:
    """The way out of a refusal: the metres meant, and the flag that skips the check."""
    parts = ([f"give metres, e.g. {example}"] if example else []) + \
        ([f"{escape} takes the value as given"] if escape else [])
    return f" ({'; '.join(parts)})" if parts else ""


def _ground_flag(spec: dict[str, Any]) -> str:
    return ("--medium" if spec.get("medium_file") is not None else
            "--layers" if spec.get("layers") is not None else "--z-surface")


def check_ground(medium: Any, spec: dict[str, Any], aperture: float, frequency: float, *,
                 escape: str | None = "--no-check") -> None:
    """Refuse a ground whose surface or layers lie where the array focuses nothing
    (``--z-surface 30`` for 30 cm), naming the flag that gave it."""
    if medium is None or medium.is_free_space:
        return
    name = _ground_flag(spec)
    deepest = float(medium.z_interfaces[-1])
    if name == "--z-surface":
        check_ranges(deepest, f"{deepest:g}", name, aperture, frequency, medium,
                     what=f"a ground surface {deepest:.4g} m", escape=escape)
        return
    from ...data.plausibility import range_problem

    problem = range_problem(deepest, aperture, frequency, medium,
                            f"a layer top at {deepest:.4g} m")
    if problem is not None:
        raise click.BadParameter(problem + _advice(None, escape), param_hint=name)


def warn_above_ground(planes: Any, medium: Any, spec: dict[str, Any], name: str = "--z") -> None:
    """Warn when every plane lies in the air above the ground: it can be meant (looking
    at something above the surface), but the ground then plays no part."""
    if medium is None or medium.is_free_space:
        return
    z = np.atleast_1d(np.asarray(planes, dtype=float))
    surface = float(medium.z_interfaces[0])
    if z.max() < surface:
        from ...data.plausibility import PlausibilityWarning, _span

        warnings.warn(f"every plane of {name} ({_span(z)} m) lies above the ground surface "
                      f"at {surface:.4g} m ({_ground_flag(spec)}): the image is in air and "
                      "the ground plays no part", PlausibilityWarning, stacklevel=2)


def check_planes(holo: Any, zs: Any, text: str, medium: Any, spec: dict[str, Any],
                 check: bool, name: str = "--z") -> None:
    """The checks of an imaging command's ranges and ground against the hologram's array:
    :func:`check_ranges`, :func:`check_ground`, :func:`warn_above_ground` (none with
    ``--no-check``)."""
    if not check:
        return
    aperture, frequency = array_of(holo)
    check_ranges(zs, text, name, aperture, frequency, medium)
    check_ground(medium, spec, aperture, frequency)
    warn_above_ground(zs, medium, spec, name)


def refuse_outside_planes(value: float, planes: Any, name: str, what: str) -> None:
    """Refuse a range outside the planes a file or store holds (the nearest plane would
    be taken silently), naming the likely unit slip and the metres meant."""
    from ...data.plausibility import plane_problem

    problem = plane_problem(value, planes, what)
    if problem is None:
        return
    reason, factor = problem
    raise click.BadParameter(reason + _advice(
        f"{name} {value / factor:.6g}" if factor != 1.0 else None, None), param_hint=name)
