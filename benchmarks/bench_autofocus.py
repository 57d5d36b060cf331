"""Autofocus on the paper's 16 x 16 array at one frequency, and on a 2 GHz band.

Cold: the first call in a fresh process pays the quadrature rules and the first
migration; warm: the same call again (new trial permittivities still cost new
Sommerfeld integrals: nothing of the fit is cached between calls). Reports the
trial permittivities, the point responses evaluated (the field of one trial object
at every element and frequency), the Sommerfeld integrals (one per frequency, trial
eps' and range, each serving many responses), and the time per response against a
bare FFT of the hologram padded to twice its size (the unit of a migration).

Run: .venv/bin/python benchmarks/bench_autofocus.py
"""

from __future__ import annotations

import platform
import time

import numpy as np
import scipy.fft as sfft

import holoradar as hr

REPEAT = 3


def hologram(freq, eps: float = 4.0, snr_db: float = 40.0) -> hr.Hologram:
    truth = hr.Medium.half_space(0.30, eps * (1 + 0.005j))
    depth = 5 * hr.C0 / 9.9e9 / np.sqrt(eps)
    scene = hr.Scene(truth, hr.PlaneWave(), [hr.PointTarget((0.01, -0.02, 0.30 + depth))])
    return hr.simulate(scene, hr.Aperture.paper(), freq, include_surface=False,
                       snr_db=snr_db, seed=0)


def run(h: hr.Hologram) -> tuple[float, hr.AutofocusResult]:
    t = time.perf_counter()
    res = hr.autofocus(h, medium_model=hr.Medium.half_space(0.30, 3.0 + 0.015j))
    return time.perf_counter() - t, res


def main() -> None:
    print(f"autofocus, 16 x 16 ({platform.machine()}, CPython {platform.python_version()})")
    u = np.random.default_rng(0).standard_normal((32, 32)) + 0j
    t = time.perf_counter()
    for _ in range(1000):
        sfft.fft2(u)
    fft = (time.perf_counter() - t) / 1000
    print(f"  bare 32 x 32 FFT: {fft * 1e6:.1f} us")
    for name, freq in (("one frequency", 9.9e9), ("2 GHz band, 5 frequencies",
                                                   np.linspace(9e9, 11e9, 5))):
        h = hologram(freq)
        cold, res = run(h)
        warm = min(run(h)[0] for _ in range(REPEAT))
        per = warm / res.evaluations
        print(f"  {name}: eps' = {res.eps:.3f} ({res.eps_interval[0]:.3f} .. "
              f"{res.eps_interval[1]:.3f}), truth 4.000")
        print(f"    cold {cold:6.3f} s, warm {warm:6.3f} s; {res.eps_grid.size} trial eps', "
              f"{res.evaluations} responses ({per * 1e3:.3f} ms each = {per / fft:.0f} FFTs), "
              f"{res.integrals} Sommerfeld integrals")


if __name__ == "__main__":
    main()
