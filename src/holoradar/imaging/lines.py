"""Parallel line scans (a survey of B-scans) into one volume: :func:`stack_lines`.

A 3-D GPR survey is often a set of parallel lines, each a transceiver pulled along
x at its own y, each starting where it started. Lines evenly spaced in y that share
their x positions are the rows of one grid: migrated together (the exact 3-D
migration, the fields' variation across the lines included). Otherwise each line
is imaged on its own (the exact 2-D migration: what does not vary along y, bars
and pipes across the lines) and its section placed at its y, on one x grid that
covers every line (each section interpolated onto it, linearly; zero where a line
has no data).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..data.hologram import Hologram, Image
from .migrate import migrate

__all__ = ["stack_lines"]


def stack_lines(lines: Sequence[Hologram], y: Sequence[float], z: Any, *,
                medium: Any = None, **migrate_options: Any) -> Image:
    """One volume ``(nz, ny, nx)`` from parallel line scans at ranges ``z``.

    Parameters
    ----------
    lines : sequence of Hologram
        Line scans along x (``Hologram(data[f, x], x, frequency=f, ...)``), the same
        frequencies, monostatic or not alike, and one pitch along x.
    y : sequence of float
        Each line's y, metres (distinct; the volume's y axis sorted).
    z : float or sequence of float
        Ranges, metres.
    medium : Medium, optional
        The ground.
    **migrate_options
        :func:`holoradar.migrate`'s other options (``upsample=``...).

    Returns
    -------
    Image
        ``(nz, ny, nx)``; ``method`` says how: ``"lines:3d"`` (evenly spaced lines on
        one x grid, migrated as one grid) or ``"lines:2d"`` (each line's section).

    Raises
    ------
    ValueError
        Not line scans, one line, lines of other frequencies, kinds or pitches,
        ``y`` not one distinct value per line.

    Examples
    --------
    >>> x = np.arange(16) * 0.02
    >>> f = np.linspace(1e9, 2e9, 8)
    >>> lines = [Hologram(np.ones((8, 16)), x, frequency=f, monostatic=True)] * 3
    >>> stack_lines(lines, [0.0, 0.05, 0.1], [0.1, 0.2]).method
    'lines:3d'
    """
    ys = _check(lines, y)
    order = np.argsort(ys)
    lines, ys = [lines[i] for i in order], ys[order]
    first = lines[0]
    same_x = all(h.x.size == first.x.size and np.allclose(h.x, first.x, rtol=0, atol=1e-9)
                 for h in lines)
    steps = np.diff(ys)
    if same_x and ys.size > 1 and np.allclose(steps, steps[0], rtol=1e-6, atol=0):
        data = np.concatenate([h.data for h in lines], axis=-2)
        grid = Hologram(data, first.x, ys, first.frequency, monostatic=first.monostatic,
                        source=first.source, tx_offset=first.tx_offset)
        img = migrate(grid, z, medium=medium, **migrate_options)
        return Image(img.data, img.x, img.y, img.z, img.frequency, "lines:3d",
                     has_z_axis=img.has_z_axis, history=img.history)
    sections = [migrate(h, z, medium=medium, **migrate_options) for h in lines]
    dx = min(float(s.x[1] - s.x[0]) for s in sections)
    x0 = min(float(s.x[0]) for s in sections)
    x1 = max(float(s.x[-1]) for s in sections)
    x = x0 + np.arange(round((x1 - x0) / dx) + 1) * dx
    nz = np.atleast_1d(sections[0].z).size
    out = np.zeros((nz, ys.size, x.size), dtype=sections[0].data.dtype)
    for j, s in enumerate(sections):
        sec = np.asarray(s.data).reshape(nz, s.x.size)
        inside = (x >= s.x[0] - 1e-9) & (x <= s.x[-1] + 1e-9)
        for iz in range(nz):
            out[iz, j, inside] = np.interp(x[inside], s.x, sec[iz].real) + \
                1j * np.interp(x[inside], s.x, sec[iz].imag)
    return Image(out, x, ys, sections[0].z, sections[0].frequency, "lines:2d",
                 has_z_axis=True, history=sections[0].history)


def _check(lines: Any, y: Any) -> np.ndarray:
    if not isinstance(lines, Sequence) or len(lines) < 2 or not all(
            isinstance(h, Hologram) and h.is_line for h in lines):
        raise ValueError("lines must be two or more line scans (Hologram(data[f, x], x, "
                         "frequency=f))")
    ys = np.asarray(y, dtype=float)
    if ys.shape != (len(lines),) or not np.all(np.isfinite(ys)) or np.unique(ys).size != ys.size:
        raise ValueError(f"y must hold one distinct position per line ({len(lines)}), "
                         f"metres, got {y!r}")
    first = lines[0]
    for i, h in enumerate(lines[1:], start=1):
        if h.nf != first.nf or not np.allclose(h.frequencies, first.frequencies, rtol=1e-9):
            raise ValueError(f"lines[{i}]: other frequencies than lines[0]'s")
        if h.monostatic != first.monostatic:
            raise ValueError(f"lines[{i}]: a transceiver's and a receiver's lines mixed")
        if not np.isclose(h.pitch[0], first.pitch[0], rtol=1e-6):
            raise ValueError(f"lines[{i}]: pitch {h.pitch[0]:.4g} m, lines[0]'s "
                             f"{first.pitch[0]:.4g} m (resample them to one)")
    return ys
