"""The migration operator against the code before it, and its forward map's cost.

Part 1, before and after in one run: each case's warm ``migrate`` call over its FFT
floor (the bare transforms the work needs, timed back to back with it, as in
``bench_fft_limit.py``), measured in fresh child processes that alternate between
this tree's ``src`` and the tree of the commit before the operator (``BEFORE``,
exported with ``git archive``): the same machine, the same minutes. Cases:

* ``plane``: one 512 x 512 plane at one frequency in free space, ``pad=False``;
  floor: an in-place ``fft2`` + ``ifft2`` pair of 512 x 512.
* ``plane_padded``: the same with the default padding; floor: the pair at that size.
* ``half_space``: the padded plane 0.2 m below the surface of a half-space (eps 4).
* ``volume``: 64 planes 0.2-0.6 m, ``pad=False``; floor: one batched inverse FFT.
* ``wideband``: a transceiver's 11 frequencies x 144 x 187 at 3 mm onto 110 planes
  0-0.18 m, default padding; floor: 11 ``fft2`` and one ``ifftn`` of the volume.
* ``tilted``: a 64 x 64 array at 1 cm tilted 30 degrees (azimuth 30) onto one
  horizontal plane 0.2 m below the sand's surface (``frame="ground"``: finufft's
  route); floor: the in-place FFT pair of the world grid it uses.

Part 2, this tree only: ``matvec`` + ``rmatvec`` of ``hr.migration_operator`` on the
512 x 512 plane (``pad=False``, complex64) over one in-place ``fft2`` + ``ifft2`` pair
(each of the two maps needs one such pair: 2.0 is the floor of the two together).

Run: ``.venv/bin/python benchmarks/bench_operator.py [case ...] [--rounds N]``; merges
the cases run into ``benchmarks/results_operator.json`` and prints a Markdown table.
``--before REV`` compares with another commit instead (a restructuring's before and
after in one run; written to ``results_operator_vs_REV.json``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from io import BytesIO
from pathlib import Path

import numpy as np

BEFORE = "fe01475"   # the last commit before the migration operator
CASES = ("plane", "plane_padded", "half_space", "volume", "wideband", "tilted")
ROOT = Path(__file__).resolve().parents[1]


def _time(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def setup(case: str) -> tuple:
    """(call, floor) of a case, in whichever holoradar is on the path."""
    import scipy.fft as sfft

    import holoradar as hr
    from holoradar.physics.propagation import padded_shape

    rng = np.random.default_rng(0)
    if case == "wideband":
        nf, ny, nx, nz = 11, 144, 187, 110
        data = (rng.standard_normal((nf, ny, nx))
                + 1j * rng.standard_normal((nf, ny, nx))).astype(np.complex64)
        h = hr.Hologram(data, np.arange(nx) * 0.003, np.arange(ny) * 0.003,
                        np.linspace(8e9, 12e9, nf), monostatic=True)
        zs = np.linspace(0.0, 0.18, nz)
        grid, vol = data.copy(), np.zeros((nz, ny, nx), np.complex64)

        def floor() -> None:
            sfft.fft2(grid, axes=(-2, -1), workers=-1, overwrite_x=True)
            sfft.ifftn(vol, workers=-1, overwrite_x=True)

        return (lambda: hr.migrate(h, zs, equalize=False)), floor
    if case == "tilted":
        n = 64
        data = (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))).astype(
            np.complex64)
        x = (np.arange(n) - (n - 1) / 2) * 0.01
        pose = hr.Pose((0.0, 0.0, 0.0), tilt=np.radians(30), azimuth=np.radians(30))
        h = hr.Hologram(data, x, x, 9.9e9, pose=pose)
        sand = hr.Medium.half_space(0.35, 2.5)

        def call() -> None:
            hr.migrate(h, 0.55, medium=sand, frame="ground")

        call()
        a = np.zeros(_ground_grid(h, sand), np.complex64)
        return call, lambda: (sfft.fft2(a, workers=-1, overwrite_x=True),
                              sfft.ifft2(a, workers=-1, overwrite_x=True))
    n, f0 = 512, 9.9e9
    dx = hr.C0 / f0 / 2
    field = (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))).astype(np.complex64)
    x = (np.arange(n) - n / 2) * dx
    h = hr.Hologram(field, x, x, f0)
    if case == "volume":
        zs = np.linspace(0.2, 0.6, 64)
        stack = np.zeros((zs.size, n, n), np.complex64)
        return (lambda: hr.migrate(h, zs, pad=False),
                lambda: sfft.ifft2(stack, axes=(-2, -1), workers=-1, overwrite_x=True))
    medium = hr.Medium.half_space(0.2, 4.0) if case == "half_space" else None
    pad = case not in ("plane", "operator")
    shape = padded_shape((n, n), pad, pitch=(dx, dx), wavelength=hr.C0 / f0, z_max=0.4)
    a = np.zeros(shape, np.complex64)

    def pair() -> None:
        sfft.fft2(a, workers=-1, overwrite_x=True)
        sfft.ifft2(a, workers=-1, overwrite_x=True)

    if case == "operator":   # the physical model: a plane wave's field on the plane
        lit = hr.Hologram(field, x, x, f0, source=hr.PlaneWave())
        A = hr.migration_operator(lit, 0.4, pad=False, dtype=np.complex64)
        v = field.ravel()
        r = (A.H @ v).astype(np.complex64)

        def both() -> None:
            A.matvec(r)
            A.rmatvec(v)

        return both, pair
    return (lambda: hr.migrate(h, 0.4, medium=medium, pad=pad)), pair


def _ground_grid(h, sand) -> tuple[int, int]:
    """The world FFT grid the ground frame uses for this case (either tree)."""
    try:
        try:
            from holoradar.imaging.migration.backends.oblique import ground_setup
        except ImportError:                 # a tree before the backends' folder
            from holoradar.imaging.oblique import ground_setup
    except ImportError:                     # the tree before the operator
        import holoradar.imaging.oblique as ob

        seen = {}
        real = ob._spectrum_on_plane

        def spy(hologram, grid, *a, **k):
            seen["grid"] = grid
            return real(hologram, grid, *a, **k)

        ob._spectrum_on_plane = spy
        try:
            ob.migrate_ground(h, np.array([0.55]), sand)
        finally:
            ob._spectrum_on_plane = real
        return seen["grid"]
    return ground_setup(h, h.k, np.array([0.55]), sand).grid


def child(case: str, pairs: int) -> None:
    """Warm ratio of a case in this process: prints JSON."""
    call, floor = setup(case)
    call(), floor(), call()
    fl, mig = [], []
    for _ in range(pairs):
        fl.append(_time(floor))
        mig.append(_time(call))
    fl_a, mig_a = np.array(fl), np.array(mig)
    print(json.dumps({"floor_ms": 1e3 * float(np.median(fl_a)),
                      "warm_ms": 1e3 * float(np.median(mig_a)),
                      "ratio": float(np.median(mig_a / fl_a))}))


def _run(case: str, src: Path, pairs: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(src)}
    out = subprocess.run([sys.executable, __file__, "--child", case, str(pairs)], env=env,
                         check=True, capture_output=True, text=True, cwd=src.parent).stdout
    return json.loads(out.strip().splitlines()[-1])


def _export_before(where: Path, rev: str = BEFORE) -> Path:
    blob = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "src"], check=True,
                          capture_output=True).stdout
    with tarfile.open(fileobj=BytesIO(blob)) as tar:
        tar.extractall(where, filter="data")
    return where / "src"


def main(rounds: int, cases: tuple[str, ...] = CASES, before: str = BEFORE) -> dict:
    res: dict = {"before": before, "load": os.getloadavg()[0]}
    with tempfile.TemporaryDirectory() as tmp:
        old = _export_before(Path(tmp), before)
        new = ROOT / "src"
        for case in cases:
            pairs = 3 if case in ("wideband", "volume") else 15
            runs: dict[str, list] = {"before": [], "after": []}
            for _ in range(rounds):
                runs["before"].append(_run(case, old, pairs))
                runs["after"].append(_run(case, new, pairs))
            row = {}
            for side, rs in runs.items():
                row[f"{side}_ratio"] = float(np.median([r["ratio"] for r in rs]))
                row[f"{side}_ms"] = float(np.median([r["warm_ms"] for r in rs]))
                row["floor_ms"] = float(np.median([r["floor_ms"] for r in rs]))
            row["after_over_before"] = row["after_ratio"] / row["before_ratio"]
            res[case] = row
            print(case, {k: float(f"{v:.3g}") for k, v in row.items()}, flush=True)
        ops = [_run("operator", new, 15) for _ in range(rounds)]
        res["operator_plane"] = {"ratio": float(np.median([r["ratio"] for r in ops])),
                                 "warm_ms": float(np.median([r["warm_ms"] for r in ops])),
                                 "floor_ms": float(np.median([r["floor_ms"] for r in ops]))}
        print("operator_plane", res["operator_plane"], flush=True)
    return res


if __name__ == "__main__":
    if len(sys.argv) > 3 and sys.argv[1] == "--child":
        child(sys.argv[2], int(sys.argv[3]))
        sys.exit(0)
    n = int(sys.argv[sys.argv.index("--rounds") + 1]) if "--rounds" in sys.argv else 3
    rev = sys.argv[sys.argv.index("--before") + 1] if "--before" in sys.argv else BEFORE
    chosen = tuple(a for a in sys.argv[1:] if a in CASES) or CASES
    results = main(n, chosen, rev)
    out = Path(__file__).with_name("results_operator.json" if rev == BEFORE else
                                   f"results_operator_vs_{rev}.json")
    merged = json.loads(out.read_text()) if out.exists() else {}
    merged.update(results)   # the cases run replace theirs
    tmp = out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(merged, indent=2) + "\n")
    tmp.replace(out)
    print("\n| case | floor ms | before / floor | after / floor | after / before |\n"
          "|---|---|---|---|---|")
    for case in chosen:
        r = results[case]
        print(f"| {case} | {r['floor_ms']:.1f} | {r['before_ratio']:.2f} "
              f"| {r['after_ratio']:.2f} | {r['after_over_before']:.2f} |")
    r = results["operator_plane"]
    print(f"\nmatvec + rmatvec of one 512 x 512 plane: {r['warm_ms']:.1f} ms, "
          f"{r['ratio']:.2f}x one in-place FFT pair ({r['floor_ms']:.1f} ms; the two maps "
          "need two)")
