"""``detect`` on a volume and on a plane, against one ``migrate`` of the same image.

Cases (fixed seeds):

* ``volume``: two point targets in lossy sand (eps 2.5 + 0.0125j, surface at
  10 cm), 9 frequencies 8-12 GHz, a 32 x 32 monostatic scan at 1 cm, imaged on
  128 planes from 12 to 30 cm at ``upsample=4``: a (128, 125, 125) volume;
  ``detect(img, medium=sand, hologram=h)``.
* ``mat``: the 11-frequency polarised 16 x 16 case, a 3 x 3 rebar mat in concrete
  searched with its hologram (:func:`mat_case`).
* ``plane``: the same scene at 10 GHz, one plane at 18 cm (125 x 125 pixels),
  ``detect(img, medium=sand)`` without the hologram (the aperture's own point
  response, :mod:`holoradar.analysis.detect.psf`).

Each round times ``migrate`` of the case's image and ``detect`` on it, one after
the other (interleaved: a shared machine's load weighs on both alike); medians of
``REPEAT`` rounds after a warm-up round (imports, the point-response tables, the
transfer functions' cache). Reported: wall and CPU seconds (``time.process_time``:
this process's CPU on all its threads) and ``detect / migrate``. The machine's
``os.getloadavg()`` is recorded before and after: with other jobs on it the wall
times stretch, the CPU times much less.

Run: ``.venv/bin/python benchmarks/bench_detect.py [--repeat N] [--out FILE]``
(default: results_detect.json beside this file). ``--label`` names the code
measured (e.g. a baseline checkout run with ``PYTHONPATH=<checkout>/src``);
``--baseline FILE`` embeds such a run's JSON and the speed-ups over it.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import holoradar as hr
from holoradar.analysis.detect import detect

REPEAT = 5


def volume_case() -> dict[str, Any]:
    f = np.linspace(8e9, 12e9, 9)
    ap = hr.Aperture.grid(32, 0.01, monostatic=True)
    sand = hr.Medium.half_space(0.10, 2.5 + 0.0125j)
    pts = [hr.PointTarget((0.03, -0.02, 0.18)), hr.PointTarget((-0.06, 0.05, 0.24), 0.3)]
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(), pts), ap, f, include_surface=False,
                    snr_db=30, seed=1)
    z = np.linspace(0.12, 0.30, 128)

    def mig() -> Any:
        return hr.migrate(h, z, medium=sand, upsample=4)

    img = mig()
    return {"name": "volume", "shape": list(img.data.shape), "migrate": mig,
            "detect": lambda: detect(img, medium=sand, hologram=h, progress=False)}


def mat_case() -> dict[str, Any]:
    """The 11-frequency polarised 16 x 16 case: a rebar mat in concrete (6 + 0.3j, surface
    20 cm below the paper's array at 2.5 cm), three bars along x under 4 cm crossing three
    along y under 6 cm, 12.5 cm apart, 8-12 GHz, 30 dB, E_y; the volume 2 to 8.5 cm
    deep at four pixels per pitch, searched with its hologram (its noise not given)."""
    z0, r = 0.20, 0.006
    concrete = hr.Medium.half_space(z0, 6 + 0.3j)
    at = (-0.125, 0.0, 0.125)
    bars = [hr.LineTarget((-0.3, y, z0 + 0.04 + r), (0.3, y, z0 + 0.04 + r), r) for y in at]
    bars += [hr.LineTarget((x, -0.3, z0 + 0.06 + r), (x, 0.3, z0 + 0.06 + r), r) for x in at]
    pol = (0, 1, 0)
    h = hr.simulate(hr.Scene(concrete, hr.PlaneWave(polarization=pol), bars),
                    hr.Aperture.grid(16, 0.025, polarization=pol), np.linspace(8e9, 12e9, 11),
                    include_surface=False, snr_db=30, seed=1)
    z = np.arange(z0 + 0.02, z0 + 0.085, 0.005)

    def mig() -> Any:
        return hr.migrate(h, z, medium=concrete, upsample=4)

    img = mig()
    return {"name": "mat", "shape": list(img.data.shape), "migrate": mig,
            "detect": lambda: detect(img, medium=concrete, hologram=h, progress=False)}


def plane_case() -> dict[str, Any]:
    ap = hr.Aperture.grid(32, 0.01, monostatic=True)
    sand = hr.Medium.half_space(0.10, 2.5 + 0.0125j)
    pts = [hr.PointTarget((0.03, -0.02, 0.18)), hr.PointTarget((-0.06, 0.05, 0.18), 0.3)]
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(), pts), ap, 10e9, include_surface=False,
                    snr_db=30, seed=1)

    def mig() -> Any:
        return hr.migrate(h, 0.18, medium=sand, upsample=4)

    img = mig()
    return {"name": "plane", "shape": list(img.data.shape), "migrate": mig,
            "detect": lambda: detect(img, medium=sand)}


def timed(fn: Any) -> tuple[float, float, Any]:
    t, c = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - t, time.process_time() - c, out


def run_case(case: dict[str, Any], repeat: int) -> dict[str, Any]:
    df = case["detect"]()                    # warm-up: imports, tables, caches
    case["migrate"]()
    rows: dict[str, list[float]] = {k: [] for k in ("migrate_wall", "migrate_cpu",
                                                    "detect_wall", "detect_cpu")}
    for _ in range(repeat):
        w, c, _ = timed(case["migrate"])
        rows["migrate_wall"].append(w)
        rows["migrate_cpu"].append(c)
        w, c, df = timed(case["detect"])
        rows["detect_wall"].append(w)
        rows["detect_cpu"].append(c)
    med = {k: statistics.median(v) for k, v in rows.items()}
    return {"case": case["name"], "shape": case["shape"], "runs": rows,
            "median": med,
            "ratio_wall": med["detect_wall"] / med["migrate_wall"],
            "ratio_cpu": med["detect_cpu"] / med["migrate_cpu"],
            "objects": df[["kind", "x", "y", "range", "snr_db"]].to_dict("records")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=REPEAT)
    ap.add_argument("--label", default="current")
    ap.add_argument("--out", type=Path, default=Path(__file__).with_name("results_detect.json"))
    ap.add_argument("--baseline", type=Path, default=None,
                    help="a JSON this script wrote for other code (e.g. the checkout before "
                         "a change): kept under 'baseline', with the speed-ups")
    args = ap.parse_args()
    warnings.filterwarnings("ignore", category=hr.AliasingWarning)
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                                cwd=Path(hr.__file__).parent, check=False).stdout.strip()
    except OSError:
        commit = ""
    load_before = os.getloadavg()
    results = [run_case(volume_case(), args.repeat), run_case(mat_case(), args.repeat),
               run_case(plane_case(), args.repeat)]
    out = {"label": args.label, "holoradar": str(Path(hr.__file__).parent), "commit": commit,
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                       "loadavg_before": load_before, "loadavg_after": os.getloadavg()},
           "env": {k: os.environ.get(k) for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")},
           "repeat": args.repeat, "results": results}
    if args.baseline is not None:
        base = json.loads(args.baseline.read_text())
        out["baseline"] = base
        out["speedup"] = {
            r["case"]: {k: b["median"][k] / r["median"][k] for k in ("detect_wall", "detect_cpu")}
            | {"ratio_cpu_before": b["ratio_cpu"], "ratio_cpu_after": r["ratio_cpu"]}
            for r in results for b in base["results"] if b["case"] == r["case"]}
    for r in results:
        m = r["median"]
        print(f"{r['case']:7s} {r['shape']}: detect {m['detect_wall']:.2f} s wall "
              f"({m['detect_cpu']:.2f} s CPU), migrate {m['migrate_wall']:.2f} s "
              f"({m['migrate_cpu']:.2f} s CPU); detect/migrate {r['ratio_wall']:.2f} wall, "
              f"{r['ratio_cpu']:.2f} CPU")
    print("load average before/after:", load_before, out["machine"]["loadavg_after"])
    tmp = args.out.with_name(args.out.name + ".tmp")
    tmp.write_text(json.dumps(out, indent=1, default=float) + "\n")
    tmp.replace(args.out)


if __name__ == "__main__":
    main()
