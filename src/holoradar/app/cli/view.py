"""``holoradar view`` (the browser viewer) and ``holoradar render`` (a saved look in batch)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click
import numpy as np

from .common import (
    Reporter,
    array_of,
    check_ground,
    check_ranges,
    layout_option,
    medium_options,
    output_options,
    refuse_outside_planes,
)

__all__ = ["COMMANDS", "ground_from_options"]


def ground_from_options(spec: dict[str, Any], frequency: float | None) -> dict[str, Any] | None:
    """The ground flags as a table of a scene file (``surface``/``eps`` or ``layer``), checked
    by building the medium; None without a ground.

    Parameters
    ----------
    spec : dict
        The medium options as the CLI parsed them (``eps``, ``z_surface``,
        ``tan_delta``, ``sigma``, ``layers``, ``medium_file``; metres).
    frequency : float or None
        Hz, for a loss given as a conductivity (default 10 GHz where unknown).

    Returns
    -------
    dict or None

    Raises
    ------
    click.BadParameter, ValueError
        A ground the medium options refuse, with their message.
    """
    from .common import ground_table_from_options, medium_from_options

    medium_from_options(spec, frequency or 1e10)  # the same checks and messages as elsewhere
    table = ground_table_from_options(spec)
    return None if table is None else dict(table)


@click.command()
@click.argument("files", nargs=-1, type=click.Path(exists=True, path_type=Path))
@medium_options
@click.option("--settings", "settings_file", default=None,
              type=click.Path(exists=True, dir_okay=False, path_type=Path),
              help="Start from a look saved by the page's 'export settings' (its files are "
                   "opened when no FILES are given).")
@click.option("--depth", type=float, default=None,
              help="First depth below the surface (range without a ground), m; default: "
                   "for holograms the brightest plane of the sweep (glare removed, see "
                   "--glare), for an image its middle plane, for a survey its first.")
@click.option("--glare", type=click.Choice(["off", "gaussian", "image_source", "cut"]),
              default=None, help="Glare suppression to start with; default: gaussian for "
                                 "holograms with a ground and a known horn, else off.")
@click.option("--host", default="127.0.0.1", show_default=True,
              help="Address to serve on. Anything but the loopback shows the data to the "
                   "network (a warning says so).")
@click.option("--port", default=0, type=click.IntRange(0, 65535),
              help="Port to serve on; default a free one.")
@click.option("--export-dir", default=None,
              type=click.Path(exists=True, file_okay=False, path_type=Path),
              help="Folder for the page's exports (default: the current folder).")
@click.option("--browser/--no-browser", default=True, show_default=True,
              help="Open the page in the default browser.")
@click.option("--objects", "objects_file", default=None,
              type=click.Path(exists=True, dir_okay=False, path_type=Path),
              help="Overlay and list the objects of a table written by `holoradar detect "
                   "-o` (.csv, .json or .geojson), in the same coordinates as the image.")
@click.option("--detect", "find", is_flag=True,
              help="Find the objects in the first plane shown (as the page's 'Find "
                   "objects' button): overlaid and listed.")
@layout_option
@output_options
def view(files: tuple[Path, ...], medium_spec: dict[str, Any], settings_file: Path | None,
         depth: float | None, glare: str | None, host: str, port: int,
         export_dir: Path | None, browser: bool, objects_file: Path | None, find: bool,
         layout: str | None, check: bool, report: Reporter) -> None:
    """Look at holograms, images or a survey in the browser, turning the knobs live.

    FILES: holograms (one per view of the scene: they are summed), or one
    image/volume file, or one survey store (.zarr). The page sweeps depth,
    removes the surface glare, sums views, shows sections, the spectral window,
    a cursor readout and distances, finds the objects in the plane shown (or
    shows those of --objects) as numbered markers and a list, and exports a PNG,
    the image (NetCDF) and the settings (TOML; `holoradar render` reproduces the
    image from it). Serves until Ctrl+C.
    """
    from ..view.server import open_in_browser, url_of
    from ..view.session import ViewSession
    from ..view.settings import read_settings

    base = read_settings(settings_file) if settings_file is not None else None
    paths = list(files) or ([Path(f) for f in base.files] if base is not None else [])
    if not paths:
        raise click.BadParameter("give the files to view (or --settings with files)",
                                 param_hint="FILES")
    for p in paths:
        if not p.exists():
            raise click.BadParameter(f"{p} does not exist", param_hint="FILES")
    objects = None
    if objects_file is not None:
        from ..view.objects import read_objects

        try:
            objects = read_objects(objects_file)
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint="--objects") from None
    session = ViewSession(paths, layout=layout, check=check)
    freq = float(np.mean(session.frequencies)) if session.frequencies.size else None
    ground = ground_from_options(medium_spec, freq)
    if session.kind != "holograms":
        # An image or a survey is shown as it is: the imaging's knobs do not apply.
        given = [n for n, v in (("the ground flags", ground is not None),
                                ("--glare", glare not in (None, "off"))) if v]
        if given:
            what = "an image" if session.kind == "image" else "a survey"
            raise click.BadParameter(f"{' and '.join(given)} apply to holograms; "
                                     f"{paths[0].name} holds {what}", param_hint="FILES")
    if base is not None:
        s = base.replace(files=tuple(str(p) for p in paths))
        if ground is not None:
            s = s.replace(ground=ground)
    else:
        s = session.default_settings(ground=ground)
    if glare is not None:
        s = s.replace(glare=glare)
    if check and session.kind == "holograms" and ground is not None:
        check_ground(session.medium(s), medium_spec, *array_of(session.views[0]))
    if depth is not None:
        if not math.isfinite(depth):
            raise click.BadParameter(f"expected a depth in metres, got {depth}",
                                     param_hint="--depth")
        _check_depth(session, s, depth, check)
        s = s.replace(depth=depth)
        if s.sweep is not None and not s.sweep[0] <= depth <= s.sweep[1]:
            # the slider spans the sweep: widen it to the depth asked for
            s = s.replace(sweep=(min(s.sweep[0], depth), max(s.sweep[1], depth)))
    if base is None:
        # the object rather than the glare: its suppression on where it can be done, the
        # brightest point's depth, unless asked otherwise
        s = session.opening_settings(s, glare=glare is None, depth=depth is None)
    session.medium(s)  # a bad ground fails here, before the server starts
    server = _serve(session, s, host, port, export_dir, objects, find)
    url = url_of(server, host)
    report.done({"url": url, "files": [str(p) for p in paths]},
                [f"holoradar view: serving {url} (Ctrl+C to stop)"])
    import sys

    sys.stdout.flush()
    if browser:
        open_in_browser(url)
    try:
        server.io_loop.start()
    except KeyboardInterrupt:
        # One line and exit code 130, as every command after Ctrl-C.
        raise KeyboardInterrupt("the viewer stopped (it writes only what you exported)") \
            from None
    finally:
        server.stop()


def _check_depth(session: Any, s: Any, depth: float, check: bool) -> None:
    """Refuse a --depth outside an image's or a survey's planes (the nearest would be
    shown silently), or one below the surface that the holograms' array cannot focus."""
    if session.kind == "image":
        refuse_outside_planes(depth, session.volume.z, "--depth", "image's planes")
    elif session.kind == "survey":
        refuse_outside_planes(depth, session.survey_z, "--depth", "stored planes")
    elif check:
        medium = session.medium(s)
        surface = session.surface(s)
        aperture, f_max = array_of(session.views[0])
        check_ranges(depth, f"{depth:g}", "--depth", aperture, f_max, medium,
                     what=f"a depth {depth:.4g} m below the surface at {surface:.4g} m"
                     if surface else None, offset=surface)


def _serve(session: Any, s: Any, host: str, port: int, export_dir: Path | None,
           objects: Any = None, find: bool = False) -> Any:
    """The started server, or a click error naming ``--host`` or ``--port``."""
    import errno
    import socket

    from ..view.server import make_server

    try:
        return make_server(session, s, host=host, port=port, export_dir=export_dir,
                           objects=objects, find=find)
    except ValueError as exc:
        raise click.BadParameter(str(exc).removeprefix("host: "), param_hint="--host") from None
    except OSError as exc:
        if isinstance(exc, socket.gaierror) or exc.errno == errno.EADDRNOTAVAIL:
            raise click.BadParameter(f"cannot serve on {host!r}: {exc.strerror or exc}",
                                     param_hint="--host") from None
        if port and exc.errno in (errno.EADDRINUSE, errno.EACCES):
            raise click.BadParameter(f"cannot serve on port {port}: {exc.strerror}"
                                     + (" (choose another, or leave --port out for a free one)"
                                        if exc.errno == errno.EADDRINUSE else ""),
                                     param_hint="--port") from None
        raise


@click.command()
@click.argument("settings_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The image shown by the look, .nc.")
@click.option("--png/--no-png", default=True, show_default=True,
              help="Also write the look's figure (plane and sections) beside --out.")
@click.option("--force", is_flag=True, help="Replace existing output files.")
@layout_option
@output_options
def render(settings_file: Path, out: Path, png: bool, force: bool, layout: str | None,
           check: bool, report: Reporter) -> None:
    """Reproduce a look saved by `holoradar view` ('export settings') in batch.

    SETTINGS_FILE: the TOML the page wrote (files, ground, depth, glare, views,
    frequencies, display). Writes the image the page showed and its figure.
    """
    from ...io import save
    from ...io.output import check_output
    from ..atomic import write_atomic
    from ..plotting import to_png
    from ..view.display import peak_of
    from ..view.export import look_figure, look_history
    from ..view.session import ViewSession
    from ..view.settings import read_settings

    s = read_settings(settings_file)
    if not s.files:
        raise click.BadParameter(f"{settings_file.name} names no files",
                                 param_hint="SETTINGS_FILE")
    inputs = [settings_file, *(Path(f) for f in s.files)]
    check_output(out, suffixes=[".nc", ".nc4"], inputs=inputs, overwrite=force, name="--out")
    if png:
        check_output(out.with_suffix(".png"), suffixes=[".png"], inputs=inputs,
                     overwrite=force, name="--out's PNG")
    for f in s.files:
        if not Path(f).exists():
            raise click.BadParameter(f"{f} (named in {settings_file.name}) does not exist",
                                     param_hint="SETTINGS_FILE")
    session = ViewSession([Path(f) for f in s.files], layout=layout, check=check)
    img = session.image(s)
    ref = float(np.abs(img.data).max()) or 1.0
    pk = peak_of(img, ref)
    fig_bytes = to_png(look_figure(session, s)) if png else None
    existed = out.exists()
    save(img, out, overwrite=force, history=look_history(s))
    files = [str(out)]
    if fig_bytes is not None:
        try:
            write_atomic(out.with_suffix(".png"), fig_bytes)
        except BaseException:
            if not existed:  # a new look is written whole or not at all
                out.unlink(missing_ok=True)
            raise
        files.append(str(out.with_suffix(".png")))
    surf = session.surface(s) if s.plane == "image" else 0.0
    report.done({"peak_m": [pk.x, pk.y, pk.z], "depth_m": pk.z - surf, "out": str(out),
                 "files": files}, [
        f"rendered {settings_file.name}: plane at range {float(img.z[0]) * 100:.1f} cm",
        f"brightest point x={pk.x * 100:.2f} y={pk.y * 100:.2f} cm, "
        f"{'depth' if s.ground is not None and s.plane == 'image' else 'range'} "
        f"{(pk.z - surf) * 100:.2f} cm",
        *[f"wrote {f}" for f in files]], result=[f"wrote {f}" for f in files])


COMMANDS = [view, render]
