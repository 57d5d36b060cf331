"""Start-up time: ``import holoradar``, ``holoradar --version`` and ``holoradar --help``.

Each case runs in a fresh interpreter, round-robin with the floors it is compared
with in the same run: a bare ``python -c pass`` (the interpreter itself) and
``import numpy`` (what holoradar cannot do without). The fastest and the median of
``--repeat`` runs are reported: the fastest is the least disturbed by the other
work on a shared machine, the median what a user sees on it.

Two bytecode settings:

- ``cached``: the modules' compiled bytecode is kept (in a temporary
  ``PYTHONPYCACHEPREFIX``, so the tree is untouched) and warmed before timing, as
  for an installed package;
- ``source``: ``PYTHONDONTWRITEBYTECODE=1`` and no cache for holoradar's own
  modules, as in this repository's development environment (every run compiles
  them; site-packages keep their own caches).

``-X importtime`` of one ``import holoradar`` (cached) gives the breakdown by
package (their own import time, summed), written beside the timings.

Run: ``.venv/bin/python benchmarks/bench_startup.py [--repeat 15] [--src DIR]``;
``--src`` times another copy of the package (e.g. an older commit's ``src``, from
``git archive``) through ``PYTHONPATH``. Writes ``benchmarks/results_startup.json``
(``--out`` to change).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent


def cases(python: str) -> dict[str, list[str]]:
    """Command lines to time, by name; the console script when it is installed."""
    script = Path(python).with_name("holoradar")
    cli = [str(script)] if script.exists() else [python, "-m", "holoradar"]
    return {
        "python -c pass": [python, "-c", "pass"],
        "import numpy": [python, "-c", "import numpy"],
        "import holoradar": [python, "-c", "import holoradar"],
        "holoradar --version": [*cli, "--version"],
        "holoradar --help": [*cli, "--help"],
    }


def environment(mode: str, cache: Path, src: Path | None) -> dict[str, str]:
    env = dict(os.environ)
    env.pop("PYTHONPYCACHEPREFIX", None)
    if mode == "cached":
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(cache)
    else:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
    if src is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(src), env.get("PYTHONPATH", "")]).rstrip(
            os.pathsep)
    return env


def run_once(cmd: list[str], env: dict[str, str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def time_cases(commands: dict[str, list[str]], env: dict[str, str], repeat: int
               ) -> dict[str, dict[str, float]]:
    for cmd in commands.values():  # warm the bytecode cache and the page cache
        run_once(cmd, env)
    samples: dict[str, list[float]] = {name: [] for name in commands}
    for _ in range(repeat):  # round-robin: a burst of load touches every case alike
        for name, cmd in commands.items():
            samples[name].append(run_once(cmd, env))
    return {name: {"min_s": min(s), "median_s": statistics.median(s)}
            for name, s in samples.items()}


def breakdown(python: str, env: dict[str, str], runs: int = 3) -> dict[str, float]:
    """Own import time per package (ms) in ``import holoradar``, fastest of ``runs``: the
    twelve largest, and the totals of numpy, scipy, holoradar and the rest."""
    best: dict[str, float] = {}
    for _ in range(runs):
        err = subprocess.run([python, "-X", "importtime", "-c", "import holoradar"], env=env,
                             check=True, capture_output=True, text=True).stderr
        own: Counter[str] = Counter()
        for line in err.splitlines():
            m = re.match(r"import time:\s+(\d+) \|\s+\d+ \|\s*(\S+)", line)
            if not m:
                continue
            parts = m.group(2).split(".")
            # scipy by subpackage (they differ by 10x), everything else by top package.
            key = ".".join(parts[:2]) if parts[0] == "scipy" and len(parts) > 1 else parts[0]
            own[key] += int(m.group(1)) / 1e3
        total = sum(own.values())
        if not best or total < best["total"]:
            best = {k: round(v, 1) for k, v in own.most_common(12)}
            groups: Counter[str] = Counter()
            for k, v in own.items():
                top = k.split(".")[0]
                groups[top if top in ("numpy", "scipy", "holoradar") else "other"] += v
            best.update({f"all {k}": round(v, 1) for k, v in sorted(groups.items())})
            best["total"] = round(total, 1)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--src", type=Path, default=None,
                        help="a directory holding the holoradar package to time instead")
    parser.add_argument("--out", type=Path, default=HERE / "results_startup.json")
    args = parser.parse_args()
    python = sys.executable
    commands = cases(python)
    result: dict[str, object] = {"python": sys.version.split()[0], "cores": os.cpu_count(),
                                 "repeat": args.repeat,
                                 "src": str(args.src) if args.src else "installed"}
    with tempfile.TemporaryDirectory() as cache:
        for mode in ("cached", "source"):
            env = environment(mode, Path(cache), args.src)
            times = time_cases(commands, env, args.repeat)
            floor = times["import numpy"]["min_s"]
            for t in times.values():
                t["over_numpy_min_s"] = t["min_s"] - floor
            result[mode] = times
            print(f"{mode}: fastest / median of {args.repeat} fresh interpreters")
            for name, t in times.items():
                print(f"  {name:22s} {1e3 * t['min_s']:7.0f} ms / {1e3 * t['median_s']:7.0f} ms"
                      f"   ({1e3 * t['over_numpy_min_s']:+.0f} ms over numpy)")
        result["importtime_ms"] = breakdown(python, environment("cached", Path(cache),
                                                                args.src))
    print("own import time by package, ms (import holoradar, cached):")
    print("  " + ", ".join(f"{k} {v:.0f}" for k, v in result["importtime_ms"].items()))
    args.out.write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
