"""Frame rate of glare suppression + coherent synthesis, against its FFTs.

Six 16 x 16 views (the paper's array, a horn at six positions over sand), the
glare of each fitted and removed, the six views migrated through the sand and
summed coherently onto a 128 x 128 image: one frame of
:class:`holoradar.StreamImager`, warm-started from the previous frame. The FFTs
a frame cannot avoid: one batched FFT of the six holograms (padded to 32 x 32)
and one batched inverse FFT of six 128 x 128 spectra. Both sides are timed
interleaved in one run, fastest of ``REPEAT``.

Run: ``.venv/bin/python benchmarks/bench_stream.py`` (writes results_stream.json).
"""

from __future__ import annotations

import json
import time
import warnings
from pathlib import Path

import numpy as np
import scipy.fft as sfft

import holoradar as hr

REPEAT = 200
F0 = 9.9e9


def main() -> dict:
    sand = hr.Medium.half_space(0.30, hr.permittivity(2.5, 0.005))
    horns = [hr.PointSource((0.0, y0, -0.05), pattern_exponent=2.0)
             for y0 in np.linspace(-0.15, 0.15, 6)]
    target = [hr.PointTarget((0.04, -0.02, 0.42), amplitude=0.02)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        views = [hr.simulate(hr.Scene(sand, s, target), hr.Aperture.paper(), F0,
                             include_direct=True) for s in horns]
        imager = hr.StreamImager(views, 0.42, sand, upsample=4)
    rng = np.random.default_rng(0)
    frames = [np.stack([v.data for v in views])
              * (1 + 0.01 * rng.standard_normal((6, 1, 1))) for _ in range(8)]
    spec = np.zeros((6, 128, 128), complex)

    def ffts() -> object:
        sfft.fft2(frames[0], s=(32, 32), axes=(-2, -1), workers=-1)
        return sfft.ifft2(spec, axes=(-2, -1), workers=-1)

    i = [0]

    def frame() -> object:
        i[0] = (i[0] + 1) % len(frames)
        return imager(frames[i[0]])

    for fn in (ffts, frame):
        fn()
    best = [np.inf, np.inf]
    for _ in range(REPEAT):
        for j, fn in enumerate((ffts, frame)):
            t0 = time.perf_counter()
            fn()
            best[j] = min(best[j], time.perf_counter() - t0)
    t_fft, t_frame = best
    return {"views": 6, "hologram": "16x16", "image": "128x128", "frame_s": t_frame,
            "frames_per_second": 1 / t_frame, "ffts_s": t_fft,
            "frame_over_ffts": t_frame / t_fft}


if __name__ == "__main__":
    r = main()
    Path(__file__).with_name("results_stream.json").write_text(json.dumps(r, indent=2))
    print(f"| frame: 6 views, glare fits + coherent synthesis to 128^2 | {r['frame_s'] * 1e3:.2f}"
          f" ms ({r['frames_per_second']:.0f} frames/s) | FFTs {r['ffts_s'] * 1e3:.2f} ms | "
          f"{r['frame_over_ffts']:.2f}x |")
