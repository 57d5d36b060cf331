"""``migrate`` as a user calls it: complex128 data, default options, warm and cold.

The case is the size of a measured scanned-transceiver hologram: 11 frequencies
8-12 GHz x 187 x 144 elements at 3 mm, imaged onto 110 planes 0-0.18 m. Timed in one
run, ratios only (the machine is shared):

* ``default``: ``hr.migrate(h, zs)`` on complex128 data (single precision, the default
  padding);
* ``double``: the same with ``dtype=np.complex128`` (the previous default);
* ``unpadded``: the default with ``pad=False``;
* ``floor``: what the work needs at least: one ``fft2`` per frequency and one inverse
  FFT per plane, complex64, unpadded;
* ``makers``: a device maker's 40-line NumPy Stolt (``bench_fft_limit.makers_stolt``);
* ``cold``: the default's first call in a fresh process (``import holoradar`` and the
  data made before the clock starts), and the whole of ``holoradar image`` on a file
  in a fresh process (start, import, read, image, write) beside the maker's whole
  script in a fresh Python (import NumPy, ``np.load``, their Stolt, ``np.save`` of the
  magnitude as float32). ``holoradar image`` runs on the ``.npz`` with ``--layout`` and
  every other option at its default (``--upsample auto``, the PNG, single precision),
  as a user types it; the sizes of the two outputs are compared too.

Writes ``benchmarks/results_defaults.json``. Run: ``python benchmarks/bench_defaults.py``;
``--large``: 64 frequencies x 256 x 256 onto 256 planes (``results_defaults_large.json``).
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
NF, NY, NX, NZ, ZMAX = 11, 187, 144, 110, 0.18
if "--large" in sys.argv:
    NF, NY, NX, NZ = 64, 256, 256, 256


# A maker's whole script in a fresh Python: import NumPy, read the data, their Stolt,
# save the volume (the Stolt of bench_fft_limit, which imports NumPy alone).
MAKERS_SCRIPT = """
import sys
import numpy as np
from types import SimpleNamespace
sys.path.insert(0, sys.argv[1])
from bench_fft_limit import makers_stolt
d = np.load(sys.argv[2])
x, y, f = d["x"], d["y"], d["f"]
h = SimpleNamespace(data=d["data"], pitch=(x[1] - x[0], y[1] - y[0]),
                    wavenumbers=2 * np.pi * f / 299792458.0)
vol = makers_stolt(h, np.linspace(0.0, float(sys.argv[4]), int(sys.argv[5])))
np.save(sys.argv[3], np.abs(vol).astype(np.float32))
"""


def hologram(dtype=np.complex128):
    import holoradar as hr

    rng = np.random.default_rng(0)
    data = (rng.standard_normal((NF, NY, NX)) + 1j * rng.standard_normal((NF, NY, NX)))
    return (hr.Hologram(data.astype(dtype), np.arange(NX) * 0.003, np.arange(NY) * 0.003,
                        np.linspace(8e9, 12e9, NF), monostatic=True),
            np.linspace(0.0, ZMAX, NZ))


def best(fn, n: int = 3) -> float:
    from timing import best as fastest

    return fastest(fn, n, warm=False)   # main() warms every run first


def cold_child() -> None:
    import holoradar as hr

    h, zs = hologram()
    t = time.perf_counter()
    hr.migrate(h, zs)
    print(time.perf_counter() - t)


def main() -> None:
    import scipy.fft as sfft

    import holoradar as hr
    sys.path.insert(0, str(HERE))
    from bench_fft_limit import makers_stolt

    h, zs = hologram()
    h64, _ = hologram(np.complex64)
    vol = np.zeros((NZ, NY, NX), np.complex64)

    def floor() -> None:
        sfft.fft2(h64.data, workers=-1)
        sfft.ifft2(vol, workers=-1)

    runs = {
        "default": lambda: hr.migrate(h, zs),
        "double": lambda: hr.migrate(h, zs, dtype=np.complex128),
        "unpadded": lambda: hr.migrate(h, zs, pad=False),
        "floor": floor,
        "makers": lambda: makers_stolt(h, zs),
    }
    for fn in runs.values():
        fn()   # warm: plans, caches, the compiled loop
    warm = {k: best(fn) for k, fn in runs.items()}
    large = ["--large"] if "--large" in sys.argv else []
    cold = [float(subprocess.run([sys.executable, __file__, "--cold", *large],
                                 capture_output=True, text=True,
                                 check=True).stdout.strip().splitlines()[-1])
            for _ in range(3)]
    with tempfile.TemporaryDirectory() as d:
        raw = Path(d) / "h.npz"
        np.savez(raw, data=h.data, x=h.x, y=h.y, f=h.frequencies)
        ends, makers_ends, sizes = [], [], []
        layout = "data=data,x=x,y=y,frequency=f,axes=fyx,monostatic=true"
        for i in range(3):
            t = time.perf_counter()
            subprocess.run([sys.executable, "-m", "holoradar", "image", str(raw), "--layout",
                            layout, "--z", f"0:{ZMAX}:{ZMAX / (NZ - 1)}", "-q",
                            "-o", str(Path(d) / f"i{i}.nc")], check=True)
            ends.append(time.perf_counter() - t)
            t = time.perf_counter()
            subprocess.run([sys.executable, "-c", MAKERS_SCRIPT, str(HERE), str(raw),
                            str(Path(d) / f"m{i}.npy"), str(ZMAX), str(NZ)], check=True)
            makers_ends.append(time.perf_counter() - t)
            sizes.append((Path(d) / f"i{i}.nc").stat().st_size
                         / (Path(d) / f"m{i}.npy").stat().st_size)
    out = {
        "case": f"{NF} frequencies x {NY} x {NX} at 3 mm onto {NZ} planes, complex128 data",
        "warm_s": warm,
        "cold_first_call_s": statistics.median(cold),
        "cli_end_to_end_s": statistics.median(ends),
        "makers_end_to_end_s": statistics.median(makers_ends),
        "ratios": {
            "default_over_floor": warm["default"] / warm["floor"],
            "makers_over_default": warm["makers"] / warm["default"],
            "double_over_default": warm["double"] / warm["default"],
            "default_over_unpadded": warm["default"] / warm["unpadded"],
            "cold_over_floor": statistics.median(cold) / warm["floor"],
            "cli_over_makers_end_to_end": statistics.median(ends) / statistics.median(
                makers_ends),
            "cli_output_over_makers_output": max(sizes),
        },
    }
    name = "results_defaults_large.json" if large else "results_defaults.json"
    (HERE / name).write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    if "--cold" in sys.argv:
        cold_child()
    else:
        main()
