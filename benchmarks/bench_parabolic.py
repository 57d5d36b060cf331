"""Parabolic-equation propagation: a 256 x 256 field through 200 depth steps, against the
bare FFTs the work needs (one forward, one inverse 2-D FFT of the field).

Cold: building the propagator (the product of the 200 split steps, one complex array)
and one propagation; warm: a propagation with the propagator built. Paraxial and
wide-angle forms. Fastest of REPEAT runs.

Run: .venv/bin/python benchmarks/bench_parabolic.py
"""

from __future__ import annotations

import platform

import numpy as np
import scipy.fft as sfft
from timing import best as fastest

import holoradar as hr
from holoradar.physics.parabolic import ParabolicEquation

REPEAT = 7
N, STEPS = 256, 200


def best(fn) -> float:
    return fastest(fn, REPEAT, warm=False)


def main() -> None:
    k = 2 * np.pi * 9.9e9 / hr.C0
    wet = hr.Medium.graded(0.30, lambda d: 3.0 + 20.0 * d, 0.30, step=0.30 / STEPS)
    rng = np.random.default_rng(0)
    u = rng.standard_normal((N, N)) + 1j * rng.standard_normal((N, N))
    ffts = best(lambda: sfft.ifft2(sfft.fft2(u)))
    print(f"{N} x {N} field, {STEPS} steps ({platform.machine()}, "
          f"CPython {platform.python_version()})")
    print(f"  bare fft2 + ifft2           {ffts * 1e3:7.2f} ms")
    for wide in (False, True):
        def cold(wide: bool = wide) -> None:
            ParabolicEquation((N, N), (0.005, 0.005), k, wet, 0.30, 0.60,
                              wide_angle=wide).forward(u)

        pe = ParabolicEquation((N, N), (0.005, 0.005), k, wet, 0.30, 0.60, wide_angle=wide)
        warm = best(lambda pe=pe: pe.forward(u))
        c = best(cold)
        name = "wide-angle" if wide else "paraxial"
        print(f"  {name:10s} warm {warm * 1e3:7.2f} ms = {warm / ffts:4.2f}x the FFTs; "
              f"cold {c * 1e3:7.2f} ms = {c / ffts:5.2f}x")


if __name__ == "__main__":
    main()
