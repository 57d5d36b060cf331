"""Files: save and load holograms and images (NetCDF-4).

``save(obj, path)`` writes a :class:`~holoradar.Hologram` or
:class:`~holoradar.Image` to ``path`` (``.nc``), refusing to overwrite an
existing file unless ``overwrite=True``, checking the folder first and writing
atomically (a temporary file beside it, renamed) with the user's umask.
``load(path)`` gives the object back, equal to what was saved. The layout is
described in :mod:`holoradar.io.netcdf`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..data.hologram import Hologram, Image
from .netcdf import from_dataset, read_history, to_dataset
from .output import check_output, write_via_temp

__all__ = ["load", "read_history", "save"]

NETCDF_SUFFIXES = (".nc", ".nc4")


def save(obj: Hologram | Image, path: str | os.PathLike[str], *, overwrite: bool = False,
         history: list[dict[str, Any]] | None = None) -> Path:
    """Write a Hologram or Image to a NetCDF-4 file.

    Parameters
    ----------
    obj : Hologram or Image
    path : str or path-like
        Output file, ending in ``.nc`` (or ``.nc4``); its folder must exist.
    overwrite : bool
        Replace an existing file (default False: an existing file is an error).
    history : list of dict, optional
        Processing steps that led to ``obj`` (each with ``step``, ``parameters``,
        ...); a ``save`` step is appended.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ValueError
        Not a Hologram or Image, wrong suffix, missing folder, existing file.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> import holoradar as hr
    >>> h = hr.Hologram(np.ones((2, 3)), [0.0, 0.01, 0.02], [0.0, 0.01], 9.9e9)
    >>> p = save(h, pathlib.Path(tempfile.mkdtemp()) / "h.nc")
    >>> bool(np.array_equal(load(p).data, h.data))
    True
    """
    if not isinstance(obj, Hologram | Image):
        raise ValueError(f"obj must be a holoradar.Hologram or holoradar.Image, got "
                         f"{type(obj).__name__}")
    target = check_output(path, suffixes=NETCDF_SUFFIXES, overwrite=overwrite)
    ds = to_dataset(obj, history)

    def write(tmp: Path) -> None:
        ds.to_netcdf(tmp, engine="h5netcdf", invalid_netcdf=False)

    return write_via_temp(target, write)


def load(path: str | os.PathLike[str]) -> Hologram | Image:
    """Read a Hologram or Image saved by :func:`save`.

    Raises
    ------
    ValueError
        The file is missing, empty, truncated, not NetCDF-4/HDF5, or not a holoradar
        file (the message lists what it holds).

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> import holoradar as hr
    >>> img = hr.Image(np.zeros((2, 3)), np.arange(3.0), np.arange(2.0), np.array([0.4]),
    ...                9.9e9, has_z_axis=False)
    >>> p = save(img, pathlib.Path(tempfile.mkdtemp()) / "i.nc")
    >>> load(p).data.shape
    (2, 3)
    """
    import xarray as xr

    src = Path(path)
    if not src.is_file():
        raise ValueError(f"path {str(src)!r} is not a file")
    if src.stat().st_size == 0:
        raise ValueError(f"path {str(src)!r} is empty")
    try:
        with xr.open_dataset(src, engine="h5netcdf") as ds:
            ds.load()
            return from_dataset(ds, what=str(src))
    except ValueError:
        raise
    except Exception as exc:  # a damaged file can fail in the HDF5 layer in many ways
        raise ValueError(f"path {str(src)!r} is not a readable NetCDF-4/HDF5 file "
                         f"({type(exc).__name__}: {exc})") from None
