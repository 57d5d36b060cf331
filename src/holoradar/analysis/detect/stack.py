"""A wideband volume without its hologram: each plane searched, one object per place.

Across a band the image focuses in range as well: an object's range profile (its
intensity along range at its lateral position) peaks at its range with a main
lobe of about one range cell,

    c_z = c0 / (2 n B),        B = N df (N frequencies df apart),

the two-way delay resolution in a ground of refractive index ``n``. Each plane is
searched on its own as a plane image (its noise, threshold and models as for one
plane), and the rows found at the same lateral place in several planes (the same
kind: points within a lateral cell, lines parallel and within a cell across, areas
within a cell or half their width) are one object, taken from the plane where it is
brightest; a point lying on a line (within a cell of its axis and extent: a piece
of it, or of a crossing bar, brighter on another plane) is part of that line, and
a point or a smaller area within a cell of a brighter area's outline is part of
that area (each plane explains an area by other components). Its
range is the maximum of its range profile, sampled from the volume
at its position (a line's or area's along its extent), refined by a parabola
through the logarithm of the three samples around it; its range standard deviation
is the Cramer-Rao bound of a peak of that main lobe, ``sqrt(3/(2 SNR)) c_z / pi``
(the bound of a ``sinc(pi z / c_z)`` peak in white noise, as laterally), the SNR
the object's.

False objects. A noise maximum of the volume above a threshold ``t`` is found in
the planes through it where it passes and merged into one object, so the distinct
false objects are the volume's noise maxima above ``t``: their expected number is
the 3-D expected Euler characteristic ``E3(t)`` (the volume's Lipschitz-Killing
curvatures, range included: :func:`~.noise.local_noise` on the whole volume). ``t``
solves ``E3(t) = false_alarm x (the volume's cells)``, and each plane is searched
with the rate per cell that gives it that threshold, ``E2(t) / (the plane's
cells)`` (its own 2-D curvatures). Searching each plane at the volume's
``false_alarm`` instead counted 2.4 times the nominal number on noise-only volumes:
a high threshold is crossed over less than a range cell, so a noise maximum is
found in fewer planes than a cell holds and the planes' maxima are more distinct
objects than the range cells suggest. Objects stacked at one
lateral place at several depths are one object here (the brightest); the
hologram's fit (``hologram=``) separates them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ...theory import range_resolution
from .areas import _inside
from .grid import Volume
from .table import cramer_rao_factor, depth_of

__all__ = ["detect_planes", "plane_rate", "range_cell"]


def range_cell(frequency: Any, eps: float) -> float:
    """The two-way range resolution ``c0 / (2 n N df)`` of a band, metres.

    Examples
    --------
    >>> round(range_cell(np.linspace(8e9, 12e9, 11), 1.0), 4)     # 11 x 0.4 GHz
    0.0341
    """
    f = np.sort(np.atleast_1d(np.asarray(frequency, float)))
    if f.size < 2:
        return np.inf
    # The band taken with one step more (each sample standing for its step): the
    # range focus's width of the plane-by-plane search.
    bandwidth = (f[-1] - f[0]) * f.size / (f.size - 1)
    return float(range_resolution(bandwidth, max(eps, 1.0)))


PlaneSearch = Callable[[Volume, float], tuple[list[dict[str, Any]], Any, str]]
"""Searches one plane at a false-alarm rate per cell: its rows, its CLEAN result and
the model's kind."""


def detect_planes(vol: Volume, run_plane: PlaneSearch, false_alarm: float,
                  medium: Any, interval: tuple[float, float] | None
                  ) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Search each plane with ``run_plane`` and merge the rows into objects (module notes).

    Returns
    -------
    rows : list of dict
        One per object, strongest first.
    meta : dict
        The table's attributes: the planes' median threshold, the resolution cell
        (x, y and the range cell), the cells searched (lateral times range), the model.
    """
    fa_plane, noise3 = plane_rate(vol, false_alarm)
    found: list[tuple[int, dict[str, Any]]] = []
    thresholds, lateral, cells, kind = [], [], [], "window"
    for iz in range(vol.z.size):
        plane = Volume(vol.data[iz:iz + 1], vol.x, vol.y, vol.z[iz:iz + 1], vol.frequency, True,
                       vol.method)
        rows, result, kind = run_plane(plane, fa_plane)
        thresholds.append(float(result.noise.t))
        lateral.append(float(result.noise.n_cells))
        cells.append(result.noise.cell[:2])
        found.extend((iz, r) for r in rows)
    z_mid = float(np.median(vol.z))
    eps = _eps_at(medium, z_mid)
    cz = range_cell(vol.frequency, eps)
    cx, cy = (float(np.median([c[i] for c in cells])) for i in (0, 1))
    cell = max(cx, cy)
    objects = _merge(found, cell)
    out = [_place(iz, row, vol, cz, medium, interval) for iz, row in objects]
    extent = float(vol.z[-1] - vol.z[0]) * vol.z.size / (vol.z.size - 1)
    n_range = max(extent / cz, 1.0) if np.isfinite(cz) else 1.0
    meta = {"threshold": float(np.median(thresholds)), "resolution_cell": [cx, cy, cz],
            "n_cells": float(noise3.n_cells), "model": f"{kind}, by planes",
            "planes": int(vol.z.size), "false_alarm_per_plane": fa_plane,
            "range_cells": n_range, "lateral_cells": float(np.mean(lateral))}
    return out, meta


def plane_rate(vol: Volume, false_alarm: float) -> tuple[float, Any]:
    """The per-plane rate per cell whose threshold keeps ``false_alarm`` per cell of the
    volume (module notes), and the volume's noise model.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> from scipy.ndimage import gaussian_filter
    >>> d = rng.normal(size=(24, 64, 64)) + 1j * rng.normal(size=(24, 64, 64))
    >>> d = gaussian_filter(d.real, 3) + 1j * gaussian_filter(d.imag, 3)
    >>> v = Volume(d, np.arange(64.0), np.arange(64.0), np.arange(24.0), None, False)
    >>> fa, _ = plane_rate(v, 1e-3)
    >>> bool(fa < 1e-3)           # a plane's rate is lower: the volume has more cells
    True
    """
    from .noise import expected_false_peaks, local_noise, threshold_resels

    empty = np.zeros(vol.data.shape[1:], bool)
    noise3 = local_noise(vol.data, empty, vol.x, vol.y, vol.z, false_alarm)
    t3 = threshold_resels(false_alarm * max(noise3.n_cells, 1.0), noise3.resels, noise3.n_ref)
    mid = vol.z.size // 2
    noise2 = local_noise(vol.data[mid:mid + 1], empty, vol.x, vol.y, vol.z[mid:mid + 1],
                         false_alarm)
    rate = expected_false_peaks(t3, noise2.resels, noise2.n_ref) / max(noise2.n_cells, 1.0)
    return float(min(max(rate, 1e-12), 0.1)), noise3


def _eps_at(medium: Any, z: float) -> float:
    if medium is None:
        return 1.0
    return float(np.real(medium.eps[int(medium.region_of(z))]))


def _same(a: dict[str, Any], b: dict[str, Any], cell: float) -> bool:
    """Whether two rows of different planes are the same object (module notes)."""
    if a["kind"] != b["kind"]:
        return False
    d = np.hypot(a["x"] - b["x"], a["y"] - b["y"])
    if a["kind"] == "point":
        return bool(d < cell)
    if a["kind"] == "area":
        return bool(d < max(cell, 0.5 * min(a.get("width", 0.0), b.get("width", 0.0))))
    shorter = max(min(a["length"], b["length"]), cell)
    tol = 2 * np.degrees(np.arctan2(cell, shorter))
    daz = abs((a["azimuth_deg"] - b["azimuth_deg"] + 90) % 180 - 90)
    if not daz < tol:
        return False
    u = np.radians(a["azimuth_deg"])
    across = abs(-(b["x"] - a["x"]) * np.sin(u) + (b["y"] - a["y"]) * np.cos(u))
    along = abs((b["x"] - a["x"]) * np.cos(u) + (b["y"] - a["y"]) * np.sin(u))
    return bool(across < cell and along < 0.5 * (a["length"] + b["length"]) + cell)


def _merge(found: list[tuple[int, dict[str, Any]]], cell: float
           ) -> list[tuple[int, dict[str, Any]]]:
    """The brightest row of each group of rows that are the same object."""
    order = sorted(found, key=lambda t: -t[1]["amplitude_db"])
    kept: list[tuple[int, dict[str, Any]]] = []
    for iz, row in order:
        if not any(_same(k, row, cell) for _, k in kept):
            kept.append((iz, row))
    lines = [k for _, k in kept if k["kind"] == "line"]
    kept = [(iz, r) for iz, r in kept
            if r["kind"] != "point" or not any(_on_line(r, ln, cell) for ln in lines)]
    # An area seen on several planes comes with different components each time: the
    # points and smaller areas within a cell of a brighter area's outline are it.
    out: list[tuple[int, dict[str, Any]]] = []
    for iz, r in kept:
        if r["kind"] in ("point", "area") and any(
                _in_area(r, a, cell) for _, a in out if a["kind"] == "area"):
            continue
        out.append((iz, r))
    return out


def _in_area(row: dict[str, Any], area: dict[str, Any], cell: float) -> bool:
    """Whether a row's position lies in an area's outline or within a cell of it."""
    ring = np.asarray(area.get("outline") or [], float)
    if ring.ndim != 2 or len(ring) < 3:
        return bool(np.hypot(row["x"] - area["x"], row["y"] - area["y"]) < cell)
    q = np.array([row["x"], row["y"]])
    if bool(_inside(ring, q[None])[0]):
        return True
    a, b = ring, np.roll(ring, -1, axis=0)
    ab = b - a
    t = np.clip(np.sum((q - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300),
                0.0, 1.0)
    return bool(np.min(np.hypot(*(a + t[:, None] * ab - q).T)) < cell)


def _on_line(p: dict[str, Any], line: dict[str, Any], cell: float) -> bool:
    """Whether a point lies on a line: within a cell of its axis and of its extent (a
    piece of it, or a crossing bar's, seen brighter on another plane)."""
    u = np.radians(line["azimuth_deg"])
    dx, dy = p["x"] - line["x"], p["y"] - line["y"]
    across = abs(-dx * np.sin(u) + dy * np.cos(u))
    along = abs(dx * np.cos(u) + dy * np.sin(u))
    return bool(across < cell and along < 0.5 * line["length"] + cell)


def _positions(row: dict[str, Any]) -> np.ndarray:
    """Lateral points along an object where its range profile is sampled."""
    if row["kind"] == "line":
        s = np.linspace(0.0, 1.0, 9)[:, None]
        a = np.array([row["x_start"], row["y_start"]])
        b = np.array([row["x_end"], row["y_end"]])
        return a + s * (b - a)
    if row["kind"] == "area" and row.get("outline"):
        ring = np.asarray(row["outline"], float)
        centre = np.array([row["x"], row["y"]])
        return np.vstack([centre, 0.5 * (ring + centre)])
    return np.array([[row["x"], row["y"]]])


def _place(iz: int, row: dict[str, Any], vol: Volume, cz: float, medium: Any,
           interval: tuple[float, float] | None) -> dict[str, Any]:
    """The object's range from its range profile, its depth and interval."""
    pts = _positions(row)
    ix = np.clip(np.rint((pts[:, 0] - vol.x[0]) / vol.dx).astype(int), 0, vol.x.size - 1)
    iy = np.clip(np.rint((pts[:, 1] - vol.y[0]) / vol.dy).astype(int), 0, vol.y.size - 1)
    profile = np.mean(np.abs(vol.data[:, iy, ix]) ** 2, axis=1)
    k = int(np.argmax(profile))
    z = float(vol.z[k])
    if 0 < k < profile.size - 1 and np.all(profile[k - 1:k + 2] > 0):
        a, b, c = np.log(profile[k - 1:k + 2])
        curv = a - 2 * b + c
        if curv < 0:
            d = float(np.clip(0.5 * (a - c) / curv, -0.5, 0.5))
            z = float(np.interp(k + d, np.arange(vol.z.size), vol.z))
    out = dict(row)
    snr = 10 ** (row["snr_db"] / 10) if np.isfinite(row["snr_db"]) else np.inf
    std = cramer_rao_factor(snr) * cz / np.pi if snr > 0 and np.isfinite(cz) else np.nan
    out["range"], out["range_std"] = z, std
    if medium is not None and medium.z_interfaces:
        out["depth"], out["depth_low"], out["depth_high"] = depth_of(z, std, medium,
                                                                     interval, True)
    return out
