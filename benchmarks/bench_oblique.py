"""Imaging from a tilted aperture onto horizontal ground planes: the two routes of
the data's spectrum on the reference plane (finufft's type-2 non-uniform FFT and
the hand-written factored sums), and the whole path against the frontal FFT
migration of the same data onto the same grid, cold and warm.

Part 1, the spectrum (``oblique_sum.sum_to_plane``), both routes on the same
grids: the tests' size (10 x 8 elements onto a 40 x 44 grid), 16 x 16 onto 64 x 64
pixels, the issue's case
(32 x 32 at lambda/2 and 9.9 GHz, tilted 35 degrees over sand, onto the world grid
of a 128 x 128 output; azimuth 90 degrees, factored by grid columns, and 30
degrees, factored in full), and larger arrays (64 x 64 onto 256 x 256, both azimuths;
128 x 128 onto 384 x 384 at azimuth 90 degrees: at 30 degrees the direct route's factors
alone would take several GB).
Warm: the geometry's factors cached, the median of REPEAT interleaved calls.
Cold: the first ground-frame ``migrate`` in a fresh Python process (imports of
holoradar done, of finufft not), the median of COLD_RUNS processes alternating
the routes. Agreement: relative L2 of the nufft spectrum against the direct one;
"auto": the route ``oblique_sum.choose_route`` takes there (the default).

Part 2, the issue's case end to end (one plane, a 64-plane volume) with the default
route and with each route forced, against the frontal migration onto the same
pixels: medians of REPEAT interleaved runs; cold, the first call after the
transfer cache is cleared (in this process: finufft already imported).

Run: ``.venv/bin/python benchmarks/bench_oblique.py [spectrum_routes] [against_frontal]``
(default both); writes ``benchmarks/results_oblique.json`` (with the machine's load
average at the end of each part) and prints Markdown tables.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import holoradar as hr
from holoradar.imaging.migration.backends import oblique, oblique_sum
from holoradar.physics.propagation import clear_transfer_cache

REPEAT = 7
COLD_RUNS = 3
F0 = 9.9e9
N = 32
PITCH = hr.C0 / F0 / 2
SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
ROUTES = ("direct", "nufft")


def _best(fn, repeat: int = REPEAT) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _case(n: int, azimuth_deg: float, out: int, dtype: str = "complex128"):
    """A tilted n x n array (lowest element 0.11 m above sand), its world grid of
    out x out pixels and the plane through a target 0.12 m deep."""
    rng = np.random.default_rng(0)
    data = (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))).astype(dtype)
    x = (np.arange(n) - (n - 1) / 2) * PITCH
    tilt, az = np.radians(35), np.radians(azimuth_deg)
    low = hr.Hologram(data, x, x, F0, pose=hr.Pose((0.0, -0.15, 0.0), tilt=tilt,
                                                  azimuth=az)).points[:, 2].max()
    pose = hr.Pose((0.0, -0.15, 0.19 - low), tilt=tilt, azimuth=az)
    h = hr.Hologram(data, x, x, F0, pose=pose)
    gx, gy = oblique.ground_grid(h, np.array([0.42]), SAND)
    gx = np.linspace(gx[0], gx[-1], out)
    gy = np.linspace(gy[0], gy[-1], out)
    return h, gx, gy


_CASES = {
    "tests 10x8 -> 40x44": None,
    "16x16 az90 -> 64^2": (16, 90.0, 64),
    "32x32 az90 -> 128^2": (32, 90.0, 128),
    "32x32 az30 -> 128^2": (32, 30.0, 128),
    "32x32 az90 -> 128^2 complex64": (32, 90.0, 128, "complex64"),
    "64x64 az90 -> 256^2": (64, 90.0, 256),
    "128x128 az90 -> 384^2": (128, 90.0, 384),
    "64x64 az30 -> 256^2": (64, 30.0, 256),
}


def _spectrum_args(name: str):
    """What ``sum_to_plane`` receives in this case (the grid the ground frame picks):
    ``(geometry, data, kk, grid, pitch, origin, work, gap)``."""
    if _CASES[name] is None:
        rng = np.random.default_rng(1)
        x = (np.arange(10) - 4.5) * 0.015
        y = (np.arange(8) - 3.5) * 0.015
        d = rng.standard_normal((8, 10)) + 1j * rng.standard_normal((8, 10))
        pose = hr.Pose((0.01, -0.02, 0.05), tilt=np.radians(35), azimuth=np.radians(30))
        h = hr.Hologram(d, x, y, F0, pose=pose)
        return (h, d[None], h.k, (40, 44), (0.01, 0.012), (-0.1, -0.1, 0.2),
                np.dtype(complex), 0.2)
    h, gx, gy = _case(*_CASES[name])
    seen = {}
    real = oblique_sum.sum_to_plane

    def spy(*a):
        seen["args"] = a[:8]
        return real(*a)

    oblique.sum_to_plane = spy
    try:
        hr.migrate(h, np.array([0.42]), medium=SAND, frame="ground", x=gx, y=gy)
    finally:
        oblique.sum_to_plane = real
    return seen["args"]


_COLD = """
import sys, time, warnings
import numpy as np
sys.path.insert(0, {here!r})
warnings.simplefilter("ignore")
import bench_oblique as b
import holoradar as hr
from holoradar.imaging.migration.backends import oblique_sum
case = b._CASES[{name!r}]
if case is None:
    args = b._spectrum_args({name!r})
    t0 = time.perf_counter()
    oblique_sum.sum_to_plane(*args, route={route!r})
else:
    h, gx, gy = b._case(*case)
    t0 = time.perf_counter()
    hr.migrate(h, np.array([0.42]), medium=b.SAND, frame="ground", x=gx, y=gy,
               algorithm="ground-" + {route!r})
print(time.perf_counter() - t0)
"""


def _cold(name: str, route: str) -> float:
    code = _COLD.format(here=str(Path(__file__).parent), name=name, route=route)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    return float(out.stdout.strip().splitlines()[-1])


def spectrum_routes() -> dict:
    res = {}
    rows = []
    for name in _CASES:
        args = _spectrum_args(name)
        H = {r: oblique_sum.sum_to_plane(*args, route=r) for r in ROUTES}   # warm-up
        err = float(np.linalg.norm(H["nufft"] - H["direct"]) / np.linalg.norm(H["direct"]))
        times = {r: [] for r in ROUTES}
        for _ in range(REPEAT):                     # interleaved
            for r in ROUTES:
                t0 = time.perf_counter()
                oblique_sum.sum_to_plane(*args, route=r)
                times[r].append(time.perf_counter() - t0)
        warm = {r: float(np.median(times[r])) for r in ROUTES}
        cold = {r: [] for r in ROUTES}
        for _ in range(COLD_RUNS):
            for r in ROUTES:
                cold[r].append(_cold(name, r))
        cold_m = {r: float(np.median(cold[r])) for r in ROUTES}
        grid = args[3]
        chosen = oblique_sum.choose_route(grid, args[0].pose, args[0].data.shape[-2:])
        res[name] = {"grid": list(grid), "elements": list(args[0].data.shape[-2:]),
                     "auto_route": chosen,
                     "dtype": str(args[6]), "rel_l2_nufft_vs_direct": err,
                     "eps": oblique_nufft_eps(args[6]),
                     **{f"{r}_warm_s": warm[r] for r in ROUTES},
                     **{f"{r}_cold_s": cold_m[r] for r in ROUTES},
                     "warm_ratio_nufft_over_direct": warm["nufft"] / warm["direct"],
                     "cold_ratio_nufft_over_direct": cold_m["nufft"] / cold_m["direct"]}
        cold_what = "sum" if _CASES[name] is None else "migrate"
        rows.append(f"| {name} | {grid[0]}x{grid[1]} | {warm['direct'] * 1e3:.2f} ms | "
                    f"{warm['nufft'] * 1e3:.2f} ms | {warm['nufft'] / warm['direct']:.2f}x | "
                    f"{cold_m['direct'] * 1e3:.0f} / {cold_m['nufft'] * 1e3:.0f} ms "
                    f"({cold_what}): {cold_m['nufft'] / cold_m['direct']:.2f}x | {err:.1e} | "
                    f"{chosen} |")
        print(rows[-1], flush=True)
    print("| case | grid | direct (warm) | nufft (warm) | ratio | cold direct / nufft | "
          "rel. L2 | auto |")
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))
    return res


def oblique_nufft_eps(work: np.dtype) -> float:
    from holoradar.imaging.migration.backends.oblique_nufft import EPS
    return EPS[np.dtype(work)]


def _forced(route: str | None, fn):
    """``fn`` (given the ``algorithm``) with the spectrum's route forced (None: the
    default choice)."""
    algorithm = "auto" if route is None else f"ground-{route}"
    return lambda: fn(algorithm)


def against_frontal() -> dict:
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
    cases = {
        "plane": (lambda a: hr.migrate(tilted, z1, medium=SAND, frame="ground", x=gx, y=gy,
                                       algorithm=a),
                  lambda: hr.migrate(frontal, z1, medium=SAND, upsample=4)),
        "volume": (lambda a: hr.migrate(tilted, zs, medium=SAND, frame="ground", x=gx,
                                        y=gy, algorithm=a),
                   lambda: hr.migrate(frontal, zs, medium=SAND, upsample=4)),
    }
    rows = []
    for name, (obl, front) in cases.items():
        runs = {"default": _forced(None, obl), "direct": _forced("direct", obl),
                "nufft": _forced("nufft", obl), "frontal": front}
        cold = {}
        for k, fn in runs.items():
            clear_transfer_cache()
            t0 = time.perf_counter()
            fn()
            cold[k] = time.perf_counter() - t0
        times = {k: [] for k in runs}
        for _ in range(REPEAT):                      # interleaved
            for k, fn in runs.items():
                t0 = time.perf_counter()
                fn()
                times[k].append(time.perf_counter() - t0)
        warm = {k: float(np.median(v)) for k, v in times.items()}
        res[name] = {**{f"{k}_warm_s": w for k, w in warm.items()},
                     **{f"{k}_cold_s": c for k, c in cold.items()},
                     **{f"{k}_warm_ratio": warm[k] / warm["frontal"]
                        for k in ("default", "direct", "nufft")},
                     **{f"{k}_cold_ratio": cold[k] / cold["frontal"]
                        for k in ("default", "direct", "nufft")}}
        rows.append(f"| {name} | " + " | ".join(
            f"{warm[k] * 1e3:.1f} ms ({warm[k] / warm['frontal']:.2f}x)"
            for k in ("default", "direct", "nufft")) + f" | {warm['frontal'] * 1e3:.1f} ms | "
            + " / ".join(f"{cold[k] * 1e3:.0f}" for k in ("default", "direct", "nufft",
                                                            "frontal")) + " ms |")
    print("| case | tilted, default route (warm) | direct | nufft | frontal (warm) | "
          "cold: default / direct / nufft / frontal |")
    print("|---|---|---|---|---|---|")
    print("\n".join(rows))
    return res


def main(parts: tuple[str, ...] = ("spectrum_routes", "against_frontal")) -> dict:
    """Run the parts asked for (default both) and write them into the results file,
    keeping the other part's last figures."""
    out = Path(__file__).with_name("results_oblique.json")
    res = json.loads(out.read_text()) if out.exists() else {}
    res = {k: v for k, v in res.items() if k in ("spectrum_routes", "against_frontal")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for part in parts:
            res[part] = {"spectrum_routes": spectrum_routes,
                         "against_frontal": against_frontal}[part]()
            res[part]["load_average"] = list(os.getloadavg())
    out.write_text(json.dumps(res, indent=1))
    return res


if __name__ == "__main__":
    main(tuple(sys.argv[1:]) or ("spectrum_routes", "against_frontal"))
