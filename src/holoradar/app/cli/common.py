"""What every command shares: --json/--quiet reporting, reading a hologram with a layout,
the ground from flags or a TOML file, depth ranges, safe outputs."""

from __future__ import annotations

import contextlib
import functools
import json
import math
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import click
import numpy as np

from ...data import range_checks
from ...data.range_checks import RangeError, array_of, scaled, warn_above_ground

__all__ = ["Reporter", "array_of", "check_ground", "check_planes", "check_ranges", "depth_ranges",
           "frame_option", "input_history", "layout_option", "medium_from_options",
           "medium_options", "output_options", "read_hologram", "refuse_outside_planes",
           "scaled", "warn_above_ground"]


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
        """Whether progress bars are shown: on a terminal's stderr only (a bar redraws
        its line with carriage returns: in a pipe or a log file it is hundreds of lines
        of noise), never with ``--quiet``."""
        import sys

        return not self.quiet and sys.stderr.isatty()

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
            from ...io.plain import plain

            click.echo(json.dumps(plain(summary), indent=2))
            return
        for text in (lines if not self.quiet or result is None else result):
            click.echo(text)


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


frame_option = click.option(
    "--frame", type=click.Choice(["aperture", "ground"]), default="aperture", show_default=True,
    help="Planes parallel to the array (aperture) or level planes in the ground's frame (for a "
         "tilted array; --z is then the world range).")
"""``--frame``: the imaging frame, shared by the commands that image or invert."""


def _crs(ctx: Any, param: Any, value: str | None) -> Any:
    from ...io.crs import as_crs

    if value is None:
        return None
    try:
        return as_crs(value, "--crs")
    except ValueError as exc:
        raise click.BadParameter(str(exc).removeprefix("--crs: "), param_hint="--crs") \
            from None


crs_option = click.option(
    "--crs", default=None, metavar="EPSG:CODE", callback=_crs,
    help="The projected coordinate reference system (metres: easting, northing) of the "
         "positions, e.g. EPSG:32633 (UTM 33N): GeoJSON is then WGS 84 longitude and "
         "latitude, as RFC 7946 requires.")
"""``--crs``: the positions' coordinate reference system, read by pyproj."""


def _upsample(ctx: Any, param: Any, value: str) -> int | str:
    text = str(value).strip().lower()
    if text == "auto":
        return "auto"
    try:
        n = int(text)
    except ValueError:
        n = 0
    if not 1 <= n <= 32:
        raise click.BadParameter(f"expected 'auto' or a whole number from 1 to 32, got "
                                 f"{value!r}", param_hint="--upsample")
    return n


upsample_option = click.option(
    "--upsample", default="auto", show_default=True, metavar="auto|N", callback=_upsample,
    help="Image pixels per element pitch: a number from 1 to 32, or 'auto': as many as "
         "give four pixels across the finest lateral resolution cell (lambda L / A, at "
         "least lambda / 2), 1 where the pitch is that fine already.")
"""``--upsample``: ``auto`` (sized by the resolution) or a factor."""


def resolve_upsample(upsample: int | str, holo: Any, zs: Any, medium: Any) -> int:
    """The factor ``--upsample`` gives for this hologram and these planes."""
    if upsample != "auto":
        return int(upsample)
    from ...imaging.migration.pixel_size import upsample_for

    return upsample_for(holo, zs, medium)


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
    @click.option("--frequency-file", type=click.Path(exists=True, dir_okay=False),
                  default=None,
                  help="A text file of the data's frequencies (one per line, Hz, or GHz "
                       "where only GHz fits): the layout's frequency list.")
    @click.option("--response", type=click.Path(exists=True, dir_okay=False), default=None,
                  help="A CSV table of the device's response per frequency (frequency, "
                       "re, im or amplitude, phase): each frequency divided by it.")
    @functools.wraps(fn)
    def wrapper(*args: Any, layout: str | None, no_check: bool, frequency_file: str | None,
                response: str | None, **kwargs: Any) -> Any:
        extra = []
        if frequency_file is not None:
            from ...io.response import read_frequencies

            try:
                f = read_frequencies(frequency_file)
            except ValueError as exc:
                raise click.BadParameter(str(exc), param_hint="--frequency-file") from None
            extra.append("frequency=[" + " ".join(repr(float(v)) for v in f) + "]")
            extra.append("frequency_unit=Hz")
        if response is not None:
            extra.append(f"response={response}")
        if extra:
            layout = ",".join([layout, *extra] if layout else extra)
        return fn(*args, layout=layout, check=not no_check, **kwargs)

    return wrapper


def read_hologram(path: Path, layout: str | None, check: bool, *, iq_check: bool = True) -> Any:
    """A hologram from any supported file; an image file is refused by name
    (:func:`holoradar.io.inputs.read_hologram`). ``iq_check=False``: the caller checks
    the I/Q sign itself, at the ranges it images."""
    from ...io.inputs import read_hologram as read

    return read(path, layout, check, iq_check=iq_check)


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
# (the checks are the library's, holoradar.data.range_checks; here their refusals become
# click errors of the option they name)

@contextlib.contextmanager
def _option_error() -> Iterator[None]:
    try:
        yield
    except RangeError as exc:
        raise click.BadParameter(str(exc), param_hint=exc.name) from None


def check_ranges(ranges: Any, text: str, name: str, aperture: float, frequency: float,
                 medium: Any = None, *, what: str | None = None, offset: float = 0.0,
                 escape: str | None = "--no-check") -> None:
    """:func:`holoradar.data.range_checks.check_ranges`; its refusal is a
    ``click.BadParameter`` of the option ``name``."""
    with _option_error():
        range_checks.check_ranges(ranges, text, name, aperture, frequency, medium, what=what,
                                  offset=offset, escape=escape)


def check_ground(medium: Any, spec: dict[str, Any], aperture: float, frequency: float, *,
                 escape: str | None = "--no-check") -> None:
    """:func:`holoradar.data.range_checks.check_ground`; its refusal is a
    ``click.BadParameter`` of the ground flag that gave the ground."""
    with _option_error():
        range_checks.check_ground(medium, spec, aperture, frequency, escape=escape)


def check_planes(holo: Any, zs: Any, text: str, medium: Any, spec: dict[str, Any],
                 check: bool, name: str = "--z") -> None:
    """:func:`holoradar.data.range_checks.check_planes`; its refusals are
    ``click.BadParameter`` of the option that gave the value."""
    with _option_error():
        range_checks.check_planes(holo, zs, text, medium, spec, check, name)


def refuse_outside_planes(value: float, planes: Any, name: str, what: str) -> None:
    """:func:`holoradar.data.range_checks.refuse_outside_planes`; its refusal is a
    ``click.BadParameter`` of the option ``name``."""
    with _option_error():
        range_checks.refuse_outside_planes(value, planes, name, what)
