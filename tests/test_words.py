"""What a user reads: summaries, messages that name the file and the option."""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest

import holoradar as hr


def test_a_hologram_prints_as_a_summary_not_its_samples():
    x = np.arange(200) * 0.003
    h = hr.Hologram(np.zeros((3, 200, 200)), x, x, [9e9, 10e9, 11e9], monostatic=True)
    text = repr(h)
    assert text.count("\n") == 0 and len(text) < 200
    for part in ("(3, 200, 200)", "9 to 11 GHz", "scanned transceiver", "0.3 x 0.3 cm"):
        assert part in text


def test_hr_io_needs_no_import_of_its_own():
    out = subprocess.run([sys.executable, "-c", "import holoradar as hr; "
                          "print(hr.io.read_history.__name__)"],
                         capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "read_history"


def test_a_file_with_nan_names_the_file_and_the_element(tmp_path):
    import xarray as xr

    x = np.arange(8) * 0.01
    p = hr.save(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9), tmp_path / "a.nc")
    with xr.open_dataset(p, engine="h5netcdf") as ds:
        ds = ds.load()
    arr = ds["hologram"].values.copy()
    arr.flat[5] = np.nan
    ds["hologram"].values = arr
    ds.to_netcdf(tmp_path / "b.nc", engine="h5netcdf")
    with pytest.raises(ValueError, match=r"b\.nc: data must be finite: 1 of 64 values .* index"):
        hr.load(tmp_path / "b.nc")


def test_the_noise_warning_names_the_command_lines_option():
    from holoradar.imaging.inversion.noise import NoiseWarning, noise_std

    x = (np.arange(16) - 7.5) * 0.025      # 2.5 cm: not below half a wavelength
    h = hr.Hologram(np.ones((16, 16)), x, x, 9.9e9)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        noise_std(h, 0.3, None)
    assert any(issubclass(w.category, NoiseWarning) and "--noise" in str(w.message)
               for w in said)


def test_a_reflectivity_is_labelled_as_such():
    from holoradar.app import plotting

    x = np.arange(4) * 0.01
    refl = hr.Image(np.ones((2, 4, 4)), x, x, np.array([0.2, 0.3]), 9.9e9, "invert:lsqr")
    field = hr.Image(np.ones((2, 4, 4)), x, x, np.array([0.2, 0.3]), 9.9e9, "angular")
    labels = [plotting.plot_planes(img, [0.2]).axes[-1].get_ylabel() for img in (refl, field)]
    assert labels[0].startswith("|reflectivity|") and labels[1].startswith("|E|")


def test_a_hologram_loaded_and_saved_again_keeps_its_steps(tmp_path):
    x = np.arange(8) * 0.01
    first = hr.save(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9), tmp_path / "a.nc",
                    history=[{"step": "simulate", "parameters": {"scene": "test"}}])
    again = hr.save(hr.load(first), tmp_path / "b.nc")
    assert [s["step"] for s in hr.io.read_history(again)] == ["simulate", "save", "save"]


def test_info_names_the_solvers_step_and_batch_says_no_zarr_spec_note(tmp_path):
    from cli_helpers import run

    sc = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))], source=hr.PlaneWave())
    h = hr.simulate(sc, hr.Aperture.grid(16, 0.0125), 9.9e9, snr_db=30, seed=1)
    p = hr.save(h, tmp_path / "p.nc")
    run("invert", p, "--z", "0.25:0.35:0.05", "-o", tmp_path / "r.nc")
    out = run("info", tmp_path / "r.nc").output
    assert "history: None" not in out and "history: invert" in out
    x = (np.arange(8) - 3.5) * 0.01
    frames = [hr.save(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9,
                                  pose=hr.Pose((0.05 * i, 0.0, 0.0))), tmp_path / f"f{i}.nc")
              for i in range(2)]
    res = run("batch", *frames, "-o", tmp_path / "s.zarr", "--z", "0.1:0.2:0.05")
    assert "ZarrUserWarning" not in res.output
