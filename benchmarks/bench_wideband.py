"""Wideband migration of a scanned transceiver's hologram: speed against its FFTs and
against a plain numpy Stolt script, cold and warm, and peak memory.

Case of the field: 11 frequencies (8-12 GHz) x 144 x 187 positions at 3 mm onto 110
planes. Ratios are measured in one run (fastest of REPEAT interleaved runs after a
warm-up; "cold" is the first call with the transfer cache cleared). The numpy Stolt
script is what users write today: FFT2 of each frequency, then for every (kx, ky)
column an interpolation from the recorded k onto a uniform kz grid (a Python loop
over columns), then an inverse 3-D FFT.

Run: ``.venv/bin/python benchmarks/bench_wideband.py``; writes
``benchmarks/results_wideband.json`` and prints a Markdown table.
"""

from __future__ import annotations

import json
import time
import tracemalloc
from pathlib import Path

import numpy as np
import scipy.fft as sfft

import holoradar as hr
from holoradar.physics.propagation import clear_transfer_cache, padded_shape

REPEAT = 3
FREQS = np.linspace(8e9, 12e9, 11)
NY, NX = 144, 187
STEP = 0.003
ZS = np.linspace(0.02, 0.35, 110)


def numpy_stolt(data: np.ndarray, dx: float, freqs: np.ndarray, zs: np.ndarray) -> np.ndarray:
    """The users' script: monostatic Stolt with a loop over spectral columns."""
    _, ny, nx = data.shape
    k = 2 * np.pi * freqs / hr.C0
    D = np.fft.fft2(data, s=(2 * ny, 2 * nx))
    ky = 2 * np.pi * np.fft.fftfreq(2 * ny, dx)
    kx = 2 * np.pi * np.fft.fftfreq(2 * nx, dx)
    dz = zs[1] - zs[0]
    kz_grid = 2 * np.pi * np.fft.fftfreq(zs.size, dz)
    S = np.zeros((zs.size, 2 * ny, 2 * nx), complex)
    for iy in range(2 * ny):
        for ix in range(2 * nx):
            kz = np.sqrt(np.maximum(4 * k**2 - kx[ix] ** 2 - ky[iy] ** 2, 0))
            col = D[:, iy, ix] * np.exp(-1j * kz * zs[0])
            S[:, iy, ix] = (np.interp(kz_grid, kz, col.real, left=0, right=0)
                            + 1j * np.interp(kz_grid, kz, col.imag, left=0, right=0))
    return np.fft.ifftn(S)[:, :ny, :nx]


def main() -> dict:
    rng = np.random.default_rng(0)
    data = rng.standard_normal((FREQS.size, NY, NX)) + 1j * rng.standard_normal(
        (FREQS.size, NY, NX))
    x, y = np.arange(NX) * STEP, np.arange(NY) * STEP
    h = hr.Hologram(data, x, y, FREQS, monostatic=True)

    def run() -> object:
        return hr.migrate(h, ZS, equalize=False)

    clear_transfer_cache()
    t0 = time.perf_counter()
    img = run()
    cold = time.perf_counter() - t0
    tracemalloc.start()
    run()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    shape = (ZS.size, *img.data.shape[-2:])
    My, Mx = padded_shape((NY, NX), True, pitch=(STEP, STEP), wavelength=hr.C0 / FREQS[0] / 2,
                          z_max=float(ZS.max()))
    grid = np.zeros((FREQS.size, My, Mx), complex)
    planes = np.zeros((8, My, Mx), complex)

    def ffts() -> object:
        sfft.fft2(grid, axes=(-2, -1), workers=-1, overwrite_x=True)
        for _ in range(0, ZS.size, 8):
            sfft.ifft2(planes, axes=(-2, -1), workers=-1, overwrite_x=True)
        return None

    def stolt() -> object:
        return numpy_stolt(data, STEP, FREQS, ZS)

    warm = min(_time(run) for _ in range(REPEAT))
    fft = min(_time(ffts) for _ in range(REPEAT))
    loop = _time(stolt)
    out_bytes = np.prod(shape) * 16
    res = {"case": f"{FREQS.size} freq x {NY} x {NX} onto {ZS.size} planes",
           "cold_s": cold, "warm_s": warm, "ffts_s": fft, "numpy_stolt_s": loop,
           "cold_over_ffts": cold / fft, "warm_over_ffts": warm / fft,
           "speedup_vs_numpy_stolt": loop / warm, "peak_bytes": peak,
           "peak_over_output": peak / out_bytes, "grid": [My, Mx]}
    print("| case | time | ratio |\n|---|---|---|")
    print(f"| cold (first call) | {cold:.3f} s | {cold / fft:.2f}x its FFTs |")
    print(f"| warm | {warm:.3f} s | {warm / fft:.2f}x its FFTs |")
    print(f"| numpy Stolt loop | {loop:.3f} s | holoradar {loop / warm:.1f}x faster |")
    print(f"| peak memory | {peak / 2**20:.0f} MiB | {peak / out_bytes:.2f}x the output |")
    res["cube"] = cube()
    Path(__file__).with_name("results_wideband.json").write_text(json.dumps(res, indent=1))
    return res


def cube() -> dict:
    """64 frequencies x 64 x 64 positions onto 128 planes of 127 x 127 pixels
    (``upsample=2``): about 128^3 voxels. Time (cold, warm) and peak memory."""
    rng = np.random.default_rng(1)
    freqs = np.linspace(8e9, 12e9, 64)
    data = rng.standard_normal((64, 64, 64)) + 1j * rng.standard_normal((64, 64, 64))
    x = np.arange(64) * STEP
    h = hr.Hologram(data, x, x, freqs, monostatic=True)
    zs = np.linspace(0.02, 0.40, 128)

    def run() -> object:
        return hr.migrate(h, zs, equalize=False, upsample=2)

    clear_transfer_cache()
    t0 = time.perf_counter()
    img = run()
    cold = time.perf_counter() - t0
    warm = min(_time(run) for _ in range(REPEAT))
    tracemalloc.start()
    run()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    out_bytes = img.data.nbytes
    print(f"| 64 freq x 64 x 64 onto {img.data.shape} | cold {cold:.2f} s, warm {warm:.2f} s |"
          f" peak {peak / 2**20:.0f} MiB = {peak / out_bytes:.2f}x the output |")
    return {"shape": list(img.data.shape), "cold_s": cold, "warm_s": warm, "peak_bytes": peak,
            "peak_over_output": peak / out_bytes}


def _time(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
