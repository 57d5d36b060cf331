"""The objects in a line scan's x-z section: what a rebar locator reports on one line.

A line scan images into one vertical section (``image.y`` one value). What crosses
the line (a bar, a pipe) is a compact spot in it; each one above the section's noise
is one row of kind ``"line"``, its axis across the scan (along y: azimuth 90 degrees
for a scan along x), at its x and range, with its depth below the surface and that
depth's interval. :func:`holoradar.rebar_layers` then counts the bars, their spacing
and their cover.

A wide band's spot is not a dot: across the scan it is fringed (the band's
wavelengths in the ground, a cell apart), and a point response computed for the
scan does not match a real reflector's (its own spectrum: a bar's, a pipe's), so it
is not subtracted (a CLEAN with it leaves fringes as strong as the spots). The
search is on the intensity averaged across one lateral resolution cell (the fringes
averaged out, a spot kept), each spot the largest within one and a half lateral
cells and half a range cell (:data:`NEIGHBOURHOOD`). An object's weaker copy at
twice its depth, under it, is its surface multiple, not an object
(:func:`~.multiples.split_multiples`).

The noise: away from its spots a migrated section is a complex Gaussian field, whose
intensity is exponential, its median ``sigma^2 ln 2``; averaged over a cell the
median rises towards ``sigma^2`` (a conservative estimate: the threshold rises with
it). The spots are far fewer than half the pixels, so the averaged intensity's median
over ``ln 2`` estimates ``sigma^2``. A spot must pass ``sigma^2 ln(N / p)`` (an
exponential's tail; the average's is thinner: conservative again), the level the
largest of the section's ``N`` resolution cells of pure noise passes with
probability ``p``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...data.hologram import C0
from ...theory import lateral_resolution, range_resolution
from .grid import Volume
from .table import cramer_rao_factor, depth_of, detection_row

__all__ = ["detect_section", "section_cells"]


def section_cells(x: np.ndarray, z: np.ndarray, frequency: Any, medium: Any
                  ) -> tuple[float, float]:
    """``(lateral, range)`` resolution cells of a line scan's section at its middle
    range, metres: ``lambda L / A`` (the scan's length ``A``, the centre frequency, the
    apparent distance ``L``, halved for the round trip; at least a quarter of the
    wavelength in the ground) and, across a band, ``c / (2 B n)`` (one frequency: the
    section's whole depth, no range focus)."""
    f = np.atleast_1d(np.asarray(frequency, float))
    zm = float(np.median(z))
    L = medium.apparent_distance(zm) if medium is not None else zm
    A = max(float(np.ptp(x)), 1e-9)
    eps = complex(medium.eps[int(medium.region_of(zm))]) if medium is not None else 1.0
    lam = C0 / float(np.mean(f))
    # A transceiver's round trip halves the paraxial lambda L / A; a scan much longer
    # than the depth sees every angle, and a quarter of the wavelength in the ground
    # is then the limit.
    lateral = max(lateral_resolution(lam, max(L, 1e-9), A) / 2,
                  lam / (4 * float(np.sqrt(eps).real)))
    if f.size < 2:
        return lateral, float(np.ptp(z)) or 1.0
    return lateral, float(range_resolution(float(np.ptp(f)), eps))


#: The neighbourhood a spot is the largest in: (lateral cells, range cells) each side.
NEIGHBOURHOOD = (1.5, 0.5)


def detect_section(vol: Volume, medium: Any, false_alarm: float, max_objects: int,
                   interval: tuple[float, float] | None
                   ) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Rows of ``detect``'s table for a line scan's section, and its attributes."""
    from scipy import ndimage

    from .multiples import split_multiples

    if np.atleast_1d(vol.frequency).size < 2:
        # One frequency has no range focus: a section's spots are its long range
        # response, and the noise is not the correlated field the threshold assumes.
        raise ValueError("image: a line scan's section at one frequency has no range "
                         "focus to find objects in; image a band of frequencies")
    S = np.asarray(vol.data).reshape(vol.z.size, -1, vol.x.size)[:, 0, :]
    cell, rcell = section_cells(vol.x, vol.z, vol.frequency, medium)
    S, x = _fine(S, vol.x, cell)
    vol = Volume(S[:, None, :], x, vol.y, vol.z, vol.frequency, vol.planar, vol.method)
    dx = float(np.ptp(vol.x)) / max(vol.x.size - 1, 1)
    dz = float(np.ptp(vol.z)) / max(vol.z.size - 1, 1)
    n_cells = max(1.0, float(np.ptp(vol.x)) / max(cell, dx)) * \
        max(1.0, float(np.ptp(vol.z)) / max(rcell, dz))
    E = ndimage.uniform_filter1d(np.abs(S) ** 2, max(1, round(cell / dx)), axis=1,
                                 mode="nearest")
    sigma2 = float(np.median(E)) / math.log(2)
    threshold = sigma2 * math.log(n_cells / min(0.5, false_alarm * n_cells))
    size = (2 * max(1, round(NEIGHBOURHOOD[1] * rcell / dz)) + 1,
            2 * max(1, round(NEIGHBOURHOOD[0] * cell / dx)) + 1)
    peaks = np.argwhere((E == ndimage.maximum_filter(E, size=size, mode="nearest"))
                        & (E > threshold))
    peaks = sorted(peaks.tolist(), key=lambda p: -E[p[0], p[1]])
    sigma = math.sqrt(sigma2)
    rows = [_row(vol, S, E, iz, ix, sigma, cell, rcell, medium, interval)
            for iz, ix in peaks[:max_objects]]
    multiples: list[dict[str, Any]] = []
    if medium is not None and medium.z_interfaces and np.atleast_1d(vol.frequency).size > 1:
        rows, multiples = split_multiples(rows, cell, rcell)
    meta = {"threshold": math.sqrt(threshold), "noise_std": sigma,
            "resolution_cell": [cell, None, rcell], "n_cells": n_cells,
            "model": "section (the intensity averaged over a lateral cell)",
            "multiples": [{k: float(m[k]) for k in ("x", "y", "depth")} for m in multiples]}
    return rows, meta


def _fine(S: np.ndarray, x: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """The section interpolated along x to at least four pixels per lateral cell (the
    zero padding of its spectrum, :func:`holoradar.physics.spectra.interpolate`): a
    section of one pixel per cell holds its spots' fringes as spots of their own."""
    from ...physics.spectra import interpolate

    dx = float(x[1] - x[0])
    u = max(1, math.ceil(4 * dx / cell))
    if u == 1:
        return S, x
    n = x.size
    fine = np.fft.ifft(interpolate(np.fft.fft(S, axis=-1), u, -1), axis=-1) * u
    return fine[:, :u * (n - 1) + 1], x[0] + np.arange(u * (n - 1) + 1) * dx / u


def _row(vol: Volume, S: np.ndarray, E: np.ndarray, iz: int, ix: int, sigma: float,
         cell: float, rcell: float, medium: Any, interval: tuple[float, float] | None
         ) -> dict[str, Any]:
    """A spot's row: its peak refined by a parabola through the neighbours of the
    averaged intensity (in x and in range), its standard deviations by the Cramer-Rao
    factor at its SNR."""
    a = np.abs(S)
    x = _vertex(vol.x, np.sqrt(E[iz]), ix)
    z = _vertex(vol.z, np.sqrt(E[:, ix]), iz)
    snr = float(E[iz, ix]) / sigma**2 if sigma > 0 else math.inf
    k = cramer_rao_factor(snr)
    depth, lo, hi = depth_of(z, rcell * k / math.pi, medium, interval,
                             np.atleast_1d(vol.frequency).size > 1)
    y0 = float(vol.y[0])
    return detection_row(
        "line", x, y0, z, depth=depth, depth_low=lo, depth_high=hi, length=math.nan,
        width=cell, azimuth_deg=90.0, amplitude_db=20 * math.log10(max(float(a[iz, ix]), 1e-300)),
        snr_db=10 * math.log10(snr) if snr > 0 else -math.inf,
        x_std=cell * k / math.pi, y_std=math.nan, range_std=rcell * k / math.pi)


def _vertex(axis: np.ndarray, values: np.ndarray, i: int) -> float:
    """The peak of a parabola through ``values[i-1:i+2]`` on a uniform ``axis`` (the
    sample itself at an edge or where the three do not curve down)."""
    if not 0 < i < axis.size - 1:
        return float(axis[i])
    a, b, c = (float(v) for v in values[i - 1:i + 2])
    curv = a - 2 * b + c
    if curv >= 0:
        return float(axis[i])
    d = float(np.clip(0.5 * (a - c) / curv, -0.5, 0.5))
    return float(axis[i] + d * (axis[i + 1] - axis[i]))
