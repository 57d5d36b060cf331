"""Write the raw files of a faulty device, as a lab would record them, for the
calibration walk-through (docs/calibration.md): ``device/plate_300.npz`` and
``device/plate_304.npz`` (a metal plate at 300.0 and 303.8 mm, 8 repeats each),
``device/dark.npz`` (32 frames with the transmitter off) and
``device/scan.npz`` (one frame of a scene with two small objects).

Each file holds the raw channels ``I`` and ``Q`` (repeats first, then
frequency, y, x), the element coordinates ``x``, ``y`` (m), ``frequency``
(Hz) and the device's identity ``device`` ("HSR-0042"). The device's faults:
DC offsets, a Q channel with 15% more gain and 8 degrees of phase error, it
delivers I - iQ, random element gains, two dead elements, one noisy, and a
response that differs between its three frequencies.

Run: python examples/make_device_files.py [FOLDER]  (default: device; existing
files are kept).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import holoradar as hr
from holoradar import calibrate as cb

DEVICE = "HSR-0042"
X = (np.arange(16) - 7.5) * 0.025
F = np.array([9.5e9, 9.9e9, 10.3e9])
HORN = hr.PointSource((0.0, -0.25, -0.05), pattern_exponent=2, axis=(0.0, 0.5, 1.0))


def faulty_device() -> cb.DeviceFaults:
    rng = np.random.default_rng(11)
    gain = np.exp(0.2 * rng.standard_normal((16, 16)) + 2j * np.pi * rng.random((16, 16)))
    gain[3, 4] = gain[10, 12] = 0.0  # dead
    noise = np.full((16, 16), 0.01)
    noise[7, 1] = 0.1  # noisy
    return cb.DeviceFaults(dc_i=0.2, dc_q=-0.1, iq_gain=1.15, iq_phase=np.radians(8.0),
                           element_gain=gain, conjugate=True, noise=noise,
                           response=np.array([1.0, 0.7, 1.3]) * np.exp(1j * np.array(
                               [0.3, 2.0, -1.2])))


def write(raw: cb.RawFrames, path: Path) -> None:
    np.savez(path, I=raw.i, Q=raw.q, x=X, y=X, frequency=F, device=np.array(DEVICE))


def main(folder: str = "device") -> None:
    out = Path(folder)
    out.mkdir(exist_ok=True)
    dev = faulty_device()
    jobs = {}
    for name, z in (("plate_300.npz", 0.300), ("plate_304.npz", 0.3038)):
        field = hr.Hologram(cb.reference_field("plate", X, X, F, HORN, plate_range=z), X, X, F,
                            source=HORN)
        jobs[name] = (field, 8, True)
    jobs["dark.npz"] = (hr.Hologram(np.zeros((3, 16, 16)), X, X, F), 32, False)
    scene = hr.Scene(hr.Medium.free_space(), HORN, [hr.PointTarget((0.03, 0.02, 0.40), 0.05),
                                                    hr.PointTarget((-0.08, 0.05, 0.45), 0.03)])
    jobs["scan.npz"] = (hr.simulate(scene, hr.Aperture.grid(16, 0.025), F), None, True)
    for k, (name, (field, repeats, on)) in enumerate(jobs.items()):
        if not (out / name).exists():
            write(dev.record(field, DEVICE, repeats=repeats, transmitter=on, seed=20 + k),
                  out / name)
    print(f"raw files of {DEVICE} in {out}/")


if __name__ == "__main__":
    main(*sys.argv[1:2])
