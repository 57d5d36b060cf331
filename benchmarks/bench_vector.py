"""The vector model: speed against the scalar model, and the coverage of the glare's
permittivity interval, in one run.

* Speed (ratios in one run): the vector glare of a Dipole on a 24 x 24 array against
  the scalar glare of a PointSource (same geometry), cold (first call: new quadrature
  rules, new Bessel matrices) and warm (a new permittivity, as in a fit); the glare
  fit (``estimate_permittivity``) vector against scalar; ``autofocus`` on a 16 x 16
  single-frequency hologram, vector against scalar.
* Coverage: ``estimate_permittivity`` on vector data simulated over grounds eps' 2 ..
  12 (lossless to wet clay), co-polarised (strong) and mostly cross-polarised (weak)
  glare, 20-40 dB, several noise seeds: the share of estimates within 1.96 sigma
  (nominal 95%) and the largest sigma / eps'. These data come from the model the fit
  uses: they test the fit and its uncertainty, not the physics.

Writes ``benchmarks/results_vector.json``. Run: ``.venv/bin/python benchmarks/bench_vector.py``.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import holoradar as hr

F = 9.9e9
K = 2 * np.pi * F / hr.C0
POS = (-0.20, 0.0, 0.20)


def _time(fn, repeat: int = 1) -> float:
    t = time.perf_counter()
    for _ in range(repeat):
        fn()
    return (time.perf_counter() - t) / repeat


_COLD = """
import sys, time
import numpy as np
import holoradar as hr
import scipy.interpolate, scipy.special  # noqa: F401,E401  (imports are not the call's)
K = 2 * np.pi * 9.9e9 / hr.C0
pts = hr.Aperture.grid(24, 0.015).points
m = hr.Medium.half_space(0.30, 2.5)
if sys.argv[1] == "v":
    src = hr.Dipole((-0.20, 0.0, 0.20), moment=(0, 1, 0))
    call = lambda: src.reflected_vector(K, m, pts)
else:
    src = hr.PointSource((-0.20, 0.0, 0.20))
    call = lambda: src.reflected(K, m, pts)
t = time.perf_counter()
call()
print(time.perf_counter() - t)
"""


def _cold_glare(kind: str) -> float:
    """Seconds of the first glare call in a fresh process ("v" vector, "s" scalar)."""
    out = subprocess.run([sys.executable, "-c", _COLD, kind], capture_output=True, text=True,
                         check=True)
    return float(out.stdout.strip().splitlines()[-1])


def speed() -> dict:
    pts = hr.Aperture.grid(24, 0.015).points
    dip = hr.Dipole(POS, moment=(0, 1, 0))
    horn = hr.PointSource(POS)
    out = {}
    m = hr.Medium.half_space(0.30, 2.5)
    # Cold as a user meets it: the first call in a fresh process (imports done), each kind
    # in its own process so neither inherits the other's quadrature rules; alternated,
    # three each, the medians.
    cold = {"v": [], "s": []}
    for _ in range(3):
        for kind in cold:
            cold[kind].append(_cold_glare(kind))
    out["glare_vector_cold_s"] = float(np.median(cold["v"]))
    out["glare_scalar_cold_s"] = float(np.median(cold["s"]))
    dip.reflected_vector(K, m, pts)   # warm-up here, for the warm figures below
    horn.reflected(K, m, pts)
    warm_v, warm_s = [], []
    for e in (2.6, 3.1, 4.0, 6.5, 9.0):
        me = hr.Medium.half_space(0.30, e)
        warm_v.append(_time(lambda me=me: dip.reflected_vector(K, me, pts)))
        warm_s.append(_time(lambda me=me: horn.reflected(K, me, pts)))
    out["glare_vector_warm_s"] = float(np.median(warm_v))
    out["glare_scalar_warm_s"] = float(np.median(warm_s))
    out["glare_ratio_cold"] = out["glare_vector_cold_s"] / out["glare_scalar_cold_s"]
    out["glare_ratio_warm"] = out["glare_vector_warm_s"] / out["glare_scalar_warm_s"]
    ap = hr.Aperture.grid(24, 0.015, polarization=(0, 1, 0))
    h = hr.simulate(hr.Scene(hr.Medium.half_space(0.30, 4.0), dip, []), ap, F,
                    include_direct=True, snr_db=40, seed=1)
    hs = h.replace(polarization=None, source=hr.PointSource(POS, axis=(0, 1, 0), dipole=True))
    start = hr.Medium.half_space(0.30, 3.0)
    out["fit_vector_s"] = _time(lambda: hr.estimate_permittivity(h, start))
    out["fit_scalar_s"] = _time(lambda: hr.estimate_permittivity(hs, start))
    out["fit_ratio"] = out["fit_vector_s"] / out["fit_scalar_s"]
    ap16 = hr.Aperture.grid(16, 0.025, polarization=(0, 1, 0))
    sand = hr.Medium.half_space(0.30, 2.5)
    hv = hr.simulate(hr.Scene(sand, dip, [hr.PointTarget((0.01, 0.0, 0.40), 1e-3)]), ap16, F,
                     include_surface=False, snr_db=40, seed=0)
    model = hr.Medium.half_space(0.30, 3.0)
    out["autofocus_vector_cold_s"] = _time(lambda: hr.autofocus(hv, medium_model=model))
    out["autofocus_vector_warm_s"] = _time(lambda: hr.autofocus(hv, medium_model=model))
    hsc = hv.replace(polarization=None, source=hr.PointSource(POS))
    out["autofocus_scalar_warm_s"] = _time(lambda: hr.autofocus(hsc, medium_model=model))
    out["autofocus_ratio_warm"] = out["autofocus_vector_warm_s"] / out["autofocus_scalar_warm_s"]
    return out


def coverage(seeds: int = 6) -> dict:
    ap = hr.Aperture.grid(24, 0.015, polarization=(0, 1, 0))
    start = hr.Medium.half_space(0.30, 3.0)
    rows = []
    for eps in (2.0, 2.5, 4.0, 6.0, 9.0, 12 + 3j):
        truth = hr.Medium.half_space(0.30, eps)
        for label, moment in (("co", (0, 1, 0)), ("cross", (1, 0.25, 0))):
            for snr in (20, 30, 40):
                for seed in range(seeds):
                    seed = seed + 100 * snr  # independent noise at every SNR
                    h = hr.simulate(hr.Scene(truth, hr.Dipole(POS, moment=moment), []), ap, F,
                                    include_direct=True, snr_db=snr, seed=seed)
                    _, rep = hr.suppress_surface(h, start, method="image_source")
                    est, s_re = rep.eps.real, rep.eps_std[0]
                    s_noise = rep.parameters["eps_noise_std"][0]
                    err = est - np.real(eps)
                    rows.append({"eps": str(eps), "glare": label, "snr_db": snr, "seed": seed,
                                 "estimate": float(est), "sigma": float(s_re),
                                 "noise_sigma": float(s_noise), "z": float(err / s_re),
                                 "z_noise": float(err / s_noise),
                                 "sigma_rel": float(s_re / np.real(eps))})
    z = np.array([r["z"] for r in rows])
    zn = np.array([r["z_noise"] for r in rows])
    return {"cases": len(rows), "within_1.96_sigma": float(np.mean(np.abs(z) < 1.96)),
            "within_2.5_sigma": float(np.mean(np.abs(z) < 2.5)),
            "max_abs_z": float(np.abs(z).max()), "std_z": float(z.std()),
            "noise_within_1.96_sigma": float(np.mean(np.abs(zn) < 1.96)),
            "std_z_noise": float(zn.std()),
            "widened": float(np.mean([r["sigma"] > r["noise_sigma"] for r in rows])),
            "max_sigma_rel": float(max(r["sigma_rel"] for r in rows)), "rows": rows}


if __name__ == "__main__":
    res = {"speed": speed()}
    print(json.dumps(res["speed"], indent=1))
    res["coverage"] = coverage()
    c = res["coverage"]
    print(f"coverage: {c['cases']} cases, {100 * c['within_1.96_sigma']:.0f}% within 1.96 sigma "
          f"(nominal 95%), {100 * c['within_2.5_sigma']:.0f}% within 2.5 sigma, max |z| "
          f"{c['max_abs_z']:.2f}, std of error/sigma {c['std_z']:.2f} (noise sigma alone: "
          f"{c['std_z_noise']:.2f}, {100 * c['noise_within_1.96_sigma']:.0f}% within 1.96), "
          f"sigma widened by model error in {100 * c['widened']:.0f}% of cases, max sigma "
          f"{100 * c['max_sigma_rel']:.2f}% of eps'")
    Path(__file__).with_name("results_vector.json").write_text(json.dumps(res, indent=1))
