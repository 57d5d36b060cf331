"""Numbers for the screen: amplitude scales, sections and readouts of an image.

Pure functions of holoradar images, shared by the page and the PNG export so
that both show the same values. Amplitudes are ``|E|`` over a reference (the
brightest voxel of the depth sweep, so that one colour scale holds across
depths and between the plan view and the sections), linear or in dB
(``20 log10(|E| / ref)``, floored at ``-db_range``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...data.hologram import Image

__all__ = ["Peak", "distance", "peak_of", "scaled", "sections"]

CM = 100.0


def scaled(amplitude: np.ndarray, ref: float, scale: str, db_range: float) -> np.ndarray:
    """``amplitude / ref`` (linear) or its dB floored at ``-db_range`` (``scale="db"``).

    Examples
    --------
    >>> scaled(np.array([1.0, 0.1, 0.0]), 1.0, "db", 30.0).tolist()
    [0.0, -20.0, -30.0]
    """
    ref = float(ref) if ref > 0 else 1.0
    if scale == "linear":
        return amplitude / ref
    floor = 10 ** (-db_range / 20)
    return 20 * np.log10(np.maximum(amplitude / ref, floor))


def db(amplitude: np.ndarray, ref: float) -> np.ndarray:
    """``20 log10(amplitude / ref)``, -inf-free (floored at -300 dB)."""
    ref = float(ref) if ref > 0 else 1.0
    return 20 * np.log10(np.maximum(amplitude / ref, 1e-15))


@dataclass(frozen=True)
class Peak:
    """The brightest point of a plane: ``x``, ``y`` (m), ``z`` (range, m), ``level_db``
    (dB re the reference)."""

    x: float
    y: float
    z: float
    level_db: float


def peak_of(img: Image, ref: float) -> Peak:
    """The brightest point of a 2-D image, refined between pixels (a parabola through
    the log-intensities of the peak pixel and its neighbours).

    Examples
    --------
    >>> x = np.arange(9.0)
    >>> d = np.exp(-((x - 4.3) ** 2))[None, :] * np.ones((3, 1))
    >>> round(peak_of(Image(d, x, np.arange(3.0), np.array([0.5]), 1e9, has_z_axis=False),
    ...               1.0).x, 1)
    4.3
    """
    from ...analysis.metrics import peak_position

    x, y, z = peak_position(img)
    level = float(np.abs(img.data).max())
    return Peak(float(x), float(y), float(z), float(db(np.array(level), ref)))


def sections(volume: Image, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    """``|volume|`` on the vertical planes through ``(x, y)``: x-z at ``y`` (nz, nx) and
    y-z at ``x`` (nz, ny), from the nearest pixel row and column."""
    a = np.abs(volume.data)
    if not volume.has_z_axis:
        a = a[None]
    iy = int(np.argmin(np.abs(volume.y - y)))
    ix = int(np.argmin(np.abs(volume.x - x)))
    return a[:, iy, :], a[:, :, ix]


def distance(p: tuple[float, float, float], q: tuple[float, float, float]) -> float:
    """Straight-line distance between two points (x, y, depth), metres.

    Examples
    --------
    >>> distance((0.0, 0.0, 0.1), (0.03, 0.04, 0.1))
    0.05
    """
    return float(np.round(np.sqrt(sum((a - b) ** 2 for a, b in zip(p, q, strict=True))), 15))
