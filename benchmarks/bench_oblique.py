"""Imaging from a tilted aperture onto horizontal ground planes, against the frontal
FFT migration of the same data onto the same grid, cold and warm.

Case of the issue: a 32 x 32 hologram (pitch lambda/2 at 9.9 GHz) tilted 35
degrees over sand (eps 2.5 + 0.0125i), imaged onto a 128 x 128 horizontal plane
(one plane), and onto a 64-plane ground volume. The frontal counterpart migrates
the same data, untilted, onto the same number of pixels (``upsample`` to 128^2)
and planes. Ratios in one run: the fastest of REPEAT interleaved runs after a
warm-up; "cold" is the first call with the transfer cache cleared.

Run: ``.venv/bin/python benchmarks/bench_oblique.py``; writes
``benchmarks/results_oblique.json`` and prints a Markdown table.
"""

from __future__ import annotations

import json
import time
import warnings
from pathlib import Path

import numpy as np

import holoradar as hr
from holoradar.physics.propagation import clear_transfer_cache

REPEAT = 5
F0 = 9.9e9
N = 32
PITCH = hr.C0 / F0 / 2
SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)


def _best(fn, repeat: int = REPEAT) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> dict:
    rng = np.random.default_rng(0)
    data = rng.standard_normal((N, N)) + 1j * rng.standard_normal((N, N))
    x = (np.arange(N) - (N - 1) / 2) * PITCH
    pose = hr.Pose((0.0, -0.15, 0.05), tilt=np.radians(35), azimuth=np.radians(90))
    tilted = hr.Hologram(data, x, x, F0, pose=pose)
    frontal = hr.Hologram(data, x, x, F0)
    # The same 128 x 128 pixels: the frontal image upsampled 4x (125^2 + the edge).
    gx = np.linspace(-0.25, 0.25, 128)
    gy = np.linspace(-0.15, 0.35, 128)
    z1 = 0.42
    zs = np.linspace(0.35, 0.5, 64)
    res: dict[str, object] = {"case": f"{N}x{N} tilted 35 deg over sand onto 128x128"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cases = {
            "plane": (lambda: hr.migrate(tilted, z1, medium=SAND, frame="ground", x=gx, y=gy),
                      lambda: hr.migrate(frontal, z1, medium=SAND, upsample=4)),
            "volume": (lambda: hr.migrate(tilted, zs, medium=SAND, frame="ground", x=gx, y=gy),
                       lambda: hr.migrate(frontal, zs, medium=SAND, upsample=4)),
        }
        rows = []
        for name, (obl, front) in cases.items():
            clear_transfer_cache()
            t0 = time.perf_counter()
            obl()
            cold_o = time.perf_counter() - t0
            clear_transfer_cache()
            t0 = time.perf_counter()
            front()
            cold_f = time.perf_counter() - t0
            obl()
            front()
            warm_o, warm_f = _best(obl), _best(front)
            res[name] = {"oblique_cold_s": cold_o, "frontal_cold_s": cold_f,
                         "oblique_warm_s": warm_o, "frontal_warm_s": warm_f,
                         "warm_ratio": warm_o / warm_f, "cold_ratio": cold_o / cold_f}
            rows.append(f"| {name} | {warm_o * 1e3:.1f} ms | {warm_f * 1e3:.1f} ms | "
                        f"{warm_o / warm_f:.2f}x | {cold_o * 1e3:.0f} ms vs {cold_f * 1e3:.0f}"
                        f" ms: {cold_o / cold_f:.2f}x |")
    print("| case | tilted, ground frame (warm) | frontal (warm) | ratio | cold |")
    print("|---|---|---|---|---|")
    print("\n".join(rows))
    Path(__file__).with_name("results_oblique.json").write_text(json.dumps(res, indent=1))
    return res


if __name__ == "__main__":
    main()
