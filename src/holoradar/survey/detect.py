"""The objects in a survey store, in survey coordinates, each once.

:func:`from_store` searches every finished frame: with its own hologram (the frame's
file, read again: each object fitted to it on all stored planes) or on one stored
plane from the images alone; the objects are placed in survey coordinates from the
frames' positions (:func:`to_survey`), each frame keeps those under its array, and
the rows of one object seen by several frames are joined into one
(:func:`~holoradar.survey.merge.merge`: a line's extent the union of its frames',
the frames it was seen in listed). ``holoradar detect STORE`` and the report's
survey sections are this.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from .merge import merge

__all__ = ["from_store", "merge", "to_survey"]

_STALE = ("is not the file the store was imaged from (changed since holoradar batch?): run "
          "holoradar batch again, or give --z RANGE to search one stored plane of each frame "
          "from the images alone")


def from_store(path: Path, plane: float | None, args: Mapping[str, Any], *,
               log: Callable[[str], None] | None = None) -> tuple[Any, dict[str, Any], Any]:
    """Every finished frame of a survey store searched, the objects in survey coordinates,
    duplicates merged.

    Parameters
    ----------
    path : Path
        The store (``.zarr`` from ``holoradar batch``).
    plane : float or None
        None: each frame fitted with its own hologram on all stored planes; else the one
        stored plane (range from the frames' arrays, m) searched from the images alone.
    args : mapping
        :func:`~holoradar.detect`'s other keywords (``false_alarm``, ``kinds``,
        ``eps_interval``; ``progress``: a bar over the frames, default after a second).
    log : callable, optional
        Told a line per frame (its number of objects).

    Returns
    -------
    table : pandas.DataFrame
        ``detect``'s columns and ``frame``; ``attrs["outlines"]`` the areas' outlines
        (world metres, keyed by row position).
    info : dict
        ``input``, ``frames`` (how many), ``model`` (``"hologram"`` or ``"window"``),
        ``plane_m`` and ``per_frame`` (each frame's name, array height, threshold, cells
        and resolution cell).
    medium : Medium or None
        The ground the store's frames were imaged through.

    Raises
    ------
    DetectionInputError
        A plane outside the stored planes (``"z"``).
    ValueError
        No finished frame; a frame's hologram that cannot be read or did not make its
        image (the message names the frame and the way out in the command line's words).
    """
    from ..analysis.detect.sources import refuse_outside
    from .store import read_index, stored_settings

    settings, _ = stored_settings(path)
    medium = settings.medium
    idx = read_index(path)
    frames = [i for i in range(idx["n"]) if idx["done"][i]]
    if not frames:
        raise ValueError(f"{path.name} holds no finished frame")
    if plane is not None:
        refuse_outside(plane, settings.z, "stored planes")
    from tqdm.auto import tqdm

    holograms = _holograms(idx, frames) if plane is None else {}
    tables = []
    # One bar over the frames (each frame's own inversion silent).
    args = dict(args)
    shown = args.pop("progress", None)
    args["progress"] = False
    # None: after a second of work, on a terminal only (a bar in a log is noise).
    with tqdm(total=len(frames), desc="detect (frames)", unit="frame", delay=1.0,
              disable=shown is False or (shown is None and not sys.stderr.isatty())) as bar:
        for i in frames:
            df = _frame_objects(path, i, idx, settings, holograms.get(i), plane, args)
            tables.append(df)
            bar.update(1)
            if log is not None:
                # the caller's own line (it knows --json and -q), the bar cleared
                # for it and drawn again below
                with bar.external_write_mode():
                    log(f"frame {idx['frame_name'][i]}: {len(df)} object(s)")
    merged = _gathered(tables)
    merged.attrs["eps_interval"] = None if args.get("eps_interval") is None else \
        list(args["eps_interval"])
    info = {"input": "survey", "frames": len(frames), "model": "hologram" if plane is None
            else "window", "plane_m": plane, "per_frame": [
                {"frame": str(idx["frame_name"][i]), "array_z_m": float(idx["frame_z"][i]),
                 "threshold": t.attrs.get("threshold"),
                 "n_cells": t.attrs.get("n_cells"), "resolution_cell": t.attrs.get(
                     "resolution_cell")} for i, t in zip(frames, tables, strict=True)]}
    return merged, info, medium


def _holograms(idx: dict[str, Any], frames: list[int]) -> dict[int, Any]:
    """Every frame's hologram, read before any is searched (a missing one stops all)."""
    from ..io import load

    holograms: dict[int, Any] = {}
    for i in frames:
        fp = str(idx["frame_path"][i])
        try:
            holograms[i] = load(fp)
        except (ValueError, OSError) as exc:
            raise ValueError(f"frame {idx['frame_name'][i]}'s hologram {fp} cannot be read "
                             f"({exc}): give --z RANGE to search one stored plane of each "
                             "frame from the images alone") from None
    return holograms


def _frame_objects(path: Path, i: int, idx: dict[str, Any], settings: Any, holo: Any,
                   plane: float | None, args: Mapping[str, Any]) -> Any:
    """Frame ``i``'s objects under its array, in survey coordinates, with the columns the
    merge needs (``frame``, ``_off``, ``_cell``, ``_outline``)."""
    import pandas as pd

    from ..analysis.detect.sources import detect_quietly, fit, from_array, level, options_of
    from .reader import frame_image

    img = frame_image(path, i)
    name = str(idx["frame_name"][i])
    medium = settings.medium
    if plane is None:
        c = holo.pose.center
        # The fit works in the frame's own coordinates (a level array at z = 0, the
        # ground seen from its height as migrate imaged it: the planes are ranges from
        # the array); the image's pixels are the frame's world position plus offsets.
        local = type(img)(img.data, img.x - c[0], img.y - c[1], img.z, img.frequency,
                          img.method, has_z_axis=True)
        opts = {"method": settings.method, **options_of(img)}
        flat, seen = level(holo, medium)
        df = fit(local, flat, seen, opts, args, f"frame {name}",
                 f"its hologram {idx['frame_path'][i]} {_STALE}")
        shift = (c[0], c[1])
    else:
        # The stored planes are ranges from the frame's array: its ground is seen from
        # the array's height (the frame's z).
        df = detect_quietly(img.plane(plane), medium=from_array(medium, float(idx["frame_z"][i])),
                            **args)
        shift = (0.0, 0.0)
    df = to_survey(df, shift)
    # Each frame reports the objects under its array: one beyond it is seen from the
    # side, fitted poorly, and left to the frame above it ...
    outlines = df.attrs.get("outlines") or {}
    df["_outline"] = pd.Series([outlines.get(n) for n in range(len(df))], index=df.index,
                               dtype=object)
    under = df["x"].between(img.x[0], img.x[-1]) & df["y"].between(img.y[0], img.y[-1])
    # ... and of those the ones nearer its centre than any other finished frame's: near
    # the array's edge an object beside it (seen from the side, beyond the image) leaves
    # pieces at the edge, where a neighbour sees the same place from above. A bar
    # crossing the frames lies near each frame's centre and is kept by each.
    done = np.flatnonzero(idx["done"])
    fx, fy = idx["frame_x"][done], idx["frame_y"][done]
    own = np.hypot(df["x"].to_numpy() - idx["frame_x"][i], df["y"].to_numpy()
                   - idx["frame_y"][i])
    if len(df) and done.size > 1:
        best = np.min(np.hypot(df["x"].to_numpy()[:, None] - fx[None],
                               df["y"].to_numpy()[:, None] - fy[None]), axis=1)
        # within half a cell of the boundary both frames keep it (the merge joins
        # them): a bar midway between two centres is not lost to the scatter of both
        # positions
        under &= own <= best + 0.5 * max(df.attrs["resolution_cell"][:2])
    df = df[under].reset_index(drop=True)
    df["frame"] = name
    df["_off"] = np.hypot(df["x"] - idx["frame_x"][i], df["y"] - idx["frame_y"][i])
    df["_cell"] = max(df.attrs["resolution_cell"][:2])
    return df


def _gathered(tables: list[Any]) -> Any:
    """The frames' tables as one, duplicates merged, the areas' outlines in ``attrs``."""
    import pandas as pd

    cols = [*tables[0].columns]
    full = pd.concat([t for t in tables if len(t)], ignore_index=True) if any(
        len(t) for t in tables) else pd.DataFrame(columns=cols)
    merged = merge(full)
    # The areas' outlines travel as a column through the concatenation and the merge.
    outlines = {n: o for n, o in enumerate(merged.pop("_outline")) if isinstance(o, list)} \
        if "_outline" in merged else {}
    merged.attrs = {"outlines": outlines}
    return merged


def to_survey(df: Any, shift: tuple[float, float]) -> Any:
    """A frame's table moved across by ``shift`` (its array's position, m): positions,
    line ends and the areas' outlines (in place; the table is returned)."""
    dx, dy = float(shift[0]), float(shift[1])
    if dx == 0.0 and dy == 0.0:
        return df
    for col in ("x", "x_start", "x_end"):
        df[col] = df[col] + dx
    for col in ("y", "y_start", "y_end"):
        df[col] = df[col] + dy
    df.attrs["outlines"] = {k: [[float(u) + dx, float(v) + dy] for u, v in ring]
                            for k, ring in df.attrs.get("outlines", {}).items()}
    return df
