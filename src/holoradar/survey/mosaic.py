"""``mosaic``: one plan-view map of a survey at a chosen depth, overlapping frames blended.

Each frame's ``|image|`` on the plane nearest the depth is resampled (bilinear)
onto one world grid and the frames are averaged with a taper weight

    w(u, v) = cos^2(pi u / (2 (H_x + s_x))) * cos^2(pi v / (2 (H_y + s_y)))

where ``(u, v)`` is the offset from the frame's centre, ``H`` the half-width of
its pixel grid and ``s`` its pixel step: 1 at the centre, falling smoothly to
``sin^2(pi s / (2 (H + s)))`` (a few per cent) on the edge pixels, so that a
seam between frames fades instead of stepping and each place is seen mostly
by the frame most nearly above it. Amplitudes are averaged, not complex
fields: neighbouring frames are separate recordings whose phases need not
agree.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..data.hologram import Image
from .store import read_images, read_index

__all__ = ["mosaic", "taper"]


def taper(offset: np.ndarray, half: float, step: float) -> np.ndarray:
    """The blending weight along one axis: ``cos^2(pi u / (2 (half + step)))``, 0 beyond.

    Examples
    --------
    >>> taper(np.array([0.0, 0.1, 0.2]), 0.1, 0.1).round(3)
    array([1. , 0.5, 0. ])
    """
    u = np.abs(np.asarray(offset, float))
    w = np.cos(np.pi * u / (2 * (half + step))) ** 2
    return np.where(u < half + step, w, 0.0)


def _grid(lo: float, hi: float, anchor: float, step: float) -> np.ndarray:
    """Points ``anchor + k*step`` covering ``[lo, hi]`` (to rounding)."""
    k0 = int(np.floor((lo - anchor) / step + 1e-6))
    k1 = int(np.ceil((hi - anchor) / step - 1e-6))
    return anchor + np.arange(k0, k1 + 1) * step


def _bilinear_axis(g: np.ndarray, start: float, step: float,
                   n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For grid points ``g``: which lie on a frame's axis ``start + i*step`` (i < n), their
    lower index and fraction."""
    t = (g - start) / step
    inside = (t > -1e-6) & (t < n - 1 + 1e-6)
    sel = np.nonzero(inside)[0]
    t = np.clip(t[sel], 0.0, n - 1)
    i0 = np.minimum(np.floor(t).astype(int), max(n - 2, 0))
    return sel, i0, t - i0, t


def mosaic(store: str | os.PathLike[str], depth: float, *, pitch: float | None = None) -> Image:
    """A plan-view map of ``|image|`` over the whole survey at the plane nearest ``depth``.

    Parameters
    ----------
    store : path
        A survey store written by :func:`~holoradar.survey.run_batch`.
    depth : float
        Range of the plane from the aperture, metres (the ``z`` of the run); the
        stored plane nearest to it is used (``Image.z`` says which).
    pitch : float, optional
        Pixel step of the map, metres. Default: the frames' pixel step
        (``pitch / upsample`` of the run), on a grid through the first frame's
        pixels, so frames placed a whole number of pixels apart are sampled
        without interpolation.

    Returns
    -------
    Image
        ``data`` (ny, nx) float: the taper-weighted mean of the frames' ``|image|``
        (module text), 0 where no frame reaches; ``x``, ``y`` world coordinates,
        metres; ``z`` the plane's range; ``method`` ``"mosaic"``;
        ``has_z_axis`` False. Frames not done are left out.

    Raises
    ------
    ValueError
        Not a survey store, no frame done, bad depth or pitch, a frame whose image
        chunk is missing or damaged (named).

    Examples
    --------
    >>> import pathlib, tempfile, numpy as np
    >>> import holoradar as hr
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> x = (np.arange(8) - 3.5) * 0.01
    >>> paths = [hr.save(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9,
    ...                               pose=hr.Pose((0.04 * i, 0.0, 0.0))), d / f"f{i}.nc")
    ...          for i in range(3)]
    >>> _ = hr.survey.run_batch(paths, d / "s.zarr", z=[0.2, 0.3], scheduler="synchronous")
    >>> m = mosaic(d / "s.zarr", 0.29)
    >>> m.data.shape, float(m.z[0]), round(float(m.x[0]), 3), round(float(m.x[-1]), 3)
    ((8, 16), 0.3, -0.035, 0.115)
    """
    try:
        dz = float(depth)
    except (TypeError, ValueError):
        raise ValueError(f"depth must be a range in metres, got {depth!r}") from None
    if not np.isfinite(dz):
        raise ValueError(f"depth must be a finite range in metres, got {depth!r}")
    idx = read_index(Path(store))
    frames = np.nonzero(idx["done"])[0]
    if frames.size == 0:
        raise ValueError(f"store {str(store)!r} holds no finished frame to map")
    # A frame marked done whose chunk is missing would read as blank (its fill value):
    # a hole in the map and a wrong brightest point without a word. (A chunk damaged
    # in place fails its checksum when read.)
    from .store import describe_store

    lost = describe_store(Path(store), checksums=False)["damaged"]
    if lost:
        raise ValueError(f"store {str(store)!r}: frame(s) "
                         f"{', '.join(d['name'] for d in lost)} damaged ({lost[0]['reason']}): "
                         "image them again with holoradar batch (a rerun repairs them)")
    zs, xo, yo = idx["z"], idx["x"], idx["y"]
    iz = int(np.argmin(np.abs(zs - dz)))
    sx = float(xo[1] - xo[0]) if xo.size > 1 else 1.0
    sy = float(yo[1] - yo[0]) if yo.size > 1 else 1.0
    if pitch is not None:
        if not (isinstance(pitch, int | float | np.floating) and np.isfinite(pitch)
                and pitch > 0):
            raise ValueError(f"pitch must be a step in metres > 0, got {pitch!r}")
        px = py = float(pitch)
    else:
        px, py = sx, sy
    fx, fy = idx["frame_x"][frames], idx["frame_y"][frames]
    gx = _grid(float(np.min(fx)) + xo[0], float(np.max(fx)) + xo[-1], fx[0] + xo[0], px)
    if yo.size == 1:
        # Line scans: one row per line, at the lines' own y (not evenly spaced).
        gy = np.unique(np.round(fy + yo[0], 9))
        return _line_mosaic(idx, frames, iz, gx, gy, xo, px)
    gy = _grid(float(np.min(fy)) + yo[0], float(np.max(fy)) + yo[-1], fy[0] + yo[0], py)
    num = np.zeros((gy.size, gx.size))
    den = np.zeros((gy.size, gx.size))
    hx, hy = 0.5 * (xo[-1] - xo[0]), 0.5 * (yo[-1] - yo[0])
    batch = 64  # frames read at a time: bounded memory on long surveys
    for b0 in range(0, frames.size, batch):
        sel = frames[b0:b0 + batch]
        amps = np.abs(read_images(idx, sel, plane=iz))
        for k, f in enumerate(sel):
            cx, cy = idx["frame_x"][f], idx["frame_y"][f]
            jx, ix0, ax, _ = _bilinear_axis(gx, cx + xo[0], sx, xo.size)
            jy, iy0, ay, _ = _bilinear_axis(gy, cy + yo[0], sy, yo.size)
            if jx.size == 0 or jy.size == 0:
                continue
            a = amps[k]
            ix1 = np.minimum(ix0 + 1, xo.size - 1)
            iy1 = np.minimum(iy0 + 1, yo.size - 1)
            top = a[np.ix_(iy0, ix0)] * (1 - ax) + a[np.ix_(iy0, ix1)] * ax
            bot = a[np.ix_(iy1, ix0)] * (1 - ax) + a[np.ix_(iy1, ix1)] * ax
            val = top * (1 - ay)[:, None] + bot * ay[:, None]
            w = taper(gy[jy] - cy, hy, sy)[:, None] * taper(gx[jx] - cx, hx, sx)[None, :]
            num[np.ix_(jy, jx)] += w * val
            den[np.ix_(jy, jx)] += w
    out = np.divide(num, den, out=np.zeros_like(num), where=den > 0)
    geo = idx["attrs"]["geometry"]
    f_hz = np.asarray(geo["frequency_hz"], float)
    return Image(out, gx, gy, zs[iz:iz + 1].copy(), f_hz if geo["wideband"] else float(f_hz[0]),
                 "mosaic", has_z_axis=False)


def _line_mosaic(idx: dict, frames: np.ndarray, iz: int, gx: np.ndarray, gy: np.ndarray,
                 xo: np.ndarray, px: float) -> Image:
    """A survey of line scans mapped at one plane: each line's row at its y (lines at
    one y blended with the frames' taper along x), on the x grid ``gx``."""
    sx = float(xo[1] - xo[0]) if xo.size > 1 else px
    num = np.zeros((gy.size, gx.size))
    den = np.zeros((gy.size, gx.size))
    hx = 0.5 * (xo[-1] - xo[0])
    zs = idx["z"]
    for b0 in range(0, frames.size, 64):
        sel = frames[b0:b0 + 64]
        amps = np.abs(read_images(idx, sel, plane=iz))
        for k, f in enumerate(sel):
            cx, cy = idx["frame_x"][f], idx["frame_y"][f]
            jx, ix0, ax, _ = _bilinear_axis(gx, cx + xo[0], sx, xo.size)
            if jx.size == 0:
                continue
            row = np.asarray(amps[k]).reshape(-1, xo.size)[0]
            ix1 = np.minimum(ix0 + 1, xo.size - 1)
            val = row[ix0] * (1 - ax) + row[ix1] * ax
            jy = int(np.argmin(np.abs(gy - (cy + float(idx["y"][0])))))
            w = taper(gx[jx] - cx, hx, sx)
            num[jy, jx] += w * val
            den[jy, jx] += w
    out = np.divide(num, den, out=np.zeros_like(num), where=den > 0)
    geo = idx["attrs"]["geometry"]
    f_hz = np.asarray(geo["frequency_hz"], float)
    return Image(out, gx, gy, zs[iz:iz + 1].copy(), f_hz if geo["wideband"] else float(f_hz[0]),
                 "mosaic", has_z_axis=False)
