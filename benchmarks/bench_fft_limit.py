"""How far ``migrate`` sits above its FFTs: ratios to the bare transforms, in one run.

Cases (complex64 data, so migrate works in complex64; FFTs by scipy.fft on all cores):

* ``plane``: one 512 x 512 plane at one frequency in free space, ``pad=False``; floor:
  an in-place ``fft2`` + ``ifft2`` pair of 512 x 512.
* ``plane_padded``: the same with the default padding; floor: the in-place pair at the
  padded size migrate uses.
* ``half_space``: the padded plane 0.2 m below the surface of a lossless half-space
  (eps 4) at 0.4 m; floor: the same padded pair.
* ``volume``: 64 planes 0.2-0.6 m, ``pad=False``; floor: one batched in-place inverse
  FFT of the (64, 512, 512) volume.
* ``wideband``: a scanned transceiver's 11 frequencies (8-12 GHz) x 144 x 187 at 3 mm
  onto 110 planes 0-0.18 m, free space; floor: 11 in-place 2-D FFTs of the recorded
  grid (unpadded) and one in-place 3-D inverse FFT of the (110, 144, 187) volume.

Warm: ``REPEAT`` rounds of a few pairs, each pair the floor then migrate timed back to
back (on a shared machine the two sides of a pair see the same load; the floor's own
time moves by 2x with it); the ratio is the median of the pairs' ratios, the times
the medians of each side. Cold: the first call in a fresh process (``import
holoradar`` and the data excluded), once as a user meets it (scipy.fft is imported by
that first call) and once with scipy.fft imported beforehand; ``REPEAT`` fresh
processes each, each next to a floor timed just before it; the ratio is the median
cold call over the median floor.

Run: ``.venv/bin/python benchmarks/bench_fft_limit.py``; writes
``benchmarks/results_fft_limit.json`` and prints a Markdown table.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPEAT = 3
CASES = ("plane", "plane_padded", "half_space", "volume", "wideband")


def setup(case: str) -> tuple:
    """(migrate call, floor call) of a case; the floor's arrays are made here."""
    import scipy.fft as sfft

    import holoradar as hr
    from holoradar.physics.propagation import padded_shape

    rng = np.random.default_rng(0)
    if case == "wideband":
        freqs = np.linspace(8e9, 12e9, 11)
        ny, nx, step = 144, 187, 0.003
        data = (rng.standard_normal((11, ny, nx))
                + 1j * rng.standard_normal((11, ny, nx))).astype(np.complex64)
        h = hr.Hologram(data, np.arange(nx) * step, np.arange(ny) * step, freqs,
                        monostatic=True)
        zs = np.linspace(0.0, 0.18, 110)
        grid = data.copy()
        vol = np.zeros((zs.size, ny, nx), np.complex64)

        def floor() -> None:
            sfft.fft2(grid, axes=(-2, -1), workers=-1, overwrite_x=True)
            sfft.ifftn(vol, workers=-1, overwrite_x=True)

        return (lambda: hr.migrate(h, zs, equalize=False)), floor
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
    pad = case != "plane"
    shape = padded_shape((n, n), pad, pitch=(dx, dx), wavelength=hr.C0 / f0, z_max=0.4)
    a = np.zeros(shape, np.complex64)

    def pair() -> None:
        sfft.fft2(a, workers=-1, overwrite_x=True)
        sfft.ifft2(a, workers=-1, overwrite_x=True)

    return (lambda: hr.migrate(h, 0.4, medium=medium, pad=pad)), pair


def _time(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def cold_child(case: str, preimport: bool) -> None:
    """In a fresh process: the first migrate call, seconds, on stdout."""
    if preimport:
        import scipy.fft  # noqa: F401
    call, _ = setup(case) if preimport else _setup_without_scipy(case)
    t0 = time.perf_counter()
    call()
    print(json.dumps(time.perf_counter() - t0))


def _setup_without_scipy(case: str) -> tuple:
    """The case's call with no scipy.fft imported before it (as a user's first call)."""
    import holoradar as hr

    rng = np.random.default_rng(0)
    if case == "wideband":
        data = (rng.standard_normal((11, 144, 187))
                + 1j * rng.standard_normal((11, 144, 187))).astype(np.complex64)
        h = hr.Hologram(data, np.arange(187) * 0.003, np.arange(144) * 0.003,
                        np.linspace(8e9, 12e9, 11), monostatic=True)
        zs = np.linspace(0.0, 0.18, 110)
        return (lambda: hr.migrate(h, zs, equalize=False)), None
    f0 = 9.9e9
    field = (rng.standard_normal((512, 512))
             + 1j * rng.standard_normal((512, 512))).astype(np.complex64)
    x = (np.arange(512) - 256) * hr.C0 / f0 / 2
    h = hr.Hologram(field, x, x, f0)
    if case == "volume":
        zs = np.linspace(0.2, 0.6, 64)
        return (lambda: hr.migrate(h, zs, pad=False)), None
    medium = hr.Medium.half_space(0.2, 4.0) if case == "half_space" else None
    return (lambda: hr.migrate(h, 0.4, medium=medium, pad=case != "plane")), None


def _cold(case: str, preimport: bool) -> float:
    cmd = [sys.executable, __file__, "--cold", case] + (["--preimport"] if preimport else [])
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return float(json.loads(out.strip().splitlines()[-1]))


def main() -> dict:
    res: dict[str, dict] = {}
    for case in CASES:
        call, floor = setup(case)
        call(), floor()   # warm-up: transfer functions cached, FFT plans made
        t = time.perf_counter()
        call()
        inner = max(3, min(20, int(0.2 / max(time.perf_counter() - t, 1e-4))))
        fl, mig, ratios, cold, cold_pre = [], [], [], [], []
        for _ in range(REPEAT):
            for _ in range(inner):
                fl.append(_time(floor))
                mig.append(_time(call))
                ratios.append(mig[-1] / fl[-1])
            fl.append(_time(floor))
            cold.append(_cold(case, False))
            fl.append(_time(floor))
            cold_pre.append(_cold(case, True))
        f, m = float(np.median(fl)), float(np.median(mig))
        c, cp = float(np.median(cold)), float(np.median(cold_pre))
        res[case] = {"floor_ms": 1e3 * f, "warm_ms": 1e3 * m,
                     "warm_ratio": float(np.median(ratios)),
                     "cold_ms": 1e3 * c, "cold_ratio": c / f,
                     "cold_scipy_imported_ms": 1e3 * cp, "cold_scipy_imported_ratio": cp / f,
                     "pairs": len(ratios)}
        print(case, {k: round(v, 3) for k, v in res[case].items()}, flush=True)
    return res


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--cold":
        cold_child(sys.argv[2], "--preimport" in sys.argv)
        sys.exit(0)
    results = main()
    out = Path(__file__).with_name("results_fft_limit.json")
    out.write_text(json.dumps(results, indent=2) + "\n")
    print("\n| case | floor ms | warm ms | warm / floor | cold ms | cold / floor "
          "| cold, scipy.fft imported / floor |\n|---|---|---|---|---|---|---|")
    for case, r in results.items():
        print(f"| {case} | {r['floor_ms']:.1f} | {r['warm_ms']:.1f} | {r['warm_ratio']:.2f} "
              f"| {r['cold_ms']:.0f} | {r['cold_ratio']:.1f} "
              f"| {r['cold_scipy_imported_ratio']:.1f} |")
