"""A scanned transceiver over sand: one frequency against eleven (range focusing).

A 40 x 40 scan at 6.2 mm (lambda/4 at 12 GHz), 15 cm above sand (eps 2.5), two
point targets 3 cm apart in depth under one another's edge. One frequency images
them as one long streak (depth of focus lambda (L/A)^2); the coherent sum of 11
frequencies over 8-12 GHz separates them (range resolution c/(2 B n) = 2.4 cm).

Run: ``.venv/bin/python examples/wideband_depth.py [out_dir]``; writes
``wideband_xz.png`` (x-z sections at y = 0, dB).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import holoradar as hr


def main(out: Path) -> Path:
    sand = hr.Medium.half_space(0.15, 2.5)
    freqs = np.linspace(8e9, 12e9, 11)
    targets = [hr.PointTarget((0.0, 0.0, 0.24)), hr.PointTarget((0.02, 0.0, 0.27))]
    scan = hr.Aperture.grid(40, 0.0062, monostatic=True)
    h = hr.simulate(hr.Scene(sand, targets=targets), scan, freqs, include_surface=False)
    zs = np.linspace(0.17, 0.33, 161)
    wide = hr.migrate(h, zs, medium=sand, upsample=2)
    mono = hr.migrate(h.at_frequency(5), zs, medium=sand, upsample=2)
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    res = hr.theory.range_resolution(4e9, 2.5)
    for ax, img, title in zip(fig.subplots(1, 2), (mono, wide),
                              ("one frequency (10 GHz)",
                               f"11 frequencies, 8-12 GHz (c/2Bn = {res * 100:.1f} cm)"),
                              strict=True):
        iy = int(np.argmin(np.abs(img.y)))
        sec = np.abs(img.data[:, iy, :])
        db = 20 * np.log10(np.maximum(sec / sec.max(), 1e-3))
        m = ax.pcolormesh(img.x * 100, zs * 100, db, vmin=-30, vmax=0, cmap="magma")
        for t in targets:
            ax.plot(t.position[0] * 100, t.position[2] * 100, "c+", ms=10)
        ax.set_ylim(zs[-1] * 100, zs[0] * 100)
        ax.set_xlabel("x (cm)")
        ax.set_ylabel("range from the scan plane (cm)")
        ax.set_title(title)
        fig.colorbar(m, ax=ax, label="|image| (dB)")
    fig.suptitle("Scanned transceiver 15 cm above sand (eps 2.5): x-z section at y = 0;"
                 " + marks the points")
    out.mkdir(parents=True, exist_ok=True)
    path = out / "wideband_xz.png"
    fig.savefig(path, dpi=110)
    return path


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out")))
