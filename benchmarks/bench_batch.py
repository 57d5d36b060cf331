"""Survey throughput: ``run_batch`` with 1 and 2 workers against a plain loop of
``load`` + ``migrate`` over the same files, in one run.

For each case (by default 200 frames of 32 x 32 elements imaged on 9 planes at
``upsample=2``, 63 x 63 pixels a plane, and 100 frames of 128 x 128 on 9 planes
at ``upsample=1``; random fields, complex128, 1 cm pitch at 9.9 GHz, placed
along x), the frames are saved as NetCDF files and timed, interleaved round by
round (a shared machine's other load then weighs on all alike; medians of
``REPEAT`` rounds):

* ``bare``: ``migrate`` alone on the holograms in memory;
* ``loop``: ``migrate(load(path))`` over the files, nothing stored (the floor a
  batch is measured against);
* ``batch1``: ``run_batch(..., workers=1)`` into a fresh store (this process);
* ``batch2``: ``run_batch(..., workers=2)``, the local cluster started for the run
  and closed after it, as ``holoradar batch --workers 2`` does: its start counts;
* ``batch2_warm``: on the local cluster ``--workers 2`` starts (one thread a worker),
  started before the clock (its address as ``scheduler``): the steady throughput of
  two workers.

Then, the ceiling two workers can reach on this machine: the plain loop in two
fresh processes side by side (one thread each, half the frames each, timed inside
each after three warm-up frames), against the same loop in one such process
(``loop_one_process``, ``loop_two_processes``; ratio 0.5 where two cores give twice
the throughput).

Then cold, once each, in fresh Python processes (imports, first FFTs and the
cluster's start count): the loop, ``workers=1`` and ``workers=2``.

Ratios are batch / loop per frame (1.0: as fast as the loop; 0.5: twice as
fast). ``os.getloadavg()`` is recorded before and after: the machine is shared,
and other jobs' load slows the two-worker cases most.

Run: ``.venv/bin/python benchmarks/bench_batch.py [--quick]`` (writes
results_batch.json beside this file).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import holoradar as hr

F0 = 9.9e9
PITCH = 0.01
REPEAT = 5
CASES = ({"frames": 200, "size": 32, "planes": 9, "upsample": 2},
         {"frames": 100, "size": 128, "planes": 9, "upsample": 1})


def make_frames(folder: Path, n: int, size: int) -> tuple[list[Path], list[hr.Hologram]]:
    rng = np.random.default_rng(0)
    x = (np.arange(size) - (size - 1) / 2) * PITCH
    folder.mkdir(parents=True, exist_ok=True)
    paths, holos = [], []
    for i in range(n):
        data = rng.standard_normal((size, size)) + 1j * rng.standard_normal((size, size))
        h = hr.Hologram(data, x, x, F0, pose=hr.Pose((0.5 * size * PITCH * i, 0.0, 0.0)))
        paths.append(hr.save(h, folder / f"frame{i:04d}.nc"))
        holos.append(h)
    return paths, holos


def timed(fn) -> tuple[float, float]:
    """Wall and CPU (this process, all its threads) seconds of ``fn()``."""
    c0, t0 = time.process_time(), time.perf_counter()
    fn()
    return time.perf_counter() - t0, time.process_time() - c0


_COLD = """
import sys, time
t0 = time.perf_counter()
import numpy as np
import holoradar as hr
mode, listing, store, planes, upsample = sys.argv[1:6]
paths = open(listing).read().split()
z = list(np.linspace(0.2, 0.4, int(planes)))
if mode == "loop":
    for p in paths:
        hr.migrate(hr.load(p), z, upsample=int(upsample))
else:
    s = hr.survey.run_batch(paths, store, z=z, upsample=int(upsample), workers=int(mode))
    assert s["done"] == len(paths), s
print(time.perf_counter() - t0)
"""


def cold(mode: str, paths: list[Path], work: Path, planes: int, upsample: int) -> float:
    """Seconds of a fresh Python process imaging the frames (imports included)."""
    listing = work / "frames.txt"
    listing.write_text("\n".join(map(str, paths)))
    store = work / f"cold_{mode}.zarr"
    code = "if __name__ == '__main__':\n" + "\n".join("    " + ln for ln in
                                                    _COLD.strip().splitlines())
    out = subprocess.run([sys.executable, "-c", code, mode, str(listing), str(store),
                          str(planes), str(upsample)], capture_output=True, text=True,
                         check=True, env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})
    shutil.rmtree(store, ignore_errors=True)
    return float(out.stdout.strip().splitlines()[-1])


_LOOP = """
import sys, time
import numpy as np
import holoradar as hr
paths = open(sys.argv[1]).read().split()
a, b, up, planes = map(int, sys.argv[2:6])
z = list(np.linspace(0.2, 0.4, planes))
for p in paths[:3]:
    hr.migrate(hr.load(p), z, upsample=up)
t0 = time.perf_counter()
for p in paths[a:b]:
    hr.migrate(hr.load(p), z, upsample=up)
print(time.perf_counter() - t0)
"""


def two_processes(paths: list[Path], work: Path, planes: int, upsample: int
                  ) -> tuple[float, float]:
    """ms per frame of the plain loop in one fresh one-thread process, and in two side
    by side on half the frames each (the slower of the two), imports excluded."""
    listing = work / "loop_frames.txt"
    listing.write_text("\n".join(map(str, paths)))
    env = {**os.environ, "HOLORADAR_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1"}

    def start(a: int, b: int) -> subprocess.Popen:
        return subprocess.Popen([sys.executable, "-c", _LOOP, str(listing), str(a), str(b),
                                 str(upsample), str(planes)], stdout=subprocess.PIPE,
                                text=True, env=env)

    n = len(paths)
    one = float(start(0, n).communicate()[0])
    procs = [start(0, n // 2), start(n // 2, n)]
    two = max(float(p.communicate()[0]) for p in procs)
    return 1e3 * one / n, 1e3 * two / n


def run_case(case: dict, work: Path, repeat: int, cluster_address: str) -> dict:
    n, size, planes, up = case["frames"], case["size"], case["planes"], case["upsample"]
    paths, holos = make_frames(work / f"f{size}", n, size)
    z = list(np.linspace(0.2, 0.4, planes))
    k = [0]

    def batch(**kw) -> None:
        k[0] += 1
        s = hr.survey.run_batch(paths, work / f"s{k[0]}.zarr", z=z, upsample=up, **kw)
        assert s["done"] == n and not s["skipped"], s

    def clean() -> None:  # the stores of a round, removed outside the clock
        for old in work.glob("s*.zarr"):
            shutil.rmtree(old, ignore_errors=True)

    for h in holos[:3]:
        hr.migrate(h, z, upsample=up)  # warm this process (imports, FFT plans)
    # Bit for bit: the stored images are the loop's (checked on a few frames).
    store = work / "check.zarr"
    hr.survey.run_batch(paths[:20], store, z=z, upsample=up, workers=1)
    for i in (0, 7, 19):
        assert np.array_equal(hr.survey.frame_image(store, i).data,
                              hr.migrate(hr.load(paths[i]), z, upsample=up).data)
    shutil.rmtree(store)
    batch(scheduler=cluster_address)  # the warm cluster's workers: imports done
    clean()
    cases = {
        "bare": lambda: [hr.migrate(h, z, upsample=up) for h in holos],
        "loop": lambda: [hr.migrate(hr.load(p), z, upsample=up) for p in paths],
        "batch1": lambda: batch(workers=1),
        "batch2": lambda: batch(workers=2),
        "batch2_warm": lambda: batch(scheduler=cluster_address),
    }
    wall: dict[str, list[float]] = {c: [] for c in cases}
    cpu: dict[str, list[float]] = {c: [] for c in cases}
    load = [os.getloadavg()[0]]
    for _ in range(repeat):
        for name, fn in cases.items():
            w, c = timed(fn)
            wall[name].append(w)
            cpu[name].append(c)
        clean()
        load.append(os.getloadavg()[0])
    med = {c: float(np.median(v)) / n for c, v in wall.items()}
    res = {**case, "pixels": [planes, up * (size - 1) + 1, up * (size - 1) + 1],
           "ms_per_frame": {c: 1e3 * v for c, v in med.items()},
           "ms_per_frame_all": {c: [1e3 * w / n for w in v] for c, v in wall.items()},
           "cpu_ms_per_frame_this_process": {c: 1e3 * float(np.median(v)) / n
                                             for c, v in cpu.items()},
           "ratio_to_loop": {c: med[c] / med["loop"] for c in ("batch1", "batch2",
                                                               "batch2_warm")},
           "loadavg_1min": load}
    tries = [two_processes(paths, work, planes, up) for _ in range(2)]
    res["loop_one_process_ms"] = float(np.median([t[0] for t in tries]))
    res["loop_two_processes_ms"] = float(np.median([t[1] for t in tries]))
    res["two_processes_ratio"] = res["loop_two_processes_ms"] / res["loop_one_process_ms"]
    res["cold_s"] = {m: cold(m, paths, work, planes, up) for m in ("loop", "1", "2")}
    res["cold_ratio_to_loop"] = {m: res["cold_s"][m] / res["cold_s"]["loop"]
                                 for m in ("1", "2")}
    res["loadavg_1min"].append(os.getloadavg()[0])
    return res


def main() -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="2 rounds, a quarter of the frames")
    ap.add_argument("--out", default=str(Path(__file__).with_name("results_batch.json")))
    args = ap.parse_args()
    from holoradar.survey.schedule import local_cluster

    repeat = 2 if args.quick else REPEAT
    cases = [{**c, "frames": c["frames"] // 4} for c in CASES] if args.quick else CASES
    work = Path(tempfile.mkdtemp(prefix="bench_batch_"))
    res: dict = {"machine": f"{platform.machine()}, {os.cpu_count()} cores, "
                            f"{platform.python_implementation()} {platform.python_version()}",
                 "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                 "repeat": repeat, "note": "medians of interleaved rounds; the machine is "
                 "shared with other jobs (loadavg_1min: before, after each round, after "
                 "the cold runs)", "cases": []}
    # The cluster `--workers 2` starts (one thread a worker, glibc's memory handling),
    # started before the clock.
    cluster, client = local_cluster(2)
    try:
        with cluster, client:
            for case in cases:
                r = run_case(case, work, repeat, cluster.scheduler_address)
                res["cases"].append(r)
                ms = r["ms_per_frame"]
                print(f"{r['frames']} frames of {r['size']} x {r['size']}, "
                      f"{r['planes']} planes of {r['pixels'][1]} x {r['pixels'][2]} "
                      f"(load {', '.join(f'{v:.1f}' for v in r['loadavg_1min'])})")
                for c in ("bare", "loop", "batch1", "batch2", "batch2_warm"):
                    ratio = r["ratio_to_loop"].get(c)
                    print(f"  {c:12s} {ms[c]:7.2f} ms/frame"
                          + (f"   {ratio:.2f} x loop" if ratio else ""))
                print(f"  plain loop, one process {r['loop_one_process_ms']:.2f}, two side by "
                      f"side {r['loop_two_processes_ms']:.2f} ms/frame "
                      f"({r['two_processes_ratio']:.2f})")
                print("  cold (fresh process): " + ", ".join(
                    f"{m} {v:.2f} s" for m, v in r["cold_s"].items()))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    Path(args.out).write_text(json.dumps(res, indent=1) + "\n")
    return res


if __name__ == "__main__":
    main()
