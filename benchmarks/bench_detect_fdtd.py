"""``detect`` with the hologram on the project's full-wave mats, stage by stage.

Cases: the G suite's FDTD scans in tests/data (gprMax; 25 x 25 at 1 cm, 21
frequencies 9-11 GHz, 30 dB of receiver noise added with a fixed seed, the field per
unit current divided by the frequency), each imaged by ``migrate`` onto planes every
2.5 mm from 1 to 12 cm under the surface, then ``detect(img, hologram=h, medium=...)``
with the defaults, in this process after a warm-up call on the same case.

Each stage's time is the cumulative time of its function under ``cProfile`` (the
profiler slows pure-Python parts more than NumPy and FFT work, so the shares are
indicative; the total is also timed without the profiler): the image check
(``HologramModel.start``), the noise estimate (``noise_std``), the inversion
(``reflectivity``, with its solver steps), the objects read off it (``_objects``, the
joins), and the points' refinement (``_refine_points``). Reported with the objects
found and the truth's count.

Run: ``.venv/bin/python benchmarks/bench_detect_fdtd.py [--cases G_mat1_top ...]``
(writes results_detect_fdtd.json beside this file).
"""

from __future__ import annotations

import argparse
import cProfile
import json
import os
import pstats
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "tests"))

import holoradar as hr  # noqa: E402
from fdtd_suite import load  # noqa: E402

STAGES = {"image check": "start", "noise estimate": "noise_std", "inversion": "reflectivity",
          "solver steps": "sparse", "objects": "_objects", "point refinement": "_refine_points"}


def _case(name: str) -> tuple[hr.Hologram, hr.Image, hr.Medium]:
    case = load(name)
    h = case.hologram
    rng = np.random.default_rng(7)
    s = np.sqrt(np.mean(np.abs(h.data) ** 2)) / 10 ** (30 / 20)
    noise = s * (rng.standard_normal(h.data.shape) + 1j * rng.standard_normal(h.data.shape))
    h = h.with_data(h.data + noise / np.sqrt(2))
    zs = np.arange(case.surface + 0.01, case.surface + 0.12, 0.0025)
    return h, hr.migrate(h, zs, medium=case.ground), case.ground


def run_case(name: str) -> dict:
    h, img, ground = _case(name)
    hr.detect(img, hologram=h, medium=ground, progress=False)          # warm-up
    t0 = time.perf_counter()
    df = hr.detect(img, hologram=h, medium=ground, progress=False)
    total = time.perf_counter() - t0
    prof = cProfile.Profile()
    prof.runcall(hr.detect, img, hologram=h, medium=ground, progress=False)
    stats = pstats.Stats(prof).stats
    stages = {}
    for stage, fn in STAGES.items():
        times = [v[3] for (path, _, func), v in stats.items()
                 if func == fn and "holoradar" in path]
        stages[stage] = float(max(times)) if times else 0.0
    return {"case": name, "shape": list(img.data.shape), "detect_s": total,
            "steps": int(df.attrs["inversion"]["iterations"]),
            "stages_s_profiled": stages, "objects": df["kind"].tolist()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="*", default=["G_mat1_top", "G_mat2_ydip"])
    ap.add_argument("--out", type=Path, default=HERE / "results_detect_fdtd.json")
    args = ap.parse_args()
    warnings.filterwarnings("ignore")
    load_before = os.getloadavg()
    results = [run_case(c) for c in args.cases]
    for r in results:
        parts = ", ".join(f"{k} {v:.1f} s" for k, v in r["stages_s_profiled"].items())
        print(f"{r['case']} {r['shape']}: detect {r['detect_s']:.1f} s, {r['steps']} steps, "
              f"{len(r['objects'])} objects ({parts}; profiled)")
    out = {"machine": {"cpus": os.cpu_count(), "loadavg_before": load_before,
                       "loadavg_after": os.getloadavg()}, "results": results}
    tmp = args.out.with_name(args.out.name + ".tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(args.out)


if __name__ == "__main__":
    main()
