"""Moisture rising with depth: eps' 3 at the surface to 9 at 30 cm; a point 20 cm deep.

The hologram (16 x 16 elements at 1.25 cm, 8.9-10.9 GHz in 11 steps, a normal plane
wave, the surface 30 cm from the array) is simulated through the graded ground
(`Medium.graded`, 2 mm layers, exact). It is imaged three ways: through the graded
model, and through two uniform half-spaces a user with one permittivity might take
(the surface's value, and the travel-time match). Their depth errors are what the
graded model saves.

Run: python examples/graded_ground.py  (prints the figures; no files)
"""

from __future__ import annotations

import warnings

import numpy as np

import holoradar as hr

Z0, DEPTH = 0.30, 0.20


def main() -> None:
    warnings.simplefilter("ignore", hr.AliasingWarning)
    wet = hr.Medium.graded(Z0, lambda d: 3.0 + 20.0 * np.minimum(d, 0.30), 0.30, step=0.002)
    f = np.linspace(8.9e9, 10.9e9, 11)
    scene = hr.Scene(wet, hr.PlaneWave(), [hr.PointTarget((0.0, 0.0, Z0 + DEPTH))])
    holo = hr.simulate(scene, hr.Aperture.grid(16, 0.0125), f)
    z = Z0 + np.arange(0.05, 0.35, 0.0025)
    img = hr.migrate(holo, z, medium=wet, upsample=2)
    print(f"graded model: focus {100 * (img.peak()[2] - Z0):.1f} cm deep "
          f"(true {100 * DEPTH:.1f} cm)")
    # The uniform grounds a user might take: the surface's value, and the one that
    # matches the travel time to the object (what a velocity analysis of the echoes
    # gives): n_eff = (1/d) int_0^d n dz = ((3 + 20 d)^1.5 - 3^1.5) / (30 d).
    n_eff = ((3 + 20 * DEPTH) ** 1.5 - 3**1.5) / (30 * DEPTH)
    for name, e in (("surface value", 3.0), ("travel-time match", n_eff**2)):
        u = hr.migrate(holo, z, medium=hr.Medium.half_space(Z0, e), upsample=2)
        zf = u.peak()[2] - Z0
        print(f"uniform half-space, {name} eps' {e:.2f}: focus {100 * zf:.1f} cm deep, "
              f"a depth error of {100 * (zf - DEPTH):+.1f} cm")


if __name__ == "__main__":
    main()
