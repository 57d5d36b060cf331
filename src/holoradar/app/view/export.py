"""What the viewer exports: a PNG of the look, the image as NetCDF, the settings TOML.

The same functions serve ``holoradar render`` (a look reproduced in batch).
Files are written whole to a hidden temporary file, then linked under the
first free name (``..._2.png`` when ``....png`` exists): an existing file is
never replaced.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ...data.hologram import Image
from .display import CM, peak_of, scaled, sections
from .session import ViewSession
from .settings import ViewSettings, settings_toml

__all__ = ["export_netcdf", "export_png", "export_settings", "look_figure", "look_history"]


def _write_new(folder: Path, stem: str, suffix: str, write: Callable[[Path], Any]) -> Path:
    """``write(tmp)`` to a hidden temporary file in ``folder``, then give it the first free
    name of ``stem{suffix}``, ``stem_2{suffix}``, ...: a hard link is refused by the
    system when the name exists, so no file is ever replaced, even one that appears
    meanwhile (where there are no hard links, the name is first claimed by creating
    it exclusively, empty, and the finished file renamed onto it). Returns the path
    written."""
    fd, tmp = tempfile.mkstemp(prefix=f".{stem}.", suffix=f".tmp{suffix}", dir=folder)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        write(tmp_path)
        i = 1
        while True:
            p = folder / (f"{stem}{suffix}" if i == 1 else f"{stem}_{i}{suffix}")
            try:
                os.link(tmp_path, p)
                return p
            except FileExistsError:
                i += 1
            except OSError:  # no hard links here (FAT, some network shares)
                try:  # claim the name, then rename the whole file onto it
                    open(p, "xb").close()
                except FileExistsError:
                    i += 1
                    continue
                try:
                    os.replace(tmp_path, p)
                except BaseException:
                    p.unlink(missing_ok=True)
                    raise
                return p
    finally:
        tmp_path.unlink(missing_ok=True)


def _stem(session: ViewSession, s: ViewSettings) -> str:
    base = session.paths[0].stem if session.paths else "view"
    what = "mirror" if s.plane == "mirror" else f"{s.depth * CM:.1f}cm".replace("-", "m")
    return f"{base}_{what}"


def _reference(session: ViewSession, s: ViewSettings, volume: Image) -> float:
    """The colour scale's 0 dB: the sweep's brightest voxel (the unsuppressed glare in the
    mirror-source plane), as on the page."""
    if s.plane == "mirror":
        return float(np.abs(session.mirror_plane(s.replace(glare="off")).data).max()) or 1.0
    return float(np.abs(volume.data).max()) or 1.0


def look_figure(session: ViewSession, s: ViewSettings) -> Any:
    """A matplotlib figure of the look: the plane and the two vertical sections, on the
    page's colour scale, labelled in cm."""
    from matplotlib.figure import Figure

    from ..._figures import edges as _edges
    from ...analysis.metrics import peak_position

    img = session.image(s)
    vol = session.sweep(s)
    ref = _reference(session, s, vol)
    surf = session.surface(s)
    lo, hi = (-s.db_range, 0.0) if s.scale == "db" else (0.0, 1.0)
    q = "|r|" if s.plane == "reflectivity" else "|E|"
    label = f"{q} (dB re sweep peak)" if s.scale == "db" else f"{q} / sweep peak"
    fig = Figure(figsize=(13, 4.6), layout="constrained")
    axs = fig.subplots(1, 3, width_ratios=[1.1, 1, 1])
    plane = scaled(np.abs(img.data), ref, s.scale, s.db_range)
    m = axs[0].pcolormesh(_edges(img.x) * CM, _edges(img.y) * CM, plane, cmap="inferno",
                          vmin=lo, vmax=hi, shading="flat")
    axs[0].set_aspect("equal")
    axs[0].set_xlabel("x (cm)")
    axs[0].set_ylabel("y (cm)")
    pk = peak_of(img, ref)
    if s.plane == "mirror":
        axs[0].set_title(f"mirror-source plane, range {float(img.z[0]) * CM:.1f} cm")
    else:
        word = "depth" if s.ground is not None else "range"
        if s.plane == "reflectivity":
            word = "reflectivity, " + word
        axs[0].set_title(f"{word} {(float(img.z[0]) - surf) * CM:.1f} cm; peak "
                         f"({pk.x * CM:.1f}, {pk.y * CM:.1f}) cm, {pk.level_db:.1f} dB")
    if session.kind != "survey":
        x, y = s.section if s.section is not None else peak_position(vol)[:2]
        xz, yz = sections(vol, x, y)
        zlab = "depth (cm)" if s.ground is not None else "range z (cm)"
        for ax, a, c, name, at in ((axs[1], xz, vol.x, "x", f"y = {y * CM:.1f}"),
                                   (axs[2], yz, vol.y, "y", f"x = {x * CM:.1f}")):
            ax.pcolormesh(_edges(c) * CM, _edges(vol.z - surf) * CM,
                          scaled(a, ref, s.scale, s.db_range), cmap="inferno", vmin=lo,
                          vmax=hi, shading="flat")
            ax.invert_yaxis()
            if s.plane != "mirror":
                ax.axhline((float(img.z[0]) - surf) * CM, color="cyan", ls="--", lw=0.8)
            ax.set_xlabel(f"{name} (cm)")
            ax.set_ylabel(zlab)
            ax.set_title(f"{name}-z section at {at} cm")
    else:
        for ax in axs[1:]:
            ax.set_axis_off()
    fig.colorbar(m, ax=axs, label=label, shrink=0.9)
    glare = "" if s.glare == "off" else f", glare removed ({s.glare})"
    n = len(session.selected(s)) if session.kind == "holograms" else 1
    fig.suptitle(f"{', '.join(p.name for p in session.paths)}: {n} view(s), {s.mode}"
                 f"{glare}")
    return fig


def look_history(s: ViewSettings) -> list[dict[str, Any]]:
    """The history entry saved with an exported image: the settings as TOML text."""
    return [{"step": "view", "parameters": {"settings_toml": settings_toml(s)}}]


def export_png(session: ViewSession, s: ViewSettings, folder: Path) -> Path:
    """Write the look's figure (:func:`look_figure`) as a PNG into ``folder``.

    Parameters
    ----------
    session : ViewSession
    s : ViewSettings
        The look.
    folder : Path
        An existing folder; the name is ``<first file>_<depth>cm.png``, or the first
        free ``..._2.png``, ``..._3.png``: no file is replaced.

    Returns
    -------
    Path
        The file written.
    """
    from ..atomic import write_atomic
    from ..plotting import to_png

    png = to_png(look_figure(session, s))
    return _write_new(folder, _stem(session, s), ".png", lambda p: write_atomic(p, png))


def export_netcdf(session: ViewSession, s: ViewSettings, folder: Path) -> Path:
    """Write the shown plane (the complex image, metres and hertz) as a holoradar NetCDF
    file into ``folder``, with the settings in its history.

    Parameters
    ----------
    session, s, folder
        As for :func:`export_png` (suffix ``.nc``).

    Returns
    -------
    Path
        The file written.
    """
    from ...io import save

    img = session.image(s)
    return _write_new(folder, _stem(session, s), ".nc",
                      lambda p: save(img, p, overwrite=True, history=look_history(s)))


def export_settings(s: ViewSettings, folder: Path) -> Path:
    """Write the settings as TOML (``holoradar render`` reads it) into ``folder``.

    Parameters
    ----------
    s : ViewSettings
    folder : Path
        File names in the TOML are relative to it where possible; the name is
        ``<first file>_look.toml`` or the first free ``..._2.toml``.

    Returns
    -------
    Path
        The file written.
    """
    from ..atomic import write_atomic

    stem = Path(s.files[0]).stem if s.files else "view"
    text = settings_toml(s, relative_to=folder).encode()
    return _write_new(folder, f"{stem}_look", ".toml", lambda p: write_atomic(p, text))
