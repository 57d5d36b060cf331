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
  onto 110 planes 0-0.18 m, free space, default padding; floor: 11 in-place 2-D FFTs of
  the recorded grid (unpadded) and one in-place 3-D inverse FFT of the (110, 144, 187)
  volume. Also timed in the same pairs: the same call with ``algorithm="stolt"``, and a
  Stolt migration as device makers write it (``makers_stolt``: a Python loop of
  ``np.interp`` over the (kx, ky) columns onto a uniform kz grid, then one ``ifftn``).
* ``wideband_unpadded``: the same with ``pad=False`` (the floor's own grid).
* ``wideband_large`` (warm and memory only, ``--large``): 64 frequencies x 256 x 256 at
  3 mm onto 256 planes 0-0.4 m, ``pad=False``; floor: 64 in-place ``fft2`` + one in-place
  ``ifftn`` of (256, 256, 256); peak memory of the call by ``tracemalloc`` in a fresh
  process, against the output volume.

Accuracy: each wideband case's image against the NumPy phase-shift sum
(``algorithm="kspace"``), relative L2, ``"auto"`` and ``"stolt"``.

Warm: ``REPEAT`` rounds of a few pairs, each pair the floor then migrate timed back to
back (on a shared machine the two sides of a pair see the same load; the floor's own
time moves by 2x with it); the ratio is the median of the pairs' ratios, the times
the medians of each side. Cold: the first call in a fresh process (``import
holoradar`` and the data excluded), once as a user meets it (scipy.fft is imported by
that first call) and once with scipy.fft imported beforehand; ``REPEAT`` fresh
processes each, each next to a floor timed just before it; the ratio is the median
cold call over the median floor.

Run: ``.venv/bin/python benchmarks/bench_fft_limit.py [case ...] [--large]``; writes
``benchmarks/results_fft_limit.json`` (the cases run, merged into what it holds) and
prints a Markdown table.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPEAT = 3
CASES = ("plane", "plane_padded", "half_space", "volume", "wideband", "wideband_unpadded")
WIDEBAND = {"wideband": True, "wideband_unpadded": False}   # case: pad


def _wideband(nf: int, ny: int, nx: int, nz: int, z_max: float):
    """A transceiver's random wideband hologram (8-12 GHz, 3 mm) and its planes."""
    import holoradar as hr

    rng = np.random.default_rng(0)
    data = (rng.standard_normal((nf, ny, nx))
            + 1j * rng.standard_normal((nf, ny, nx))).astype(np.complex64)
    h = hr.Hologram(data, np.arange(nx) * 0.003, np.arange(ny) * 0.003,
                    np.linspace(8e9, 12e9, nf), monostatic=True)
    return h, np.linspace(0.0, z_max, nz)


def makers_stolt(h, zs: np.ndarray) -> np.ndarray:
    """Stolt as a device maker's script does it: per frequency ``fft2``; for each (kx, ky)
    column, the spectrum at the round-trip ``kz = sqrt(4k^2 - kx^2 - ky^2)`` of each
    frequency interpolated (``np.interp``, real and imaginary parts) onto the uniform kz
    grid of the planes; one ``ifftn``. (No padding, no band limit; its own accuracy is
    not the phase-shift sum's.)"""
    ny, nx = h.data.shape[-2:]
    S = np.fft.fft2(h.data)
    kx = 2 * np.pi * np.fft.fftfreq(nx, h.pitch[0])
    ky = 2 * np.pi * np.fft.fftfreq(ny, h.pitch[1])
    k2 = 4 * h.wavenumbers ** 2
    dz = zs[1] - zs[0]
    kzg = 2 * np.pi * np.fft.fftfreq(zs.size, dz)
    out = np.zeros((zs.size, ny, nx), dtype=np.complex64)
    for iy in range(ny):
        for ix in range(nx):
            k2t = kx[ix] ** 2 + ky[iy] ** 2
            ok = k2 > k2t
            if ok.sum() < 2:
                continue
            kz = np.sqrt(k2[ok] - k2t)
            col = S[ok, iy, ix] * np.exp(-1j * kz * zs[0])
            out[:, iy, ix] = (np.interp(kzg, kz, col.real, left=0, right=0)
                              + 1j * np.interp(kzg, kz, col.imag, left=0, right=0))
    return np.fft.ifftn(out).astype(np.complex64, copy=False)


def setup(case: str) -> tuple:
    """(migrate call, floor call) of a case; the floor's arrays are made here."""
    import scipy.fft as sfft

    import holoradar as hr
    from holoradar.physics.propagation import padded_shape

    rng = np.random.default_rng(0)
    if case in WIDEBAND or case == "wideband_large":
        h, zs = (_wideband(64, 256, 256, 256, 0.4) if case == "wideband_large"
                 else _wideband(11, 144, 187, 110, 0.18))
        grid = h.data.copy()
        vol = np.zeros((zs.size, *grid.shape[-2:]), np.complex64)

        def floor() -> None:
            sfft.fft2(grid, axes=(-2, -1), workers=-1, overwrite_x=True)
            sfft.ifftn(vol, workers=-1, overwrite_x=True)

        pad = WIDEBAND.get(case, False)
        return (lambda: hr.migrate(h, zs, equalize=False, pad=pad)), floor
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
    if case in WIDEBAND:
        h, zs = _wideband(11, 144, 187, 110, 0.18)
        return (lambda: hr.migrate(h, zs, equalize=False, pad=WIDEBAND[case])), None
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


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def wideband_extras(case: str) -> dict:
    """Accuracy of "auto" and "stolt" against the phase-shift sum; warm "stolt" and the
    makers' Stolt, each timed in pairs with migrate ("auto")."""
    import holoradar as hr

    pad = WIDEBAND.get(case, False)
    h, zs = (_wideband(64, 256, 256, 256, 0.4) if case == "wideband_large"
             else _wideband(11, 144, 187, 110, 0.18))
    ref = hr.migrate(h, zs, equalize=False, pad=pad, algorithm="kspace").data
    auto = hr.migrate(h, zs, equalize=False, pad=pad).data
    st = hr.migrate(h, zs, equalize=False, pad=pad, algorithm="stolt").data
    out = {"auto_vs_kspace": _rel(auto, ref), "stolt_vs_kspace": _rel(st, ref)}
    del ref, auto, st
    if case == "wideband_large":
        return out
    pairs: dict[str, list] = {"stolt": [], "makers": []}
    for _ in range(REPEAT):
        for name, fn in (("stolt", lambda: hr.migrate(h, zs, equalize=False, pad=pad,
                                                      algorithm="stolt")),
                         ("makers", lambda: makers_stolt(h, zs))):
            a = _time(lambda: hr.migrate(h, zs, equalize=False, pad=pad))
            pairs[name].append((a, _time(fn)))
    for name, p in pairs.items():
        arr = np.array(p)
        out[f"{name}_ms"] = 1e3 * float(np.median(arr[:, 1]))
        out[f"{name}_over_auto"] = float(np.median(arr[:, 1] / arr[:, 0]))
    return out


def large() -> dict:
    """64 x 256 x 256 onto 256 planes: warm ratio to its floor, peak memory (fresh
    process, tracemalloc) against the output volume, accuracy."""
    call, floor = setup("wideband_large")
    call(), floor()
    fl, mig = [], []
    for _ in range(REPEAT):
        fl.append(_time(floor))
        mig.append(_time(call))
    cmd = [sys.executable, __file__, "--memory", "wideband_large"]
    mem = json.loads(subprocess.run(cmd, check=True, capture_output=True,
                                    text=True).stdout.strip().splitlines()[-1])
    res = {"floor_ms": 1e3 * float(np.median(fl)), "warm_ms": 1e3 * float(np.median(mig)),
           "warm_ratio": float(np.median(np.array(mig) / np.array(fl))), **mem,
           **wideband_extras("wideband_large")}
    print("wideband_large", {k: float(f"{v:.3g}") for k, v in res.items()}, flush=True)
    return res


def memory_child(case: str) -> None:
    """In a fresh process: cold and warm call; the warm call's peak memory (tracemalloc)."""
    import tracemalloc

    call, _ = setup(case)
    t0 = time.perf_counter()
    img = call()
    cold = time.perf_counter() - t0
    out_bytes = img.data.nbytes
    del img
    tracemalloc.start()
    call()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    print(json.dumps({"cold_ms": 1e3 * cold, "output_MiB": out_bytes / 2**20,
                      "peak_MiB": peak / 2**20, "peak_over_output": peak / out_bytes}))


def main(cases: tuple[str, ...] = CASES) -> dict:
    res: dict[str, dict] = {}
    for case in cases:
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
        if case in WIDEBAND:
            res[case].update(wideband_extras(case))
        print(case, {k: float(f"{v:.3g}") for k, v in res[case].items()}, flush=True)
    return res


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--cold":
        cold_child(sys.argv[2], "--preimport" in sys.argv)
        sys.exit(0)
    if len(sys.argv) > 2 and sys.argv[1] == "--memory":
        memory_child(sys.argv[2])
        sys.exit(0)
    chosen = tuple(a for a in sys.argv[1:] if not a.startswith("--")) or CASES
    results = main(chosen)
    if "--large" in sys.argv:
        results["wideband_large"] = large()
    out = Path(__file__).with_name("results_fft_limit.json")
    merged = json.loads(out.read_text()) if out.exists() else {}
    merged.update(results)
    tmp = out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(merged, indent=2) + "\n")
    tmp.replace(out)
    print("\n| case | floor ms | warm ms | warm / floor | cold ms | cold / floor "
          "| cold, scipy.fft imported / floor |\n|---|---|---|---|---|---|---|")
    for case, r in results.items():
        if "cold_ratio" not in r:
            continue
        print(f"| {case} | {r['floor_ms']:.1f} | {r['warm_ms']:.1f} | {r['warm_ratio']:.2f} "
              f"| {r['cold_ms']:.0f} | {r['cold_ratio']:.1f} "
              f"| {r['cold_scipy_imported_ratio']:.1f} |")
