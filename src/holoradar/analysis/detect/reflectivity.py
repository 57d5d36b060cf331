"""Objects found in the reflectivity: ``detect`` with the hologram, on every geometry.

With the hologram, the measurement is inverted on the image's grid
(:func:`holoradar.invert`): each voxel's Born scattering amplitude, the illumination
divided out, no sidelobes, no pull towards the array. Objects are then read off the
reflectivity, not off the adjoint image's amplitude:

* the voxels above the noise (``|r_j| c_j`` above the threshold that noise alone
  passes nowhere on the grid but with probability ``p``, ``c_j`` the operator's
  column norm; the sparse inversion keeps only such voxels) are joined into objects:
  each voxel climbs its column's energy to its range peak, and peaks join where they
  touch laterally and their ranges differ by at most half a range cell (a bar's
  voxels, kept sparsely along it, make one object; bars crossing at depths further
  apart than that stay two, where their voxels touch); the pieces of one bar (the
  crossing goes to the stronger bar) are joined along its axis before anything is
  judged on its energy;
* each object's position is its voxels' centroid weighted by ``|r|^2``; its lateral
  extents along and across its principal axis (weighted second moments, the full
  width ``sqrt(12)`` standard deviations of a uniform bar, at least one voxel) make
  it a line (longer than two cells and three times its width), an area (both extents
  over two cells) or a point;
* a point under a level array is refined by the exact point response fitted to the
  hologram (:class:`~.model.HologramModel`: no grid, the Cramer-Rao standard
  deviations, the fitted amplitude); elsewhere its position's standard deviation is
  that of a peak of the resolution cell's width at the object's SNR,
  ``cell sqrt(3 / (2 SNR)) / pi``, and the grid's ``pitch / sqrt(12)`` in quadrature;
* the amplitude is the object's Born amplitude, ``|sum_j r_j|``; its SNR
  ``sum |r_j c_j|^2 / sigma^2`` (the matched filter's).

The sparse inversion is used up to :data:`SPARSE_VOXELS` voxel-frequencies (it
resolves, and its support is the object); beyond, damped least squares, thresholded.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..._lazy import lazy_module
from ...imaging.inversion.noise import NoiseLevel, NoiseWarning, nearest_source, noise_std
from ...theory import resolution_cells
from .errors import HologramFitError
from .grid import Volume
from .multiples import line_offset, split_multiples
from .table import cramer_rao_factor, depth_of, detection_row

ndimage = lazy_module("scipy.ndimage")

__all__ = ["SPARSE_VOXELS", "detect_by_inversion"]

SPARSE_VOXELS = 3_000_000   # voxel-frequencies up to which the sparse method is used
GRID_CELLS = 0.5            # the inversion grid's pixel, in lateral resolution cells
#: The inversion's plane spacing, in range cells c / (2 B n). Range peaks closer than
#: half a range cell join (one object); on planes ``d`` apart each peak sits within
#: ``d / 2`` of its object and a dip needs a plane between two peaks, so two objects
#: ``s`` apart are told apart for certain when ``s - d >= max(1/2, 2 d)``: a quarter
#: cell separates objects 0.75 of a range cell apart (half a cell joined them).
RANGE_GRID_CELLS = 0.25
MAX_ITER = 300              # the sparse solver's steps in detect
PROBE_ITER = 100            # its steps where the first fit only measures the noise
LSQR_PROBE_ITER = 30        # least squares' steps for that (it converges in tens)
#: A weaker object within a resolution cell of a stronger one by more than this (the
#: energy, dB) is a fragment of it: the aperture's first sidelobe level.
FRAGMENT_DB = -13.3
#: An object whose brightest voxel's reflectivity lies further below the brightest
#: object's (dB) is not told from the operator's model error: full-wave objects
#: differ from its points by 5-15 % in amplitude, and the sparse fit spreads that
#: difference over voxels up to about -18 dB of the object that causes it.
DYNAMIC_RANGE_DB = -22.0
#: The operator's model error of a real object, in amplitude: full-wave objects differ
#: from its points by 5-15 % (cylinders, plates, spheres against the fixtures).
MODEL_ERROR = 0.15


def detect_by_inversion(vol: Volume, hologram: Any, medium: Any, options: dict[str, Any],
                        noise: float | None, interval: tuple[float, float] | None,
                        false_alarm: float, max_objects: int, progress: bool | None = False
                        ) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Rows of ``detect``'s table and its attributes (see the module docstring)."""
    from ...imaging.inversion.api import reflectivity

    if not hologram.pose.is_identity and not vol.method.endswith(":ground"):
        raise HologramFitError(
            "image must be in the ground frame of hologram's posed (tilted or moved) array: "
            "migrate(hologram, z, medium=medium, frame='ground', x=..., y=...); the "
            "reflectivity is inverted on its world planes", "tilted")
    _check_same_frequencies(vol, hologram)
    grid, level = _grid(vol, hologram, medium, options)
    model = None
    if level:
        from .model import HologramModel

        # The image must be this hologram's migration (checked on a few planes):
        # otherwise its planes and pixels say nothing of where the inversion looks.
        model = HologramModel(hologram, vol, medium, dict(options))
        model.start()
    rcell = _range_cell(hologram, medium, float(np.median(vol.z)))
    planes = _planes(vol.z, rcell if hologram.nf > 1 else 0.0)
    n_vox = planes.size * len(grid.get("y", vol.y)) * len(grid.get("x", vol.x))
    method = "sparse" if n_vox * hologram.nf <= SPARSE_VOXELS else "lsqr"
    cell = _lateral_cell(hologram, medium, float(np.median(vol.z)))
    n_cells = max(1.0, (np.ptp(vol.x) * np.ptp(vol.y)) / cell**2) * planes.size
    p = min(0.5, false_alarm * n_cells)
    zs = planes if not vol.planar else float(vol.z[0])
    if not hologram.monostatic and hologram.source is None:
        # The source unknown: its illumination taken as uniform (each object's amplitude
        # then carries it), said in the table's attributes.
        grid["illumination"] = "none"
    # Single precision: its relative 1e-7 lies far below any noise the threshold
    # admits, and halves the memory each of the solver's hundreds of steps moves.
    grid.setdefault("dtype", np.complex64)

    def invert(sigma: Any, steps: int | None) -> Any:
        return reflectivity(hologram, zs, medium=medium, method=method, progress=progress,
                            max_iter=steps,
                            false_alarm=p, need_source=False, noise=sigma, **grid)

    res = _invert_at_the_noise(invert, hologram, nearest_source(planes, medium), noise,
                               method)
    r = res.image
    data = r.data if r.has_z_axis else r.data[None]
    c = res.column_norms.reshape(data.shape)
    energy = (np.abs(data) * c) ** 2
    step = r.history[0]
    # The sparse solution's voxels each passed the threshold on their correlation with
    # the data (the soft threshold then shrank them by it); least squares' are kept
    # where they stand above it.
    support = np.abs(data) > 0 if method == "sparse" else energy > res.threshold**2
    # A bar's pieces (where bars cross, the stronger takes the crossing) are joined
    # first: a piece is weaker than the bar it crosses, the whole bar is not, and the
    # floor holds for the whole bar, not for each piece.
    objects = _join_collinear(_objects(data, support, r, cell, rcell, c), cell, rcell)
    objects = _join_collinear(_merge_fragments(objects, cell, rcell), cell, rcell)
    floor = _floor(res.threshold, step["residual"], step["noise_norm"],
                   sum(_energy(ob) for ob in objects))
    objects = [ob for ob in objects if _energy(ob) > floor]
    if objects:
        top = max(float(ob["w"].max()) for ob in objects)
        objects = [ob for ob in objects
                   if float(ob["w"].max()) >= 10 ** (DYNAMIC_RANGE_DB / 10) * top]
    objects = objects[:max_objects]
    rows = [_row(ob, res.sigma, medium, interval, hologram) for ob in objects]
    if model is not None and any(row["kind"] == "point" for row in rows):
        _refine_points(rows, model, medium, interval, hologram.nf > 1)
    multiples: list[dict[str, Any]] = []
    if medium is not None and medium.z_interfaces and hologram.nf > 1:
        rows, multiples = split_multiples(rows, cell, rcell)
    _spacing(rows)
    meta = {"threshold": float(res.threshold), "noise_std": float(res.sigma),
            "resolution_cell": [cell, cell, rcell if hologram.nf > 1 else None],
            "n_cells": float(n_cells),
            "model": f"reflectivity:{method}", "inversion": dict(step),
            "illumination": grid.get("illumination", "field"),
            "model_error_floor": float(floor),
            # Surface multiples recognised (not objects): where, and whose.
            "multiples": [{**{k: float(m[k]) for k in ("x", "y", "depth")}, "kind": m["kind"],
                           **{f"of_{k}": float(rows[m["multiple_of"]][k])
                              for k in ("x", "y", "depth")}} for m in multiples]}
    return rows, meta


def _invert_at_the_noise(invert: Any, hologram: Any, z_min: float, noise: Any,
                         method: str) -> Any:
    """The inversion at the receiver noise: given, estimated from the data (found once,
    its warning said once, passed on as found), or, where it can only be assumed, what
    a first fit leaves of the data: noise and the model's error together, a noise no
    lower than the true one (fewer steps leave more: the probe errs high, towards
    missing a weak object rather than reporting the noise's pieces), then the
    inversion again with it (a noise set too low is fitted, and spurious pieces
    follow). ``invert(noise, steps)`` runs the inversion."""
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always", NoiseWarning)
        level = NoiseLevel(*noise_std(hologram, z_min, noise))
        assumed = level.how.startswith("assumed")
        res = invert(level, (PROBE_ITER if assumed else MAX_ITER) if method == "sparse"
                     else (LSQR_PROBE_ITER if assumed else None))
    if assumed:
        step = res.image.history[0]
        sigma = max(res.sigma, step["residual"] / math.sqrt(hologram.data.size))
        res = res.again(sigma) if method == "sparse" else invert(sigma, None)
        res.image.history[0]["noise"] = ("the residual of a first inversion with the "
                                         "noise assumed 40 dB below the data's power")
    for w in said:
        if not issubclass(w.category, NoiseWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return res


def _check_same_frequencies(vol: Volume, hologram: Any) -> None:
    """The image's frequencies (where it carries them) must be the hologram's: another
    band images other objects, and the inversion would look where the image does not."""
    if vol.frequency is None:
        return
    fi = np.atleast_1d(np.asarray(vol.frequency, float)).ravel()
    fh = np.atleast_1d(np.asarray(hologram.frequencies, float)).ravel()
    if fi.size == fh.size and np.allclose(fi, fh, rtol=1e-9, atol=0):
        return

    def say(f: np.ndarray) -> str:
        return (f"{f.size} frequencies {f.min() / 1e9:.4g}-{f.max() / 1e9:.4g} GHz"
                if f.size > 1 else f"one frequency {f[0] / 1e9:.4g} GHz")

    raise HologramFitError(f"hologram does not match image: its {say(fh)} are not the "
                           f"image's {say(fi)}; pass the hologram the image was migrated "
                           "from (or leave hologram out)", "frequency")


def _planes(z: np.ndarray, range_cell: float) -> np.ndarray:
    """The image's planes the inversion is solved on: across a band, every plane up to
    :data:`RANGE_GRID_CELLS` of a range cell apart, more finely sampled ones thinned to
    that (finer planes make nearly parallel columns, which cost steps and spread an
    object over them), the first and the last kept; one frequency (``range_cell`` 0):
    every plane."""
    z = np.atleast_1d(np.asarray(z, float))
    if z.size < 3 or not range_cell > 0:
        return z
    step = max(1, math.floor(RANGE_GRID_CELLS * range_cell / float(np.min(np.diff(z)))))
    keep = np.unique(np.r_[np.arange(0, z.size, step), z.size - 1])
    return z[keep]


def _floor(threshold: float, residual: float, noise_norm: float, found: float) -> float:
    """The energy ``sum_j |r_j c_j|^2`` an object needs: above the noise's threshold
    squared, and above what the fit leaves unexplained beyond the noise,
    ``|A r - d|^2 - M sigma^2`` (the model's error: the sparse fit explains part of it
    by small spurious objects, each weaker than what it leaves) -- but not above the
    model's error of what was found, :data:`MODEL_ERROR` squared times the objects'
    energy ``found``: the rest of the residual is what the grid cannot hold (objects
    beside the frame's field of view, whose echoes the elements record) or what the
    steps have not reached yet, and neither makes objects on the grid."""
    unexplained = residual**2 - noise_norm**2
    return max(threshold**2, min(unexplained, MODEL_ERROR**2 * found))


def _grid(vol: Volume, hologram: Any, medium: Any, options: dict[str, Any]
          ) -> tuple[dict[str, Any], bool]:
    """The inversion's grid: the image's planes; pixels of at most :data:`GRID_CELLS`
    of the lateral resolution cell at the shallowest plane (finer grids make nearly
    parallel columns, which the sparse solver spreads a point over, and cost voxels);
    a tilted array's ground frame, its region the image's."""
    step_m = GRID_CELLS * _lateral_cell(hologram, medium, float(np.min(vol.z)))
    level = bool(hologram.pose.is_identity) and not vol.method.endswith(":ground") and \
        options.get("frame", "aperture") == "aperture"
    if level:
        pitch = max(hologram.pitch)
        return {"upsample": max(1, min(8, math.ceil(pitch / step_m)))}, True
    step = max(1, math.floor(step_m / vol.dx))
    return {"frame": "ground", "x": vol.x[::step], "y": vol.y[::step]}, False


def _lateral_cell(hologram: Any, medium: Any, z: float) -> float:
    """``lambda L / A`` at range ``z`` (:func:`holoradar.theory.resolution_cells`)."""
    return resolution_cells(hologram, medium, z)[0]


def _range_cell(hologram: Any, medium: Any, z: float) -> float:
    """The depth response at ``z`` (:func:`holoradar.theory.resolution_cells`)."""
    return resolution_cells(hologram, medium, z)[1]


def _objects(data: np.ndarray, keep: np.ndarray, r: Any, cell: float, rcell: float,
             c: np.ndarray) -> list[dict[str, Any]]:
    """Voxels above the noise joined into objects, strongest first.

    Lateral neighbours touch (the grid's pixels are half a cell); in range, voxels
    within half a range cell join. Within each group so joined, the voxels weaker than
    :data:`FRAGMENT_DB` of its strongest voxel do not join others (what the model
    misses lands there, and chains of them would tie separate bars together): each
    goes to the nearest of its group's strong pieces within a resolution cell, or
    makes a piece of its own.
    """
    if not keep.any():
        return []
    dx = float(abs(r.x[1] - r.x[0])) if r.x.size > 1 else cell
    dz = float(np.min(np.diff(r.z))) if r.z.size > 1 else 1.0
    zreach = max(1, math.floor(rcell / 2 / dz))
    energy = np.where(keep, (np.abs(data) * c) ** 2, 0.0)

    def groups(mask: np.ndarray) -> tuple[np.ndarray, int]:
        # Each voxel climbs its column's energy to its range peak; peaks join laterally
        # where their ranges lie within half a range cell, and every voxel goes with
        # its peak. Bars crossing at two depths are then two objects where their
        # range responses overlap, and a sloping object stays one.
        top = _range_peaks(np.where(mask, energy, 0.0), mask)
        peaks = mask & (top == np.arange(mask.shape[0])[:, None, None])
        # Peaks whose planes differ by at most zreach join: each grown by half of it.
        half = zreach // 2
        joined = ndimage.binary_dilation(peaks, np.ones((2 * half + 1, 1, 1), bool)) \
            if half else peaks
        labels, count = ndimage.label(joined, np.ones((3, 3, 3), bool))
        iy, ix = np.indices(mask.shape[1:])
        return np.where(mask, labels[top, iy, ix], 0), count

    group, count = groups(keep)
    peak = np.asarray(ndimage.maximum(energy, group, np.arange(count + 1)))
    strong = keep & (energy >= 10 ** (FRAGMENT_DB / 10) * peak[group])
    pieces, n = groups(strong)
    weak = keep & ~strong
    if weak.any():
        # The nearest strong voxel, a range cell counting as a lateral cell.
        dist, idx = ndimage.distance_transform_edt(
            ~strong, sampling=(dz * cell / max(rcell, 1e-9), dx, dx), return_indices=True)
        host = pieces[tuple(idx)]
        near = weak & (dist <= cell) & (group[tuple(idx)] == group)
        pieces = np.where(near, host, pieces)
        rest, m = groups(weak & ~near)
        pieces = np.where(rest > 0, rest + n, pieces)
        n += m
    out = []
    for i in range(1, n + 1):
        iz, iy, ix = np.nonzero(pieces == i)
        if iz.size == 0:
            continue
        vals = data[iz, iy, ix]
        out.append({"w": np.abs(vals) ** 2, "vals": vals, "x": r.x[ix], "y": r.y[iy],
                    "z": r.z[iz], "c": c[iz, iy, ix], "dx": dx,
                    "dz": dz if r.z.size > 1 else 0.0})
    out.sort(key=lambda ob: -_energy(ob))
    return out


def _range_peaks(energy: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """For each voxel of ``mask`` the plane of the range peak it climbs to along its
    column (through neighbouring voxels of the mask, each step to the brighter
    neighbour); elsewhere its own plane."""
    nz = energy.shape[0]
    here = np.broadcast_to(np.arange(nz)[:, None, None], energy.shape)
    if nz == 1:
        return np.array(here)
    pad = np.pad(energy, ((1, 1), (0, 0), (0, 0)), constant_values=-1.0)
    below, above = pad[:-2], pad[2:]
    step = np.where((below > energy) & (below >= above), -1,
                    np.where(above > energy, 1, 0))
    step = np.where(mask, step, 0)
    iy, ix = np.indices(energy.shape[1:])
    top = np.array(here + step)
    # Pointer jumping: each pass doubles the steps followed.
    for _ in range(max(1, math.ceil(math.log2(nz))) + 1):
        nxt = top[top, iy, ix]
        if np.array_equal(nxt, top):
            break
        top = nxt
    return top


def _energy(ob: dict[str, Any]) -> float:
    return float(np.sum(ob["w"] * ob["c"] ** 2))


def _merge_fragments(objects: list[dict[str, Any]], cell: float, range_cell: float
                     ) -> list[dict[str, Any]]:
    """Objects (strongest first) with each fragment joined to the stronger object it
    lies within a resolution cell of (laterally ``cell``, in range ``range_cell``)
    when it is weaker than that object by more than :data:`FRAGMENT_DB`: within one
    cell the sparse solution spreads an object over several voxels, and what the model
    misses of a full-wave object (5-15 % in amplitude) lands there too; neither is
    another object."""
    kept: list[dict[str, Any]] = []
    cores: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    ratio = 10 ** (FRAGMENT_DB / 10)
    for ob in objects:
        cx, cy, cz = (float(np.average(ob[k], weights=ob["w"])) for k in ("x", "y", "z"))
        host = None
        # Near an object's own voxels, not those of the fragments it took: else a bar
        # grows fragment by fragment along the bars that cross it.
        for big, (bx, by, bz) in zip(kept, cores, strict=True):
            near = (np.hypot(bx - cx, by - cy) <= cell) & (np.abs(bz - cz) <= range_cell)
            if near.any() and _energy(ob) < ratio * _energy(big):
                host = big
                break
        if host is None:
            kept.append(dict(ob))
            cores.append((ob["x"], ob["y"], ob["z"]))
        else:
            for k in ("w", "vals", "x", "y", "z", "c"):
                host[k] = np.concatenate([host[k], ob[k]])
    return kept


def _axis(ob: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, float, float]:
    """An object's centroid (x, y, z), its unit axis, its length and width."""
    w = ob["w"] / ob["w"].sum()
    c = np.array([float(np.sum(w * ob[k])) for k in ("x", "y", "z")])
    length, width, azimuth, _ = _extent(ob, w, c[0], c[1])
    t = math.radians(azimuth)
    return c, np.array([math.cos(t), math.sin(t)]), length, width


def _join_collinear(objects: list[dict[str, Any]], cell: float, range_cell: float
                    ) -> list[dict[str, Any]]:
    """Pieces of one bar joined: two objects of which one is a line (longer than two
    cells and three times its width) and the other lies on its axis (each centroid
    within half a cell of the other's axis, directions within the angle a cell
    subtends over the line, depths within half a range cell), the gap between them
    along the axis shorter than the line. Where bars cross, the sparse solution gives
    the crossing to the stronger bar, and the weaker one comes out in pieces."""
    out = [dict(ob) for ob in objects]
    axes = [_axis(ob) for ob in out]
    joined = True
    while joined:
        joined = False
        for i in range(len(out)):
            ci, ui, li, wi = axes[i]
            if not (li > 2 * cell and li > 3 * wi):
                continue
            for j in range(len(out)):
                if j == i:
                    continue
                cj, uj, lj, _ = axes[j]
                d = cj[:2] - ci[:2]
                across = abs(d[0] * ui[1] - d[1] * ui[0])
                along = abs(float(d @ ui))
                # A piece's direction is known to about a cell over its length.
                turn = abs(float(ui @ uj)) if lj > 2 * cell else 1.0
                if across <= 0.5 * cell and abs(cj[2] - ci[2]) <= 0.5 * range_cell and \
                        turn >= math.cos(math.atan2(cell, min(li, lj))) and \
                        along - 0.5 * (li + lj) <= li:
                    for k in ("w", "vals", "x", "y", "z", "c"):
                        out[i][k] = np.concatenate([out[i][k], out[j][k]])
                    del out[j], axes[j]
                    axes[i if i < j else i - 1] = _axis(out[i if i < j else i - 1])
                    joined = True
                    break
            if joined:
                break
    out.sort(key=lambda ob: -_energy(ob))
    return out


def _row(ob: dict[str, Any], sigma: float, medium: Any, interval: Any,
         hologram: Any) -> dict[str, Any]:
    w = ob["w"] / ob["w"].sum()
    cx, cy, cz = (float(np.sum(w * ob[k])) for k in ("x", "y", "z"))
    cell = _lateral_cell(hologram, medium, cz)
    length, width, azimuth, ends = _extent(ob, w, cx, cy)
    kind = "line" if length > 2 * cell and length > 3 * width else \
        "area" if min(length, width) > 2 * cell else "point"
    amp = abs(complex(np.sum(ob["vals"])))
    snr_lin = float(np.sum(ob["w"] * ob["c"] ** 2)) / sigma**2
    k = cramer_rao_factor(snr_lin)
    # The peak's spread at the object's SNR, and the grid's: a centroid of voxels a
    # pitch p apart is off by up to p / 2, a standard deviation of p / sqrt(12).
    grid = (ob["dx"] ** 2 / 12, ob["dx"] ** 2 / 12, ob.get("dz", 0.0) ** 2 / 12)
    std = tuple(math.sqrt(s**2 + g) for s, g in zip(
        (cell * k / math.pi, cell * k / math.pi,
         _range_cell(hologram, medium, cz) * k / math.pi), grid, strict=True))
    depth, lo, hi = depth_of(cz, std[2], medium, interval, hologram.nf > 1)
    line, point = kind == "line", kind == "point"
    row = detection_row(
        kind, cx, cy, cz, depth=depth, depth_low=lo, depth_high=hi,
        length=0.0 if point else length, width=0.0 if point else width,
        azimuth_deg=np.nan if point else azimuth,
        amplitude_db=20 * math.log10(max(amp, 1e-300)),
        snr_db=10 * math.log10(snr_lin) if snr_lin > 0 else -np.inf,
        x_std=std[0], y_std=std[1], range_std=std[2],
        **(dict(zip(("x_start", "y_start", "x_end", "y_end"), ends, strict=True))
           if line else {}))
    if kind == "area":
        row["outline"], row["area"] = _outline(ob)
    return row


def _extent(ob: dict[str, Any], w: np.ndarray, cx: float, cy: float
            ) -> tuple[float, float, float, tuple[float, float, float, float]]:
    """Full length and width along and across the principal axis (weighted second
    moments, sqrt(12) standard deviations, at least one voxel), azimuth (degrees from +x
    towards +y, in [0, 180)) and the line's ends."""
    X, Y = ob["x"] - cx, ob["y"] - cy
    cov = np.array([[np.sum(w * X * X), np.sum(w * X * Y)],
                    [np.sum(w * X * Y), np.sum(w * Y * Y)]])
    vals, vecs = np.linalg.eigh(cov)
    axis = vecs[:, 1]
    length = max(math.sqrt(12 * max(vals[1], 0.0)), ob["dx"])
    width = max(math.sqrt(12 * max(vals[0], 0.0)), ob["dx"])
    azimuth = math.degrees(math.atan2(axis[1], axis[0])) % 180.0
    half = 0.5 * length
    ends = (cx - half * axis[0], cy - half * axis[1], cx + half * axis[0], cy + half * axis[1])
    return length, width, azimuth, ends


def _outline(ob: dict[str, Any]) -> tuple[list[tuple[float, float]], float]:
    """An area's lateral outline (the convex hull of its voxels) and its area, m^2."""
    from scipy.spatial import ConvexHull, QhullError

    pts = np.unique(np.stack([ob["x"], ob["y"]], axis=1), axis=0)
    try:
        hull = ConvexHull(pts)
    except (QhullError, ValueError):
        return [tuple(map(float, p)) for p in pts], 0.0
    return [tuple(map(float, pts[i])) for i in hull.vertices], float(hull.volume)


def _spacing(rows: list[dict[str, Any]]) -> None:
    """Each line's distance to the nearest parallel line (azimuths within 15 degrees),
    across its direction."""
    lines = [r for r in rows if r["kind"] == "line"]
    for a in lines:
        best = np.inf
        for b in lines:
            if b is a:
                continue
            d_az, across = line_offset(a, b)
            if d_az <= 15.0:
                best = min(best, across)
        a["spacing"] = best if np.isfinite(best) else np.nan


def _refine_points(rows: list[dict[str, Any]], model: Any, medium: Any,
                   interval: tuple[float, float] | None, wideband: bool) -> None:
    """Points under a level array: the exact point response fitted from each one's
    centroid (strongest first, each subtracted), then refitted together; Cramer-Rao
    standard deviations."""
    points = [r for r in rows if r["kind"] == "point"]
    for row in points:
        model.add_point((row["x"], row["y"], row["range"]))
    model.refine()
    for row, ob, std in zip(points, model.objects, model.uncertainty(), strict=True):
        row["x"], row["y"], row["range"] = (float(v) for v in ob["r"])
        row["x_std"], row["y_std"], row["range_std"] = (float(v) for v in std)
        # The fitted point's amplitude (the band's mean magnitude): one number, where
        # the voxels' sum at one frequency cancels along the long focus.
        row["amplitude_db"] = 20 * math.log10(max(float(np.mean(np.abs(ob["a"]))), 1e-300))
        if medium is not None and medium.z_interfaces:
            row["depth"], row["depth_low"], row["depth_high"] = depth_of(
                row["range"], row["range_std"], medium, interval, wideband)
