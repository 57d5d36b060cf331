"""Write a small survey: frames of a 16 x 16 array moved along a buried pipe.

The array (2.5 cm pitch, 40 cm wide) is moved in 10 cm steps along x over
sand (eps 2.5+0.0125j, surface 30 cm below the array); a pipe 12 cm deep runs
along x from -0.30 to 0.30 m at y = 0.05, a small stone lies at (0.25, -0.10).
Each frame is a holoradar file placed by its pose: `survey/frame_00.nc`, ...

Run: python examples/make_survey.py [FOLDER]  (default: survey; existing frames
are kept, not overwritten).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import holoradar as hr


def main(folder: str = "survey") -> None:
    out = Path(folder)
    out.mkdir(exist_ok=True)
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    pipe = [hr.PointTarget((x, 0.05, 0.42), 0.004) for x in np.arange(-0.30, 0.3001, 0.005)]
    stone = [hr.PointTarget((0.25, -0.10, 0.40), 0.02)]
    scene = hr.Scene(sand, hr.PlaneWave(), pipe + stone)
    for k, x0 in enumerate(np.arange(-0.40, 0.4001, 0.10)):
        path = out / f"frame_{k:02d}.nc"
        if path.exists():
            continue
        ap = hr.Aperture.grid(16, 0.025, pose=hr.Pose((float(x0), 0.0, 0.0)))
        holo = hr.simulate(scene, ap, 9.9e9, include_surface=False, snr_db=35.0, seed=k)
        hr.save(holo, path, history=[{"step": "simulate", "parameters": {"x0": float(x0)}}])
    print(f"{len(list(out.glob('frame_*.nc')))} frames in {out}/")


if __name__ == "__main__":
    main(*sys.argv[1:2])
