"""Write a holoradar NetCDF-4 file through h5netcdf directly, without xarray.

The file is the one ``xarray.Dataset.to_netcdf(engine="h5netcdf")`` writes of
:func:`holoradar.io.netcdf.to_dataset` (the same dimensions, variables, attributes
and ``coordinates`` attribute naming the scalar coordinates), less xarray's
``_FillValue = NaN`` on every float variable: holoradar's values are never
missing, and CF asks coordinate variables to have no missing values at all.

Why not xarray: in a fresh process its import (pandas) and its array checks (which
import dask and dask.distributed whenever dask is installed) cost 0.6-1.2 s, ten
times the write of a 100 MB image (see ``benchmarks/bench_defaults.py``).
Reading stays with xarray where it must (a foreign file) and h5py where it may.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from .netcdf import NetcdfContent

__all__ = ["write_content"]


def _attribute(value: Any) -> Any:
    """A value as an HDF5 attribute NetCDF reads: text as UTF-8, whole numbers as
    64-bit integers, arrays as they are."""
    if isinstance(value, bool | np.bool_):
        return np.int64(int(value))
    if isinstance(value, int) and not isinstance(value, bool):
        return np.int64(value)
    if isinstance(value, float):
        return np.float64(value)
    return value


def write_content(path: str | os.PathLike[str], c: NetcdfContent) -> None:
    """Write ``c`` to a new NetCDF-4 file at ``path`` (replaced if there).

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from holoradar import Hologram, load
    >>> from holoradar.io.netcdf import content
    >>> h = Hologram(np.ones((2, 3)), [0.0, 0.01, 0.02], [0.0, 0.01], 9.9e9)
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "h.nc"
    >>> write_content(p, content(h))
    >>> bool(np.array_equal(load(p).data, h.data))
    True
    """
    import h5netcdf

    sizes: dict[str, int] = {}
    for v in (*c.coords.values(), c.data):
        for d, n in zip(v.dims, v.values.shape, strict=True):
            if sizes.setdefault(d, n) != n:
                raise ValueError(f"dimension {d!r} has sizes {sizes[d]} and {n}")
    with h5netcdf.File(path, "w", invalid_netcdf=False) as f:
        f.dimensions = sizes
        # Coordinates first (NetCDF readers expect a dimension's variable to exist
        # before a variable uses the dimension), then the data.
        for name, v in c.coords.items():
            var = f.create_variable(name, v.dims, v.values.dtype, data=v.values)
            for k, a in v.attrs.items():
                var.attrs[k] = _attribute(a)
        var = f.create_variable(c.name, c.data.dims, c.data.values.dtype, data=c.data.values)
        for k, a in c.data.attrs.items():
            var.attrs[k] = _attribute(a)
        scalars = [name for name, v in c.coords.items() if not v.dims]
        if scalars:
            # CF: a scalar coordinate is named in the data variable's "coordinates".
            var.attrs["coordinates"] = " ".join(scalars)
        for k, a in c.attrs.items():
            f.attrs[k] = _attribute(a)
