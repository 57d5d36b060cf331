"""Scattered samples: ``migrate`` through non-uniform FFTs against the matched filter
written out in NumPy, and against a uniform grid of the same extent and density.

Case: 10 000 transceiver samples (a freehand scan: 100 wobbling sweeps over a 24 cm
patch, positions jittered by 0.5 mm), 32 frequencies 8-12 GHz, three points in free
space; imaged onto 101 x 101 pixels x 21 planes (6-16 cm), complex64, warm (best of
three after a first call). The grid: 100 x 100 elements over the same patch, the same
frequencies and planes, ``migrate`` with its defaults.

The matched filter (``sum_n d_n (z/R^2) exp(-2ikR)`` per pixel, plane and frequency, in
chunks of pixels) would take hours: it is timed on one plane and two frequencies (all
samples, all pixels) and scaled by planes x frequencies / 2 (its cost is exactly
proportional to each).

Streaming (``SampleStream``): the same samples added in batches of 100 (as a tracker
delivers them) onto the same grid, the image redrawn after every 10 batches (1000
samples); the samples per second of the whole (adds and redraws), and the seconds of
one redraw.

Run: ``.venv/bin/python benchmarks/bench_samples.py``; writes
``benchmarks/results_samples.json``.
"""

from __future__ import annotations

import json
import time
import warnings
from pathlib import Path

import numpy as np
from timing import best

import holoradar as hr

HERE = Path(__file__).parent
C0 = 299792458.0
F = np.linspace(8e9, 12e9, 32)
ZS = np.linspace(0.06, 0.16, 21)
XS = np.linspace(-0.12, 0.12, 101)
POINTS = [(0.0, 0.0, 0.10), (0.05, 0.04, 0.12), (-0.06, -0.03, 0.08)]


def freehand(n_sweeps: int = 100, per: int = 100, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    out = []
    for j, y0 in enumerate(np.linspace(-0.12, 0.12, n_sweeps)):
        x = np.linspace(-0.12, 0.12, per) + rng.normal(0, 0.0005, per)
        y = y0 + 0.001 * np.sin(30 * x + j) + rng.normal(0, 0.0005, per)
        out.append(np.column_stack([x, y]))
    return np.concatenate(out)


def point_data(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    k = 2 * np.pi * F[:, None] / C0
    d = 0
    for px, py, pz in POINTS:
        R = np.sqrt((x - px) ** 2 + (y - py) ** 2 + pz**2)
        d = d + np.exp(2j * k * R) / R**2
    return d


def matched_filter_part(p: np.ndarray, d: np.ndarray) -> float:
    """Seconds of the written-out matched filter on one plane and two frequencies."""
    X, Y = np.meshgrid(XS, XS)
    px, py = X.ravel(), Y.ravel()
    k = 2 * np.pi * F / C0
    t = time.perf_counter()
    z = ZS[len(ZS) // 2]
    for i in (0, 1):
        out = np.empty(px.size, complex)
        for c in range(0, px.size, 256):
            R = np.sqrt((px[c:c + 256, None] - p[:, 0]) ** 2
                        + (py[c:c + 256, None] - p[:, 1]) ** 2 + z**2)
            out[c:c + 256] = (z / R**2 * np.exp(-2j * k[i] * R)) @ d[i]
    return time.perf_counter() - t


def main() -> None:
    warnings.simplefilter("ignore")
    p = freehand()
    d = point_data(p[:, 0], p[:, 1])
    s = hr.Hologram.from_samples(d, p, F, monostatic=True)
    g = np.linspace(-0.12, 0.12, 100)
    Gx, Gy = np.meshgrid(g, g)
    h = hr.Hologram(point_data(Gx.ravel(), Gy.ravel()).reshape(F.size, 100, 100), g, g, F,
                    monostatic=True)
    t_samples = best(lambda: hr.migrate(s, ZS, x=XS, y=XS))
    t_grid = best(lambda: hr.migrate(h, ZS))
    t_mf = matched_filter_part(p, d) * ZS.size * F.size / 2
    from holoradar.imaging.samples_stream import SampleStream

    stream = SampleStream(F, ZS, XS, XS, monostatic=True)
    t = time.perf_counter()
    for i in range(0, len(p), 100):
        stream.add(d[:, i:i + 100], p[i:i + 100])
        if (i // 100) % 10 == 9:
            stream.image()
    t_add = time.perf_counter() - t
    t_image = best(stream.image)
    out = {"samples": len(p), "frequencies": int(F.size),
           "voxels": [int(ZS.size), int(XS.size), int(XS.size)],
           "migrate_samples_s": t_samples, "migrate_grid_s": t_grid,
           "matched_filter_s_estimated": t_mf,
           "matched_filter_over_samples": t_mf / t_samples,
           "samples_over_grid": t_samples / t_grid,
           "stream_samples_per_s": len(p) / t_add, "stream_image_s": t_image}
    (HERE / "results_samples.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
