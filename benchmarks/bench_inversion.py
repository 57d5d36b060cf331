"""The inversion's cost: per step against the operator, and whole problems.

Part 1, ``step``: a solver step against one ``matvec`` + ``rmatvec`` pair of the same
operator (the floor: each step of LSQR and of FISTA needs one of each). A step's time
is the difference of two runs that differ only in their number of steps (the set-up,
the noise estimate, the column norms and FISTA's largest eigenvalue, cancel), over
that difference; the pair is timed in the same process, the best of several, and the
time inside the operator's two maps during the same runs is counted too (a step over
its own operator time: the solver's overhead, free of the machine's load). Case: a
32 x 32 array at 1.25 cm, one frequency, through sand, onto 10 planes at 2x upsampling.

Part 2, ``sizes``: wall time and steps of ``hr.invert`` with its defaults (noise
estimated, stopped at the noise) on

* ``paper``: the paper's 16 x 16 array (2.5 cm), one frequency, a point 12 cm deep in
  sand, onto 61 x 61 x 40 voxels (upsample 4; the 2.5 cm pitch is sampled at lambda/2
  by the operator, so 2 x 2 of the image's pixels per fine sample);
* ``rod``: the gprMax rod (41 x 41 at 1 cm, 21 frequencies, its dipole beside the
  array) onto 81 x 81 x 40 voxels (upsample 2).

Part 3, ``validation``: the steps to the stop of each validation case of the tests.

Run: ``.venv/bin/python benchmarks/bench_inversion.py [step] [sizes] [validation]``;
merges what ran into ``benchmarks/results_inversion.json`` and prints it.
"""

from __future__ import annotations

import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import holoradar as hr

warnings.simplefilter("ignore", hr.AliasingWarning)
ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results_inversion.json"
Y = (0, 1, 0)


def _t(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def step() -> dict:
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(polarization=Y),
                             [hr.PointTarget((0.01, 0.0, 0.42))]),
                    hr.Aperture.grid(32, 0.0125, polarization=Y), 9.9e9,
                    include_surface=False, snr_db=30, seed=1)
    zs = np.linspace(0.36, 0.48, 10)
    from holoradar.imaging.inversion.api import _options

    A = hr.migration_operator(h, zs, medium=sand, **{**_options(h, zs, {}), "upsample": 2})
    x = np.ones(A.shape[1], A.dtype)
    y = np.ones(A.shape[0], A.dtype)
    A @ x, A.H @ y   # warm
    pair = min(_t(lambda: (A @ x, A.H @ y)) for _ in range(20))
    out = {"voxels": int(A.shape[1]), "samples": int(A.shape[0]), "pair_s": pair}
    # The operator's own time inside each run, counted around its two maps: the same
    # minutes as the steps (the machine's load cancels in the ratio).
    from holoradar.imaging.migration.linear import MigrationOperator

    spent = [0.0]
    plain = {k: getattr(MigrationOperator, k) for k in ("_apply_forward", "_apply_adjoint")}

    def timed(fn):
        def inner(self, X):
            t0 = time.perf_counter()
            try:
                return fn(self, X)
            finally:
                spent[0] += time.perf_counter() - t0
        return inner

    for k, fn in plain.items():
        setattr(MigrationOperator, k, timed(fn))
    try:
        for method, (n1, n2) in (("lsqr", (10, 60)), ("sparse", (50, 250))):
            # noise tiny: least squares does not reach it early; the runs differ in steps
            run, ops = {}, {}
            for n in (n1, n2):
                best = None
                for _ in range(3):
                    spent[0] = 0.0
                    t = _t(lambda n=n, m=method: hr.invert(h, zs, medium=sand, method=m,
                                                 upsample=2, noise=1e-12, max_iter=n,
                                                 progress=False))
                    if best is None or t < best[0]:
                        best = (t, spent[0])
                run[n], ops[n] = best
            per = (run[n2] - run[n1]) / (n2 - n1)
            per_ops = (ops[n2] - ops[n1]) / (n2 - n1)
            out[method] = {"step_s": per, "step_over_pair": per / pair,
                           "operator_s_per_step": per_ops,
                           "step_over_its_operator_time": per / per_ops}
    finally:
        for k, fn in plain.items():
            setattr(MigrationOperator, k, fn)
    return out


def sizes() -> dict:
    out = {}
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget((0.02, -0.01, 0.42))]),
                    hr.Aperture.paper(), 9.9e9, include_surface=False, snr_db=30, seed=2)
    zs = np.linspace(0.32, 0.52, 40)
    for method in ("lsqr", "sparse"):
        t0 = time.perf_counter()
        r = hr.invert(h, zs, medium=sand, method=method, upsample=4, progress=False)
        out[f"paper_{method}"] = {"voxels": list(r.data.shape), "wall_s":
                                  time.perf_counter() - t0, **_steps(r)}
    data = ROOT / "tests" / "data"
    with np.load(data / "run_B_background.npz") as b, np.load(data / "run_C_rod.npz") as c:
        f = b["freqs_hz"].astype(float)
        scat = c["Ey"].astype(complex) - b["Ey"].astype(complex)
        x, y = b["x_m"].copy(), b["y_m"].copy()
    sand = hr.Medium.half_space(0.30, hr.permittivity(2.5, sigma=0.0069, frequency=9.9e9))
    h = hr.Hologram(scat, x, y, f, source=hr.PointSource((-0.2, 0.0, 0.2), axis=Y, dipole=True))
    zs = np.linspace(0.34, 0.48, 40)
    t0 = time.perf_counter()
    r = hr.invert(h, zs, medium=sand, upsample=2, progress=False)
    out["rod_lsqr"] = {"voxels": list(r.data.shape), "wall_s": time.perf_counter() - t0,
                       **_steps(r)}
    return out


def _steps(r: hr.Image) -> dict:
    s = r.history[0]
    return {"steps": s["iterations"], "stop": s["stop"],
            "residual_over_noise": s["residual_over_noise"]}


def validation() -> dict:
    out = {}
    z = 0.4
    cell = hr.C0 / 9.9e9 * z / 0.4
    arr = hr.Aperture.grid(32, 0.0125, polarization=Y)
    two = hr.simulate(hr.Scene(hr.Medium.free_space(), hr.PlaneWave(polarization=Y),
                               [hr.PointTarget((-0.3 * cell, 0.0, z)),
                                hr.PointTarget((0.3 * cell, 0.0, z))]), arr, 9.9e9,
                      snr_db=30, seed=1)
    out["two_points_sparse"] = _steps(hr.invert(two, z, method="sparse", upsample=2,
                                                progress=False))
    concrete = hr.Medium.half_space(0.20, 6.0 + 0.3j)
    bars = [hr.LineTarget((xb, -0.15, 0.25), (xb, 0.15, 0.25), radius=0.006)
            for xb in (-0.12, 0.0, 0.12)]
    h = hr.simulate(hr.Scene(concrete, hr.Dipole((-0.25, 0.0, 0.05), Y), bars),
                    hr.Aperture.grid(41, 0.01, polarization=Y), np.linspace(8e9, 12e9, 5),
                    include_surface=False, snr_db=30, seed=3)
    out["bars_lsqr"] = _steps(hr.invert(h, np.arange(0.22, 0.29, 0.01), medium=concrete,
                                        progress=False))
    sand = hr.Medium.half_space(0.50, 2.5 + 0.0125j)
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(polarization=Y),
                             [hr.PointTarget((0.01, -0.005, 0.60))]), arr, 9.9e9,
                    include_surface=False, snr_db=30, seed=4)
    out["raised_point_sparse"] = _steps(hr.invert(h, np.arange(0.50, 0.71, 0.01), medium=sand,
                                                  method="sparse", progress=False))
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    ap = hr.Aperture.grid(24, 0.0125, polarization=(1, 0, 0), pose=hr.Pose(
        (0.0, -0.15, 0.05), tilt=np.radians(35), azimuth=np.radians(90)))
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(polarization=(1, 0, 0)),
                             [hr.PointTarget((0.0, 0.05, 0.42))]), ap, 9.9e9,
                    include_surface=False, snr_db=30, seed=4)
    out["tilted_point_sparse"] = _steps(hr.invert(
        h, np.arange(0.34, 0.55, 0.01), medium=sand, method="sparse", progress=False,
        frame="ground", x=np.arange(-0.04, 0.0401, 0.005), y=np.arange(0.01, 0.0901, 0.005)))
    return out


if __name__ == "__main__":
    parts = [a for a in sys.argv[1:] if a in ("step", "sizes", "validation")] or \
        ["step", "sizes", "validation"]
    results = json.loads(OUT.read_text()) if OUT.exists() else {}
    for part in parts:
        results[part] = globals()[part]()
        print(part, json.dumps(results[part], indent=1))
    results["machine"] = {"cpus": __import__("os").cpu_count()}
    OUT.write_text(json.dumps(results, indent=1) + "\n")
