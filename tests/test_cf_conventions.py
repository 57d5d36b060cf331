"""Every kind of NetCDF file holoradar writes passes the CF checker with no error.

``cfchecks`` (cfchecker, the CF community's checker) runs on each file with the
standard name table stored in ``tests/data/cf`` (the machines here are offline). It
needs the UDUNITS-2 library, which ``make test`` installs (Debian's libudunits2-0).
"""

from __future__ import annotations

import gzip
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import holoradar as hr
from holoradar import calibrate as cb

TABLES = Path(__file__).parent / "data" / "cf"


def _cfchecks() -> str:
    exe = Path(sys.executable).with_name("cfchecks")
    if not exe.exists():
        pytest.fail("cfchecks is missing: `make test` installs cfchecker from the test extras")
    probe = subprocess.run([sys.executable, "-c", "import cfunits"], capture_output=True,
                           text=True)
    if probe.returncode != 0:
        pytest.skip("the UDUNITS-2 library is missing (cfunits cannot load it): `make test` "
                    "installs Debian's libudunits2-0 where it may (root); "
                    + probe.stderr.strip().splitlines()[-1])
    return str(exe)


@pytest.fixture(scope="module")
def tables(tmp_path_factory) -> list[str]:
    d = tmp_path_factory.mktemp("cf")
    names = d / "cf-standard-name-table.xml"
    with gzip.open(TABLES / "cf-standard-name-table.xml.gz", "rb") as src, \
            open(names, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return ["-s", str(names), "-a", str(TABLES / "area-type-table.xml"),
            "-r", str(TABLES / "standardized-region-list.xml")]


def _files(d: Path) -> dict[str, Path]:
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))], source=hr.PlaneWave())
        wide = hr.simulate(sc, hr.Aperture.grid(8, 0.01), [9e9, 10e9])
        one = hr.simulate(sc, hr.Aperture.grid(8, 0.01), 9.9e9)
        pol = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))],
                                   source=hr.Dipole((-0.2, 0.0, -0.1), moment=(0, 1, 0))),
                          hr.Aperture.grid(8, 0.01, polarization=(0, 1, 0)), 9.9e9)
        pair = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))]),
                           hr.Aperture.grid(8, 0.01, tx_offset=(0.02, 0, 0)), [9e9, 10e9])
        ground = hr.Medium.half_space(0.1, 4 + 0.1j)
        volume = hr.migrate(wide, [0.2, 0.3])
        plane = hr.migrate(one, 0.3)
        amplitude = hr.Image(np.abs(volume.data), volume.x, volume.y, volume.z,
                             volume.frequency, "mosaic")
        frames = wide.with_data(np.stack([wide.data, wide.data]))
        for name, obj in {"hologram_band": wide, "hologram_one": one,
                          "hologram_polarised": pol, "hologram_pair": pair,
                          "hologram_frames": frames, "image_volume": volume,
                          "image_plane": plane, "image_amplitude": amplitude}.items():
            out[name] = hr.save(obj, d / f"{name}.nc")
        migrated = hr.migrate(wide, [0.2, 0.3], medium=ground)
        out["image_ground"] = hr.save(migrated, d / "image_ground.nc", history=[
            {"step": "migrate", "parameters": {"medium": {
                "z_interfaces": [0.1], "eps": ["(1+0j)", "(4+0.1j)"]}}}])
        cal = cb.Calibration("test device", wide.x, wide.y, 9.9e9, iq_sign="I+iQ",
                             response=[1.0], gains=np.ones((8, 8)))
        out["calibration"] = cal.save(d / "calibration.nc")
    return out


def test_every_file_kind_passes_cfchecks(tmp_path, tables):
    exe = _cfchecks()
    files = _files(tmp_path)
    for name, path in files.items():
        run = subprocess.run([exe, *tables, str(path)], capture_output=True, text=True,
                             timeout=300)
        text = run.stdout + run.stderr
        assert "ERRORS detected: 0" in text and "WARNINGS given: 0" in text, (name, text)


def test_ground_and_source_are_numbers_a_program_reads(tmp_path):
    import xarray as xr

    files = _files(tmp_path)
    with xr.open_dataset(files["image_ground"]) as ds:
        assert ds.attrs["ground"] == "layered"
        assert np.atleast_1d(ds.attrs["ground_z_interfaces_m"]).tolist() == [0.1]
        assert list(ds.attrs["ground_eps_real"]) == [1.0, 4.0]
        assert list(ds.attrs["ground_eps_imag"]) == [0.0, 0.1]
    with xr.open_dataset(files["hologram_band"]) as ds:
        assert ds.attrs["source_type"] == "PlaneWave"
        assert ds["x"].attrs["axis"] == "X" and ds["frequency"].attrs["units"] == "Hz"
        assert ds["iq"].attrs["flag_meanings"] == "in_phase quadrature"
    with xr.open_dataset(files["image_plane"]) as ds:
        # One plane, one frequency: scalar coordinates, no dimension of length one.
        assert ds["z"].ndim == 0 and ds["frequency"].ndim == 0
        assert set(ds.dims) == {"y", "x", "iq"}


def test_files_read_back_alike(tmp_path):
    files = _files(tmp_path)
    for name in ("hologram_one", "image_plane", "image_volume", "hologram_pair"):
        back = hr.load(files[name])
        again = hr.load(hr.save(back, tmp_path / f"again_{name}.nc"))
        assert np.array_equal(back.data, again.data)
        assert np.array_equal(np.atleast_1d(back.frequency), np.atleast_1d(again.frequency))
