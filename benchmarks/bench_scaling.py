"""Cost against size: ``migrate``, ``invert``, ``detect`` and ``holoradar image``, each
beside the FFTs its work needs, one axis of the problem varied at a time.

Base case: a scanned transceiver, 64 x 64 elements at 3 mm, 8 frequencies 8-12 GHz,
32 planes 2-18 cm, complex128 data of unit noise plus a point at 8 cm (what a user's
scan holds), every option at its default. Varied: the aperture (16^2 to 512^2), the
planes (1 to 512) and the frequencies (1 to 128); ``invert`` (least squares, 10 steps:
its cost is steps x a forward-adjoint pair) and ``detect`` on the smaller sizes only
(a 512^2 x 512 volume is 1 GiB of complex64). Each time is the best of three warm
calls (plans and caches built by a first call); the floor is what the work needs at
least, complex64 and unpadded: one ``fft2`` of each frequency's data and one
``ifft2`` of each plane (for ``invert``: twice that, a forward and an adjoint map per
step). ``holoradar image`` runs end to end in a fresh process (start, import, read
the ``.npz``, image, check, write the ``.nc`` and the PNG) on the aperture axis, with
``--no-check`` (a 16 x 16 array at 3 mm is refused as too small to focus at 18 cm).

The slope is the least-squares slope of log(time) against log(size) over the axis:
1 for work linear in the size (each plane, each frequency), ~1 for the aperture's
pixel count (an FFT's ``n log n``).

Run: ``.venv/bin/python benchmarks/bench_scaling.py [n] [planes] [nf]`` (the axes to
measure, default all; the others are kept from the results file); writes
``benchmarks/results_scaling.json`` and prints the table docs/performance.md shows.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from timing import best

HERE = Path(__file__).parent
BASE = {"n": 64, "planes": 32, "nf": 8}
AXES = {"n": [16, 32, 64, 128, 256, 512], "planes": [1, 8, 32, 128, 512],
        "nf": [1, 8, 32, 128]}
SMALL = {"n": 128, "planes": 128, "nf": 32}   # invert and detect up to these


def hologram(n: int, nf: int):
    import holoradar as hr

    rng = np.random.default_rng(0)
    x = (np.arange(n) - n / 2) * 0.003
    f = np.linspace(8e9, 12e9, nf) if nf > 1 else np.array([10e9])
    k = 2 * np.pi * f / 299792458.0
    X, Y = np.meshgrid(x, x)
    r = np.sqrt(X**2 + Y**2 + 0.08**2)
    data = rng.standard_normal((nf, n, n)) + 1j * rng.standard_normal((nf, n, n))
    data += 10 * np.exp(2j * k[:, None, None] * r) / (r / 0.08) ** 2
    return hr.Hologram(data if nf > 1 else data[0], x, x, f if nf > 1 else float(f[0]),
                       monostatic=True)


def planes(count: int) -> np.ndarray:
    return np.array([0.08]) if count == 1 else np.linspace(0.02, 0.18, count)


def floor(n: int, nf: int, nz: int) -> float:
    import scipy.fft as sfft

    data = np.zeros((nf, n, n), np.complex64)
    vol = np.zeros((nz, n, n), np.complex64)
    return best(lambda: (sfft.fft2(data, workers=-1, overwrite_x=True),
                         sfft.ifft2(vol, workers=-1, overwrite_x=True)))


def cli(n: int, nf: int, nz: int) -> float:
    h = hologram(n, nf)
    zs = planes(nz)
    with tempfile.TemporaryDirectory() as d:
        src = Path(d) / "scan.npz"
        np.savez(src, data=h.data, x=h.x, y=h.y, f=h.frequencies)
        times = []
        for i in range(3):
            t = time.perf_counter()
            subprocess.run([sys.executable, "-m", "holoradar", "image", str(src), "--layout",
                            "data=data,x=x,y=y,frequency=f,axes=fyx,monostatic=true"
                            if nf > 1 else "data=data,x=x,y=y,frequency=f,monostatic=true",
                            "--z", f"{zs[0]}:{zs[-1] + 1e-9}:{(zs[-1] - zs[0]) / max(nz - 1, 1)}"
                            if nz > 1 else str(zs[0]), "-q", "--no-check",
                            "-o", str(Path(d) / f"o{i}.nc")],
                           check=True, capture_output=True)
            times.append(time.perf_counter() - t)
    return min(times)


def slope(sizes: list[float], times: list[float]) -> float:
    return float(np.polyfit(np.log(sizes), np.log(times), 1)[0])


def main() -> None:
    import holoradar as hr

    warnings.simplefilter("ignore")
    only = [a for a in sys.argv[1:] if a in AXES] or list(AXES)
    old = HERE / "results_scaling.json"
    rows = [r for r in json.loads(old.read_text())["rows"] if r["axis"] not in only] \
        if old.exists() and only != list(AXES) else []
    for axis, values in ((a, AXES[a]) for a in only):
        for v in values:
            case = {**BASE, axis: v}
            n, nf, nz = case["n"], case["nf"], case["planes"]
            h, zs = hologram(n, nf), planes(nz)
            row = {"axis": axis, **case, "floor_s": floor(n, nf, nz),
                   "migrate_s": best(lambda h=h, zs=zs: hr.migrate(h, zs))}
            if all(case[k] <= SMALL[k] for k in SMALL):
                row["invert_s"] = best(lambda h=h, zs=zs: hr.invert(
                    h, zs, method="lsqr", max_iter=10, progress=False), n=1)
                img = hr.migrate(h, zs)
                if nf == 1 and nz > 1:
                    # one frequency does not focus in range: detect searches the plane
                    # of the point (from the image alone), as a user is told to
                    img = img.plane(0.08)
                row["detect_s"] = best(lambda img=img: hr.detect(img), n=1)
            if axis == "n":
                row["cli_s"] = cli(n, nf, nz)
            rows.append(row)
            print(json.dumps(row), flush=True)
    slopes = {}
    for axis in AXES:
        sub = [r for r in rows if r["axis"] == axis]
        size = [(r["n"] ** 2 if axis == "n" else r[axis]) for r in sub]
        for what in ("floor_s", "migrate_s", "invert_s", "detect_s", "cli_s"):
            pts = [(s, r[what]) for s, r in zip(size, sub, strict=True) if what in r]
            if len(pts) >= 3:
                slopes[f"{axis}:{what}"] = slope(*zip(*pts, strict=True))
    out = {"base": BASE, "rows": rows, "slopes": slopes}
    (HERE / "results_scaling.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(slopes, indent=1))


if __name__ == "__main__":
    main()
