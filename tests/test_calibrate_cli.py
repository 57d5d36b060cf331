"""``holoradar calibrate fit`` and ``apply`` as a user meets them: the I/Q imbalance printed
with its standard errors, a weak one warned of, and the horn never assumed (its pattern
and boresight from the options or from what the files record, else a one-line error)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import holoradar as hr
from cli_helpers import one_line_error, run
from holoradar import calibrate as cb

X = (np.arange(8) - 3.5) * 0.025
F = np.array([9.5e9, 9.9e9])
HORN = hr.PointSource((0.0, -0.25, -0.05), pattern_exponent=2, axis=(0.0, 0.5, 1.0))
HORN_OPTS = ("--horn", "0,-0.25,-0.05", "--horn-axis", "0,0.5,1", "--pattern", "2")






@pytest.fixture(scope="module")
def device(tmp_path_factory):
    """A faulty device's plate pair as a user's .npz files (no horn recorded) and as
    holoradar .nc files (the horn recorded as their source), and the library's fit."""
    d = tmp_path_factory.mktemp("device")
    rng = np.random.default_rng(3)
    dev = cb.DeviceFaults(iq_gain=1.1, iq_phase=np.radians(6),
                          element_gain=np.exp(2j * np.pi * rng.random((8, 8))),
                          response=np.array([1.0, 0.8j]), conjugate=True, noise=1e-3)
    refs, npz, nc = [], [], []
    for j, z in enumerate((0.300, 0.304)):
        field = hr.Hologram(cb.reference_field("plate", X, X, F, HORN, plate_range=z), X, X, F,
                            source=HORN)
        raw = dev.record(field, "HSR-7", repeats=4, seed=j)
        refs.append(cb.Reference(raw, "plate", plate_range=z))
        np.savez(d / f"plate{j}.npz", I=raw.i, Q=raw.q, x=X, y=X, frequency=F)
        npz.append(d / f"plate{j}.npz")
        nc.append(hr.save(hr.Hologram(raw.i + 1j * raw.q, X, X, F, source=HORN),
                          d / f"plate{j}.nc"))
    survey = dev.record(field, "HSR-7", seed=9)
    np.savez(d / "survey.npz", I=survey.i, Q=survey.q, x=X, y=X, frequency=F)
    return {"dir": d, "npz": npz, "nc": nc, "refs": refs, "lib": cb.fit_calibration(refs)}


def _plates(files: list[Path]) -> list[object]:
    return ["--plate", files[0], "0.300", "--plate", files[1], "0.304"]


def test_fit_prints_the_iq_imbalance_with_its_standard_errors(device, tmp_path):
    res = run("calibrate", "fit", "--device", "HSR-7", *_plates(device["npz"]), *HORN_OPTS,
              "--layout", "axes=tfyx", "-o", tmp_path / "cal.nc")
    iq = device["lib"].provenance["iq_imbalance"]
    m = re.search(r"Q gain ([\d.]+) \+- ([\d.]+), Q phase ([\d.]+) \+- ([\d.]+) deg "
                  r"\(standard errors\)", res.output)
    assert m, res.output
    gain, se_gain, phase, se_phase = (float(v) for v in m.groups())
    # Two significant digits of the error, the value to the same place.
    assert se_gain == pytest.approx(iq["stderr_gain"][0], rel=0.05)
    assert se_phase == pytest.approx(np.degrees(iq["stderr_phase_rad"][0]), rel=0.05)
    assert abs(gain - device["lib"].iq_gain[0]) <= se_gain / 20
    assert abs(phase - np.degrees(device["lib"].iq_phase[0])) <= se_phase / 20
    assert m.group(1).split(".")[1].__len__() == m.group(2).split(".")[1].__len__()
    # One plate leaves the imbalance weak: warned, with the fix.
    res = run("calibrate", "fit", "--device", "HSR-7", "--plate", device["npz"][0], "0.300",
              *HORN_OPTS, "--iq-sign", "I-iQ", "--layout", "axes=tfyx", "-o",
              tmp_path / "one.nc")
    warned = [ln for ln in res.output.splitlines() if ln.startswith("warning: ")]
    assert len(warned) == 1 and "(CalibrationWarning)" in warned[0], res.output
    assert "several ranges" in warned[0] and "second reflector" in warned[0]


def test_fit_refuses_a_horn_it_would_have_to_assume(device, tmp_path):
    """A user's files record no horn: its pattern is required, and its boresight with a
    pattern above 0; nothing is written."""
    base = ("calibrate", "fit", "--device", "HSR-7", *_plates(device["npz"]), "--layout",
            "axes=tfyx", "-o", tmp_path / "cal.nc")
    one_line_error(run(*base, ok=False), "plate0.npz records no horn", "--horn")
    one_line_error(run(*base, "--horn", "0,-0.25,-0.05", ok=False), "--pattern",
                   "0 for an isotropic horn")
    one_line_error(run(*base, "--horn", "0,-0.25,-0.05", "--pattern", "2", ok=False),
                   "--horn-axis", "--pattern 2")
    assert not (tmp_path / "cal.nc").exists()
    # An isotropic horn needs no boresight.
    run(*base, "--horn", "0,-0.25,-0.05", "--pattern", "0", "--iq-sign", "I-iQ", "-q")
    assert cb.Calibration.load(tmp_path / "cal.nc").source.pattern_exponent == 0


def test_the_horn_a_file_records_is_used_and_options_override_it(device, tmp_path):
    """holoradar files record their source: fit needs no horn option and equals the
    library's fit; apply with only the horn moved keeps the calibration's pattern and
    axis."""
    run("calibrate", "fit", "--device", "HSR-7", *_plates(device["nc"]), "-o",
        tmp_path / "cal.nc", "-q")
    cal = cb.Calibration.load(tmp_path / "cal.nc")
    assert np.array_equal(cal.total_gain, device["lib"].total_gain)
    assert cal.source.pattern_exponent == 2 and np.allclose(cal.source.axis, HORN.axis)
    # An option given replaces that part of the record only (here the calibration's).
    res = run("calibrate", "apply", device["dir"] / "survey.npz", "--calibration",
              tmp_path / "cal.nc", "--device", "HSR-7", "--horn", "0.01,-0.25,-0.05", "-o",
              tmp_path / "survey.nc", "--json")
    assert json.loads(res.stdout)["device"] == "HSR-7"
    src = hr.load(tmp_path / "survey.nc").source
    assert np.allclose(src.position, (0.01, -0.25, -0.05))
    assert src.pattern_exponent == 2 and np.allclose(src.axis, HORN.axis)
