"""Write examples/data/wall_scan.csv: a measured-looking export of a 16 x 16 array.

What a lab program would write: one row per element, coordinates in
millimetres, the in-phase and quadrature voltages, the frequency in GHz in a
comment; receiver noise 30 dB below the signal. The scene: a concrete wall (eps 6+0.3j) 20 cm
in front of the array, two rebars 5 cm deep running along y, a horn beside
the array lighting the wall at an angle. The device has subtracted a reference
frame recorded over a bare stretch of the same wall (the surface glare and the
horn's direct wave) and calibrated its receivers to field units.

Run: python examples/make_measured_example.py  (rewrites the file only if asked:
--force).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import holoradar as hr

OUT = Path(__file__).parent / "data" / "wall_scan.csv"


def main() -> None:
    if OUT.exists() and "--force" not in sys.argv:
        print(f"{OUT} exists (pass --force to rewrite it)")
        return
    wall = hr.Medium.half_space(0.20, 6.0 + 0.3j)
    horn = hr.PointSource((0.0, -0.30, 0.0), pattern_exponent=4, axis=(0.0, 0.3, 0.25))
    # A rebar is a line of point scatterers 5 mm apart (a fifth of the resolution).
    ys = np.arange(-0.25, 0.2501, 0.005)
    bars = [hr.PointTarget((x0, y, 0.25), 0.005) for x0 in (-0.06, 0.07) for y in ys]
    holo = hr.simulate(hr.Scene(wall, horn, bars), hr.Aperture.paper(), 9.9e9,
                       include_surface=False, snr_db=30.0, seed=3)
    yy, xx = np.meshgrid(holo.y, holo.x, indexing="ij")
    volts = holo.data
    lines = ["# wall scan, 16 x 16 receivers, pitch 25 mm, f = 9.9 GHz",
             "x_mm,y_mm,I_V,Q_V"]
    lines += [f"{x * 1e3:.1f},{y * 1e3:.1f},{v.real:.6e},{v.imag:.6e}"
              for x, y, v in zip(xx.ravel(), yy.ravel(), volts.ravel(), strict=True)]
    OUT.parent.mkdir(exist_ok=True)
    OUT.write_text("\n".join(lines) + "\n")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
