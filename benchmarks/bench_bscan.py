"""A B-scan's image against its FFT floor and against delay-and-sum, in one run.

Case: a ground-coupled transceiver's line scan, 200 positions 2.13 cm apart, 128
frequencies 0.98-2.0 GHz, concrete of eps 6 under the antennas (surface at range 0),
imaged with the defaults onto 60 depths 0.5-30 cm (``migrate(h, z, medium=ground)``).

* floor: the bare FFTs the work needs, timed back to back with it: the 128 traces'
  FFTs along x on the padded grid, and one inverse FFT per plane (the phase-shift
  sum carries the band from plane to plane in the wavenumber domain);
* delay-and-sum in NumPy, two ways: in the frequency domain (every pixel's round-trip
  phase to every antenna at every frequency, summed) and in the time domain (each
  trace to a range profile by one zero-padded inverse FFT, then every pixel's
  straight-ray delay to every antenna read off it by linear interpolation and
  summed: the usual back-projection of GPR software);
* the first call in a fresh process (the plan built, numba's loop loaded).

Wall medians of ``REPEAT`` rounds after a warm-up. Run:
``.venv/bin/python benchmarks/bench_bscan.py`` (writes results_bscan.json).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
from timing import median

HERE = Path(__file__).parent
REPEAT = 5
C0 = 299_792_458.0


def case() -> tuple:
    import holoradar as hr

    f = np.linspace(0.98e9, 2.0e9, 128)
    x = np.arange(200) * 0.0213
    rng = np.random.default_rng(0)
    h = hr.Hologram(rng.standard_normal((128, 200)) + 1j * rng.standard_normal((128, 200)),
                    x, frequency=f, monostatic=True)
    return h, hr.Medium.half_space(0.0, 6.0), np.arange(0.005, 0.3 + 1e-9, 0.005)


def _median(fn, repeat: int = REPEAT) -> float:
    return median(fn, repeat)


def das_frequency(d: np.ndarray, x: np.ndarray, f: np.ndarray, zs: np.ndarray,
                  n: float) -> np.ndarray:
    k = 2 * np.pi * f / C0
    out = np.empty((zs.size, x.size), complex)
    for iz, z in enumerate(zs):
        R = np.hypot(x[None, :] - x[:, None], z)
        out[iz] = np.einsum("fpa,fa->p", np.exp(-2j * n * k[:, None, None] * R[None]), d)
    return out


def das_time(d: np.ndarray, x: np.ndarray, f: np.ndarray, zs: np.ndarray, n: float,
             pad: int = 8) -> np.ndarray:
    """Range profiles by one zero-padded FFT over the band, ``P(tau) = sum_j d_j
    exp(-2 pi i j df tau)`` sampled every ``dt = 1 / (m df)``, then each pixel's delay
    to each antenna interpolated and summed, times ``exp(-2 pi i f0 tau)``: the
    frequency-domain sum ``sum_f d_f exp(-2 pi i f tau)`` to the interpolation's
    error."""
    nf = f.size
    df = float(f[1] - f[0])
    m = pad * nf
    prof = np.fft.fft(d, n=m, axis=0)                        # (m, nant): delay k / (m df)
    dt = 1.0 / (m * df)
    out = np.empty((zs.size, x.size), complex)
    for iz, z in enumerate(zs):
        tau = 2 * n * np.hypot(x[None, :] - x[:, None], z) / C0  # (pixel, antenna)
        pos = tau / dt
        i0 = np.floor(pos).astype(int) % m
        w = pos - np.floor(pos)
        a = np.arange(x.size)[None, :]
        # The band starts at f[0]: a delay tau carries exp(-2 pi i f0 tau) on top.
        v = (1 - w) * prof[i0, a] + w * prof[(i0 + 1) % m, a]
        out[iz] = np.sum(v * np.exp(-2j * np.pi * f[0] * tau), axis=1)
    return out


def floor_fn(h, zs) -> object:
    import scipy.fft as sfft

    from holoradar.imaging.migration.backends.terms import band_grid

    grid = band_grid((1, h.x.size), h.pitch, h.wavenumbers, True, True, float(zs.max()))
    a = np.zeros((h.nf, grid[1]), complex)
    b = np.zeros((zs.size, grid[1]), complex)

    def floor() -> None:
        sfft.fft(a, axis=-1, workers=-1)
        sfft.ifft(b, axis=-1, workers=-1)

    return floor


def cold() -> float:
    """The first call in a fresh process (the case's setup not counted)."""
    code = ("import time, warnings; warnings.filterwarnings('ignore');"
            f"import sys; sys.path.insert(0, {str(HERE)!r}); import bench_bscan as b;"
            "import holoradar as hr; h, g, zs = b.case(); t = time.perf_counter();"
            "hr.migrate(h, zs, medium=g); print(time.perf_counter() - t)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    return float(out.stdout.strip().splitlines()[-1])


def main() -> dict:
    import holoradar as hr

    warnings.filterwarnings("ignore")
    h, g, zs = case()
    d = h.data[:, 0, :]
    n = float(np.sqrt(6.0))
    res = {"cpus": os.cpu_count(), "loadavg_before": os.getloadavg(),
           "shape": [h.nf, h.x.size], "planes": int(zs.size)}
    res["migrate_s"] = _median(lambda: hr.migrate(h, zs, medium=g))
    res["floor_s"] = _median(floor_fn(h, zs))
    res["das_time_s"] = _median(lambda: das_time(d, h.x, h.frequencies, zs, n), 3)
    res["das_frequency_s"] = _median(lambda: das_frequency(d, h.x, h.frequencies, zs, n), 1)
    res["cold_first_call_s"] = cold()
    res["migrate_over_floor"] = res["migrate_s"] / res["floor_s"]
    res["das_time_over_migrate"] = res["das_time_s"] / res["migrate_s"]
    res["das_frequency_over_migrate"] = res["das_frequency_s"] / res["migrate_s"]
    res["loadavg_after"] = os.getloadavg()
    return res


if __name__ == "__main__":
    out = main()
    print(json.dumps(out, indent=1))
    (HERE / "results_bscan.json").write_text(json.dumps(out, indent=1) + "\n")
