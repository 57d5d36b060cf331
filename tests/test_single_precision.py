"""The default precision: migrate computes in single precision unless asked.

A float32 operation rounds to u = 2^-24 = 6e-8 of its result; an FFT of M points
adds up to about u log2(M) of the transform's peak (each butterfly stage rounds
once), and the per-plane products and the sum over frequencies a few u more. On
grids up to 2^16 points (log2 M = 16) that stays under 16 u + a few u ~ 1.2e-6 of the
image's peak: the bound asserted here is 1e-6 of the double-precision image's peak,
measured 1.1-1.2e-7 on these cases, far below the noise of any measured hologram
(30-60 dB SNR, 1e-3.5 to 1e-1.5 of the peak).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from conftest import DATA

BOUND = 1e-6


def _rod(band: bool) -> tuple[hr.Hologram, hr.Medium]:
    with np.load(DATA / "run_B_background.npz") as b, np.load(DATA / "run_C_rod.npz") as c:
        fs = b["freqs_hz"]
        scat = c["Ey"].astype(complex) - b["Ey"].astype(complex)
        x, y = b["x_m"].copy(), b["y_m"].copy()
    sand = hr.Medium.half_space(0.30, hr.permittivity(2.5, sigma=0.0069, frequency=9.9e9))
    h = hr.Hologram(scat if band else scat[9], x, y, fs if band else fs[9])
    return h, sand


def _transceiver() -> hr.Hologram:
    ap = hr.Aperture.grid(48, 0.005, monostatic=True)
    scene = hr.Scene(targets=[hr.PointTarget((0.01, 0.0, 0.2)),
                              hr.PointTarget((-0.05, 0.02, 0.3))])
    return hr.simulate(scene, ap, np.linspace(8e9, 12e9, 21), snr_db=30, seed=0)


@pytest.mark.parametrize("case", ["rod", "rod band", "transceiver", "transceiver upsample",
                                  "layers"])
def test_default_is_single_precision_within_1e6_of_double(case):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        warnings.simplefilter("ignore", hr.IlluminationWarning)
        kw: dict = {}
        if case.startswith("rod"):
            h, medium = _rod(case == "rod band")
            z = np.linspace(0.32, 0.5, 10)
        elif case == "layers":
            h = _transceiver()
            medium = hr.Medium.layered([0.05, 0.12], [4 + 0.2j, 9 + 0.5j])
            z = np.linspace(0.06, 0.3, 25)
        else:
            h, medium = _transceiver(), None
            z = np.linspace(0.1, 0.4, 61)
            kw = {"upsample": 2} if case.endswith("upsample") else {}
        single = hr.migrate(h, z, medium=medium, **kw)
        double = hr.migrate(h, z, medium=medium, dtype=np.complex128, **kw)
    assert double.data.dtype == np.complex128
    if case != "rod band":   # (a dipole's incident phase, in double, promotes the sum)
        assert single.data.dtype == np.complex64
    err = np.abs(single.data - double.data).max() / np.abs(double.data).max()
    assert err <= BOUND


def test_dtype_must_be_a_complex_type():
    h = _transceiver()
    for bad in (np.float32, "int", np.float64):
        with pytest.raises(ValueError, match=r"dtype must be numpy\.complex64 or"):
            hr.migrate(h, 0.2, dtype=bad)
