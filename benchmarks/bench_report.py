"""``hr.report`` of a survey: seconds for a 100-frame store, and the share that is the
detection itself.

A survey of ``--frames`` frames (16 x 16 elements at 1.25 cm, 9.9 GHz, 10 cm apart
along x: each point seen by two frames) over sand (eps 2.5 + 0.0125i, surface 30 cm
below the arrays) with a point scatterer 12 cm deep every 25 cm, 30 dB, is simulated
with holoradar's simulator, saved frame by frame and imaged by
:func:`holoradar.survey.run_batch` into a store (one plane, the points' range, four
pixels per pitch). Then, interleaved ``--repeat`` times (the machine is shared:
medians):

* ``detect``: the store's objects as ``holoradar detect STORE --z`` finds them (each
  frame searched, the objects merged in survey coordinates), the floor of any report;
* ``report``: ``hr.report(STORE, "survey.html", z=...)``, the same detection plus the
  mosaic's plan view, the page and its atomic write;
* ``report_given``: ``hr.report`` with the table given (``detections=``): the
  report's own part (mosaic, pictures, page, write).
Both from the stored plane alone (``--z``, the image's own point response); with
``--fit`` also with each frame's hologram fitted (``holoradar detect STORE``'s
default), which costs about a second per frame.

Run: ``.venv/bin/python benchmarks/bench_report.py [--frames 100] [--repeat 3] [--fit]``
(writes results_report.json beside this file).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import holoradar as hr

F0 = 9.9e9
SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
DEPTH = 0.42
STEP = 0.10


def make_survey(folder: Path, n: int) -> tuple[Path, int]:
    """The frames' files and the store; the number of points laid under the survey."""
    xs = np.arange(0.0, STEP * (n - 1) + 1e-9, 0.25)
    points = [hr.PointTarget((float(x), 0.03 * (-1) ** k, DEPTH)) for k, x in enumerate(xs)]
    paths = []
    for i in range(n):
        x0 = STEP * i
        near = [p for p in points if abs(p.position[0] - x0) < 0.3]
        ap = hr.Aperture.grid(16, 0.0125, pose=hr.Pose((x0, 0.0, 0.0)))
        h = hr.simulate(hr.Scene(SAND, hr.PlaneWave(), near), ap, F0, include_surface=False,
                        snr_db=30, seed=i)
        paths.append(hr.save(h, folder / f"frame{i:04d}.nc"))
    store = folder / "survey.zarr"
    hr.survey.run_batch(paths, store, z=[DEPTH], medium=SAND, upsample=4,
                        scheduler="synchronous")
    return store, len(points)


def detect_only(store: Path, z: float | None, table: bool = False) -> object:
    """``holoradar detect STORE``'s work: the objects of every frame, merged (their
    number, or with ``table`` the table)."""
    from holoradar.survey.detect import from_store

    df, _, _ = from_store(store, z, {"false_alarm": 1e-3, "kinds": ("point", "line", "area"),
                                     "eps_interval": None})
    return df if table else len(df)


def timed(fn) -> tuple[float, object]:
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def main() -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--fit", action="store_true",
                    help="also time the hologram fit (each frame's hologram read again)")
    ap.add_argument("--keep", default=None, help="copy the plane report here")
    ap.add_argument("--out", default=str(Path(__file__).with_name("results_report.json")))
    args = ap.parse_args()
    warnings.simplefilter("ignore", hr.AliasingWarning)
    work = Path(tempfile.mkdtemp(prefix="bench_report_"))
    try:
        t_make, (store, n_points) = timed(lambda: make_survey(work, args.frames))
        out = work / "survey.html"
        given = {}
        cases = {
            "detect_plane": lambda: given.setdefault("df", detect_only(store, DEPTH, True)),
            "report_plane": lambda: hr.report(store, out, force=True, z=DEPTH),
            "report_given": lambda: hr.report(store, out, force=True,
                                              detections=given["df"]),
        }
        if args.fit:
            cases.update({"detect": lambda: detect_only(store, None),
                          "report": lambda: hr.report(store, out, force=True)})
        # warm: imports, compiled kernels, the store's files in the page cache (not timed)
        small, _ = make_survey(Path(tempfile.mkdtemp(dir=work)), 2)
        hr.report(small, work / "warm.html", z=DEPTH)
        detect_only(store, DEPTH)
        if args.fit:
            hr.report(small, work / "warm.html", force=True)
        wall: dict[str, list[float]] = {c: [] for c in cases}
        result: dict[str, object] = {}
        load = [os.getloadavg()[0]]
        for _ in range(args.repeat):
            for name, fn in cases.items():
                s, r = timed(fn)
                wall[name].append(s)
                result[name] = r
            load.append(os.getloadavg()[0])
        med = {c: float(np.median(v)) for c, v in wall.items()}
        res = {
            "machine": f"{platform.machine()}, {os.cpu_count()} cores, "
                       f"{platform.python_implementation()} {platform.python_version()}",
            "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "note": "medians of interleaved rounds; the machine is shared with other jobs "
                    "(loadavg_1min: before and after each round)",
            "frames": args.frames, "points_laid": n_points, "repeat": args.repeat,
            "make_survey_s": t_make,
            "seconds": med, "seconds_all": wall,
            "ratio_report_to_detect_plane": med["report_plane"] / med["detect_plane"],
            "report_own_share": med["report_given"] / med["report_plane"],
            "objects": {"plane": result["report_plane"]["n_objects"]},
            "report_bytes": {"plane": result["report_plane"]["bytes"]},
            "loadavg_1min": load,
        }
        if args.fit:
            res["ratio_report_to_detect"] = med["report"] / med["detect"]
            res["objects"]["hologram"] = result["report"]["n_objects"]
            res["report_bytes"]["hologram"] = result["report"]["bytes"]
        if args.keep:
            hr.report(store, args.keep, force=True, z=DEPTH)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"{args.frames} frames ({n_points} points laid), load "
          + ", ".join(f"{v:.1f}" for v in load))
    for c, v in med.items():
        print(f"  {c:13s} {v:6.2f} s")
    print(f"  report / detect: {res['ratio_report_to_detect_plane']:.2f} (plane)"
          + (f", {res['ratio_report_to_detect']:.2f} (fit)" if args.fit else "")
          + f"; report {res['report_bytes']['plane'] / 1e3:.0f} kB, "
          f"{res['objects']['plane']} objects")
    Path(args.out).write_text(json.dumps(res, indent=1) + "\n")
    return res


if __name__ == "__main__":
    main()
