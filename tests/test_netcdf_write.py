"""The NetCDF file ``holoradar.save`` writes through h5netcdf directly is the one xarray
writes of the same content: read back by xarray (an independent reader), every
variable, dimension, coordinate and attribute agrees with ``to_dataset``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr

import holoradar as hr
from holoradar.io.netcdf import to_dataset


def _objects() -> dict[str, object]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))], source=hr.PlaneWave())
        one = hr.simulate(sc, hr.Aperture.grid(8, 0.01), 9.9e9)
        wide = hr.simulate(sc, hr.Aperture.grid(8, 0.01), [9e9, 10e9])
        frames = one.with_data(np.stack([one.data, 2 * one.data]))
        return {
            "one": one, "wide": wide, "frames": frames,
            "plane": hr.migrate(one, 0.3),
            "sweep": hr.migrate(wide, np.linspace(0.2, 0.4, 5)),
            "real": hr.Image(np.abs(hr.migrate(one, 0.3).data), one.x, one.y,
                             np.array([0.3]), 9.9e9, has_z_axis=False),
        }


@pytest.mark.parametrize("name", list(_objects()))
def test_direct_file_reads_in_xarray_as_to_dataset(tmp_path, name):
    obj = _objects()[name]
    path = hr.save(obj, tmp_path / f"{name}.nc")
    want = to_dataset(obj)
    with xr.open_dataset(path, engine="h5netcdf") as got:
        got = got.load()
    # the clock of the history's steps may tick between the two
    for ds in (want, got):
        ds.attrs.pop("history")
    xr.testing.assert_identical(got, want)
    assert set(got.dims) == set(want.dims)
    back = hr.load(path)
    np.testing.assert_array_equal(back.data, obj.data)
    assert type(back) is type(obj)


def test_a_file_without_fill_values_on_coordinates(tmp_path):
    # CF: coordinate variables hold no missing values; xarray's own writer marks every
    # float with _FillValue = NaN, this one does not.
    import h5netcdf

    path = hr.save(_objects()["sweep"], tmp_path / "s.nc")
    with h5netcdf.File(path, "r") as f:
        assert all("_FillValue" not in f.variables[c].attrs for c in ("x", "y", "z"))
        assert f.variables["image"].dimensions == ("z", "y", "x", "iq")
