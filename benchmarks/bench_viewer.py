"""Speed of ``holoradar view``: from a depth-slider move to the new picture in the browser.

The paper's array (16 x 16 elements, 2.5 cm pitch, 9.9 GHz) imaged onto 128 x 128
pixels, six views (a horn at six places above sand), glare suppression on (the
Gaussian-beam fit, per view), coherent synthesis. Headless Chromium drives the
page as a user would:

- cold: from starting ``holoradar view`` to the served URL, and from opening
  the page to its first picture; and a new ground permittivity (glare refit,
  depth sweep and picture redone) from the spinner to the picture;
- warm: 100 slider moves to depths never shown before (no cache hit), each
  timed in the browser from setting the slider to the new picture's arrival,
  to its paint (the animation frame after it arrived) and to that frame shown
  (the next one): the last is the reported latency, what a user waits;
- the imaging behind one move in this process (``ViewSession.image``) against
  the bare FFTs it needs (a forward and an inverse 2-D FFT per view at the
  migration's padded size), as a ratio in one run.

Run: ``.venv/bin/python benchmarks/bench_viewer.py`` (needs Chromium and
chromedriver, as ``make test`` installs). Writes ``benchmarks/results_viewer.json``.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import scipy.fft as sfft

import holoradar as hr
from holoradar.app.view.browser import (
    ViewerProcess,
    find_chromium,
    headless_chromium,
    measure_slider,
    set_model,
    wait_idle,
)
from holoradar.app.view.session import ViewSession

MOVES = 100
F0 = 9.9e9
SAND = (0.30, 2.5 + 0.01j)
HORNS = [(-0.15, -0.10), (0.0, -0.15), (0.15, -0.10), (-0.15, 0.10), (0.0, 0.15),
         (0.15, 0.10)]


def scene(folder: Path) -> list[Path]:
    """Six views of two points in sand (the horn 5 cm behind the array, tilted to
    the centre), written as holoradar files."""
    sand = hr.Medium.half_space(*SAND)
    targets = [hr.PointTarget((0.02, 0.01, 0.42), 0.05), hr.PointTarget((-0.06, 0.0, 0.38),
                                                                        0.03)]
    paths = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i, (x, y) in enumerate(HORNS):
            src = hr.PointSource((x, y, -0.05), pattern_exponent=4, axis=(-x, -y, 0.35))
            h = hr.simulate(hr.Scene(sand, src, targets), hr.Aperture.grid(16, 0.025), F0)
            paths.append(hr.save(h, folder / f"view{i}.nc"))
    return paths


def bare_ffts(session: ViewSession, image_shape: tuple[int, int]) -> float:
    """Fastest time of the FFTs one plane needs, seconds: as migrate does for this
    array, the views' 16 x 16 holograms padded to 32 x 32 forward, and the upsampled
    spectra (the image's shape) back, all views at once."""
    k = len(session.views)
    a = np.ones((k, 16, 16), complex)
    b = np.ones((k, 1, *image_shape), complex)
    best = np.inf
    for _ in range(50):
        t0 = time.perf_counter()
        sfft.fft2(a, s=(32, 32), axes=(-2, -1), workers=-1)
        sfft.ifft2(b, axes=(-2, -1), workers=-1)
        best = min(best, time.perf_counter() - t0)
    return best


def in_process(paths: list[Path]) -> dict[str, float]:
    S = ViewSession(paths)
    s = S.default_settings(ground={"surface": SAND[0], "eps": str(SAND[1])}).replace(
        glare="gaussian")
    t0 = time.perf_counter()
    shape = S.image(s.replace(depth=0.05)).data.shape
    cold = time.perf_counter() - t0
    depths = 0.05 + 0.1 * np.random.default_rng(1).random(MOVES)
    ts = []
    for d in depths:
        t0 = time.perf_counter()
        S.image(s.replace(depth=float(d)))
        ts.append(time.perf_counter() - t0)
    fft = bare_ffts(S, shape)
    warm = float(np.median(ts))
    return {"image_pixels": f"{shape[1]} x {shape[0]}", "plane_cold_ms": cold * 1e3,
            "plane_warm_median_ms": warm * 1e3,
            "bare_ffts_ms": fft * 1e3, "plane_over_bare_ffts": warm / fft}


def in_browser(paths: list[Path], folder: Path) -> dict[str, float]:
    t0 = time.perf_counter()
    with ViewerProcess([*paths, "--z-surface", str(SAND[0]), "--eps", str(SAND[1]),
                        "--glare", "gaussian", "--depth", "0.1"], cwd=folder) as server:
        started = time.perf_counter() - t0
        driver = headless_chromium()
        try:
            t0 = time.perf_counter()
            driver.get(server.url)
            wait_idle(driver)
            first = time.perf_counter() - t0
            t0 = time.perf_counter()
            set_model(driver, "eps_re", "value", 2.6)
            new_medium = time.perf_counter() - t0
            depths = 5.0 + 10.0 * np.random.default_rng(0).random(MOVES)  # cm, all new
            times = measure_slider(driver, depths)
            ms = times[:, 2]
            errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        finally:
            driver.quit()
    return {"server_start_s": started, "first_picture_s": first,
            "new_permittivity_s": new_medium,
            "slider_arrived_median_ms": float(np.median(times[:, 0])),
            "slider_painted_median_ms": float(np.median(times[:, 1])),
            "slider_median_ms": float(np.median(ms)),
            "slider_p95_ms": float(np.percentile(ms, 95)),
            "slider_max_ms": float(ms.max()), "moves": MOVES,
            "updates_per_s_at_median": 1e3 / float(np.median(ms)),
            "console_errors": len(errors)}


def main() -> dict:
    _, _, why = find_chromium()
    if why:
        sys.exit(f"bench_viewer: {why}")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        paths = scene(folder)
        res: dict[str, object] = {
            "array": "16 x 16, pitch 2.5 cm, 9.9 GHz", "image": "128 x 128 (4x upsampled)",
            "views": len(paths), "glare": "gaussian", "cores": len(os.sched_getaffinity(0))}
        res.update(in_process(paths))
        res.update(in_browser(paths, folder))
    out = Path(__file__).with_name("results_viewer.json")
    out.write_text(json.dumps(res, indent=2) + "\n")
    print("| measure | value |\n|---|---|")
    for k, v in res.items():
        print(f"| {k} | {v:.3g} |" if isinstance(v, float) else f"| {k} | {v} |")
    return res


if __name__ == "__main__":
    main()
