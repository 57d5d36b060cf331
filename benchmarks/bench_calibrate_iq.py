"""Coverage of the I/Q imbalance's stated standard errors, as ``fit_calibration`` states
them, over simulated devices.

The test bench of ``docs/calibration.md``: 16 x 16 elements at 2.5 cm, 9.5/9.9/10.3 GHz,
the horn at (0, -0.25, -0.05) m (cos^2, tilted 27 degrees), gq = 1.15, phi = 8 degrees,
I - iQ, a per-frequency response, receiver noise 0.01 and 8 repeats of each reference.
Three reference sets (one plate at 0.300 m; the plate at 0.300 and 0.304 m; the empty
scene and the plate with the direct wave) and four kinds of element phases, each device
drawn anew (amplitudes log-normal, 20%):

* ``uniform``: independent and uniform (what the standard errors assume);
* ``ramp``: a linear phase across the array, up to two turns each way, random offset;
* ``smooth``: a smooth random field (Gaussian-filtered noise, width 4 elements, sd 2
  rad), random offset;
* ``blocks``: one random phase per block of 4 x 4 elements (a cable each) plus 0.2 rad.

For each: the mean stated standard error over the actual scatter of the estimates
(gain and phase), the share of errors within 1.96 and 1 standard errors (nominal 95%
and 68%), the mean effective number of groups, and the same ratio for the plain
sandwich (``n/(n-1)`` times the sum, no leverage correction). Blocks are also fitted
with ``groups`` = the blocks. A ratio from T trials is known to about 1/sqrt(2T)
(1.1% at 4000), a coverage to sqrt(p(1-p)/T) (0.34%).

Writes ``benchmarks/results_calibrate_iq.json``. Run:
``.venv/bin/python benchmarks/bench_calibrate_iq.py [TRIALS]`` (4000: about 3 minutes).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter

import holoradar as hr
from holoradar import calibrate as cb
from holoradar.calibrate.iq import correct_iq

X = (np.arange(16) - 7.5) * 0.025
F = np.array([9.5e9, 9.9e9, 10.3e9])
HORN = hr.PointSource((0.0, -0.25, -0.05), pattern_exponent=2, axis=(0.0, 0.5, 1.0))
SIGMA, NREP = 0.01, 8
G_IQ, PHI = 1.15, np.radians(8.0)
RESPONSE = np.array([1.0, 0.7, 1.3]) * np.exp(1j * np.array([0.3, 2.0, -1.2]))
CASES = {"one plate": [("plate", 0.300, None)],
         "plate pair": [("plate", 0.300, None), ("plate", 0.304, None)],
         "empty + plate": [("empty", None, None), ("plate", 0.300, True)]}
KINDS = ("uniform", "ramp", "smooth", "blocks")
YY, XX = np.meshgrid(np.arange(16), np.arange(16), indexing="ij")
ELEMENTS = np.arange(256).reshape(16, 16)
BLOCKS = (YY // 4) * 4 + XX // 4


def phases(kind: str, rng: np.random.Generator) -> np.ndarray:
    offset = 2 * np.pi * rng.random()
    if kind == "uniform":
        return 2 * np.pi * rng.random((16, 16))
    if kind == "ramp":
        a, b = rng.uniform(-2, 2, 2) * 2 * np.pi / 16
        return offset + a * XX + b * YY
    if kind == "smooth":
        w = gaussian_filter(rng.standard_normal((16, 16)), 4, mode="wrap")
        return offset + 2.0 * w / w.std()
    if kind == "blocks":
        return (offset + np.kron(2 * np.pi * rng.random((4, 4)), np.ones((4, 4)))
                + 0.2 * rng.standard_normal((16, 16)))
    raise ValueError(kind)


def plain_sandwich(i: np.ndarray, q: np.ndarray, g: float, phi: float,
                   groups: np.ndarray) -> tuple[float, float]:
    """The standard errors without the leverage correction (``n/(n-1)`` times the sum)."""
    z = correct_iq(i, q, g, phi).ravel()
    x = np.exp(1j * phi) * z * z
    lab = groups.ravel()
    n = lab.max() + 1
    sums = np.bincount(lab, x.real, n) + 1j * np.bincount(lab, x.imag, n)
    scale = np.cos(phi) / np.sum(np.abs(z) ** 2) * np.sqrt(n / (n - 1))
    return (g * scale * np.sqrt(np.sum(sums.real**2)), scale * np.sqrt(np.sum(sums.imag**2)))


def run(case: str, models: list[np.ndarray], kind: str, labels: np.ndarray,
        trials: int) -> dict:
    rng = np.random.default_rng(7)
    rows = []
    for _ in range(trials):
        gain = np.exp(0.2 * rng.standard_normal((16, 16))) * np.exp(1j * phases(kind, rng))
        ii, qq = [], []
        for m in models:
            s = RESPONSE[:, None, None] * gain * m
            s = s + SIGMA / np.sqrt(2 * NREP) * (rng.standard_normal(s.shape)
                                                 + 1j * rng.standard_normal(s.shape))
            s = np.conj(s)                                  # the device delivers I - iQ
            ii.append(s.real)
            qq.append(G_IQ * (np.cos(PHI) * s.imag + np.sin(PHI) * s.real))
        i, q = np.stack(ii), np.stack(qq)
        groups = np.broadcast_to(labels, i.shape)
        est = cb.iq_imbalance(i, q, groups)
        rows.append((est.gain, est.phase, est.stderr_gain, est.stderr_phase,
                     est.effective_groups, *plain_sandwich(i, q, est.gain, est.phase, groups)))
    r = np.array(rows)
    sd_g, sd_p = r[:, 0].std(ddof=1), r[:, 1].std(ddof=1)
    zg, zp = (r[:, 0] - G_IQ) / r[:, 2], (r[:, 1] - PHI) / r[:, 3]
    out = {"case": case, "phases": kind, "groups": "blocks" if labels is BLOCKS else "elements",
           "trials": trials,
           "stderr_gain_rel": float(r[:, 2].mean() / G_IQ), "scatter_gain_rel": sd_g / G_IQ,
           "stderr_phase_deg": float(np.degrees(r[:, 3].mean())),
           "scatter_phase_deg": float(np.degrees(sd_p)),
           "ratio_gain": float(r[:, 2].mean() / sd_g), "ratio_phase": float(r[:, 3].mean() / sd_p),
           "within_1.96_gain": float(np.mean(np.abs(zg) < 1.96)),
           "within_1.96_phase": float(np.mean(np.abs(zp) < 1.96)),
           "within_1_gain": float(np.mean(np.abs(zg) < 1)),
           "within_1_phase": float(np.mean(np.abs(zp) < 1)),
           "effective_groups": float(r[:, 4].mean()),
           "plain_ratio_gain": float(r[:, 5].mean() / sd_g),
           "plain_ratio_phase": float(r[:, 6].mean() / sd_p)}
    print(f"{case:14s} {kind:8s} {out['groups']:8s} SE/scatter {out['ratio_gain']:.2f} "
          f"{out['ratio_phase']:.2f} (plain {out['plain_ratio_gain']:.2f} "
          f"{out['plain_ratio_phase']:.2f})  within 1.96 SE {out['within_1.96_gain']:.3f} "
          f"{out['within_1.96_phase']:.3f}  n_eff {out['effective_groups']:.0f}", flush=True)
    return out


def main(trials: int = 4000) -> None:
    results = []
    for case, refs in CASES.items():
        models = [cb.reference_field(kind, X, X, F, HORN, plate_range=z, include_direct=d)
                  for kind, z, d in refs]
        for kind in KINDS:
            results.append(run(case, models, kind, ELEMENTS, trials))
        results.append(run(case, models, "blocks", BLOCKS, trials))
    path = Path(__file__).with_name("results_calibrate_iq.json")
    path.write_text(json.dumps(results, indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
