"""Time-domain traces and GPR vendors' files: a pulse radar's line imaged as a line scan.

The traces here are made from frequency samples of ``simulate`` by the inverse
relation (``s(t) = sum_f S(f) exp(-2 pi i f t) / (N dt)`` over the positive and
negative bins): turned back into frequency samples they must be those samples to
rounding. The file is a SEG-Y written with segyio as impdar reads it (sample interval
in nanoseconds, positions in GroupX in centimetres, little-endian), read by
``hr.load`` through impdar.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from holoradar.data.hologram import C0
from holoradar.data.traces import frequency_samples

DT, NT = 1e-9, 256          # 1 ns sampling (SEG-Y's interval in whole ns), 256 ns
EPS = 9.0                   # moist soil
PIPES = ((-0.5, 1.0), (0.6, 1.5))   # (x, axis depth) of two pipes across the line
RADIUS = 0.05
PITCH = 0.05


def _line() -> tuple[hr.Hologram, np.ndarray, np.ndarray]:
    """A 250 MHz pulse GPR's line over two pipes: its traces (NT, nx), the frequency
    samples they hold, and those bins' frequencies."""
    fk = np.fft.fftfreq(NT, DT)
    band = np.flatnonzero((fk > 90e6) & (fk < 410e6))
    f = fk[band]
    soil = hr.Medium.half_space(0.0, EPS)
    pipes = [hr.LineTarget((x, -20.0, z), (x, 20.0, z), RADIUS) for x, z in PIPES]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        h = hr.simulate(hr.Scene(soil, targets=pipes),
                        hr.Aperture.grid(60, PITCH, ny=1, monostatic=True), f,
                        include_surface=False)
    S = h.data[:, 0, :] * np.exp(-((f - 250e6) / 100e6) ** 2)[:, None]   # the pulse
    spec = np.zeros((NT, S.shape[1]), complex)
    spec[band], spec[(NT - band) % NT] = S, np.conj(S)
    traces = (np.fft.fft(spec, axis=0) / (NT * DT)).real
    return h, traces, S


@pytest.fixture(scope="module")
def line() -> tuple[hr.Hologram, np.ndarray, np.ndarray]:
    return _line()


def test_traces_give_back_the_frequency_samples_they_hold(line):
    h, traces, S = line
    got, f = frequency_samples(traces, DT, band=(h.frequencies[0] - 1, h.frequencies[-1] + 1))
    np.testing.assert_allclose(f, h.frequencies)
    # Two FFTs of 256 in float64: 1e-12 of the peak is rounding, a sign or a factor
    # of dt off is O(1).
    assert np.max(np.abs(got - S)) <= 1e-12 * np.max(np.abs(S))
    # A time zero t0 takes exp(-2 pi i f t0) off every sample.
    shifted, _ = frequency_samples(traces, DT, band=(f[0] - 1, f[-1] + 1), time_zero=3e-9)
    np.testing.assert_allclose(shifted, S * np.exp(-2j * np.pi * f * 3e-9)[:, None],
                               atol=1e-12 * np.abs(S).max())


def test_the_antennas_band_is_where_the_pulse_is(line):
    _, traces, _ = line
    _, f = frequency_samples(traces, DT)
    # A Gaussian pulse spectrum exp(-((f - 250 MHz) / 100 MHz)^2) in power falls to
    # -10 dB at 250 +- 100 sqrt(ln(10) / 2) = 250 +- 107 MHz (the scene's own spectrum
    # tilts it by a bin or two: 4 MHz bins here, allowed 10 MHz).
    half = 100e6 * np.sqrt(np.log(10) / 2)
    assert abs(f[0] - (250e6 - half)) < 10e6 and abs(f[-1] - (250e6 + half)) < 10e6


def test_a_segy_line_through_impdar_images_its_pipes(line, tmp_path):
    segyio = pytest.importorskip("segyio")
    pytest.importorskip("impdar")
    h, traces, _ = line
    fn = tmp_path / "line.sgy"
    spec = segyio.spec()
    spec.endian, spec.format = "little", 5
    spec.samples, spec.tracecount = list(range(NT)), traces.shape[1]
    with segyio.create(str(fn), spec) as s:
        s.bin.update({segyio.BinField.Interval: int(DT * 1e9), segyio.BinField.Samples: NT})
        for i in range(traces.shape[1]):
            s.header[i] = {segyio.TraceField.GroupX: round((h.x[i] - h.x[0]) * 100),
                           segyio.TraceField.GroupY: 0}
            s.trace[i] = traces[:, i].astype(np.float32)
    g = hr.load(fn)
    assert g.is_line and g.monostatic and g.nf > 50
    np.testing.assert_allclose(g.x, h.x - h.x[0], atol=1e-9)
    soil = hr.Medium.half_space(0.0, EPS)
    zs = np.arange(0.2, 2.0, 0.02)
    img = hr.migrate(g, zs, medium=soil, upsample=2)
    a = np.abs(img.data[:, 0, :])
    # Within one trace spacing across and a quarter of the range cell c / (2 B n)
    # (B the band read, 200-220 MHz: about 8 cm) of each pipe's top.
    quarter = C0 / (2 * np.ptp(g.frequencies) * np.sqrt(EPS)) / 4
    for x, z in PIPES:
        near = np.abs(img.x - (x - h.x[0])) < 0.3
        iz, ix = np.unravel_index(np.argmax(a[:, near]), a[:, near].shape)
        assert abs(img.x[near][ix] - (x - h.x[0])) <= PITCH
        assert abs(zs[iz] - (z - RADIUS)) <= quarter


def test_a_gpr_file_impdar_cannot_read_is_named(tmp_path):
    pytest.importorskip("impdar")
    bad = tmp_path / "broken.sgy"
    bad.write_bytes(b"not a segy file" * 10)
    with pytest.raises(ValueError, match=r"broken\.sgy: impdar cannot read it as segy"):
        hr.load(bad)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"x": [0.0]}, "x must hold one position per trace"),
    ({"x": [0.0, 0.1, 0.05]}, "x must be monotonic"),
    ({"time_zero": 1e-6}, "time_zero must lie within the trace"),
    ({"band": (5e8, 6e8)}, "band must lie within the sampled band"),
    ({"dt": 0.0}, "dt must be the sample interval"),
])
def test_bad_traces_are_refused_naming_the_argument(kwargs, match):
    t = np.arange(64) * DT
    traces = np.exp(-((t[:, None] - 5e-9) / 2e-9) ** 2) * np.ones((1, 3))
    args = {"traces": traces, "dt": DT, "x": [0.0, 0.05, 0.1], **kwargs}
    with pytest.raises(ValueError, match=match):
        hr.Hologram.from_traces(**args)


def test_traces_of_different_lengths_and_one_position_are_refused():
    with pytest.raises(ValueError, match="same number of samples"):
        hr.Hologram.from_traces([np.ones(64), np.ones(60)], DT, [0.0, 0.05])
    with pytest.raises(ValueError, match="at least 2 positions"):
        hr.Hologram.from_traces(np.ones((64, 1)), DT, [0.0])
