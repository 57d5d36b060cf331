"""Reading a survey store: the whole of it as an xarray Dataset, or one frame's Image."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..data.hologram import Image
from .store import read_images, read_index

__all__ = ["frame_image", "open_survey"]


def open_survey(store: str | os.PathLike[str]) -> Any:
    """Open a survey store (:func:`~holoradar.survey.run_batch`) as an ``xarray.Dataset``.

    Parameters
    ----------
    store : path
        The ``.zarr`` store.

    Returns
    -------
    xarray.Dataset
        ``image`` (frame, z, y, x, iq), lazy (Dask), I at ``iq = 0`` and Q at
        ``iq = 1``, NaN for frames not done; coordinates ``z`` (m, range from
        the aperture), ``y``, ``x`` (m, pixel offsets from the frame's centre),
        and per frame ``frame_name``, ``frame_path``, ``frame_x``, ``frame_y``,
        ``frame_z`` (m, world position of its centre), ``finished`` (s since
        1970 UTC) and ``done``; attributes ``settings`` and ``geometry``. A
        frame's world pixel is ``(frame_x + x, frame_y + y)``. Readable while a
        run is writing, or after one was killed.

    Raises
    ------
    ValueError
        ``store`` is not a survey store.

    Examples
    --------
    >>> import pathlib, tempfile, numpy as np
    >>> import holoradar as hr
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> x = (np.arange(8) - 3.5) * 0.01
    >>> p = hr.save(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9), d / "f.nc")
    >>> _ = hr.survey.run_batch([p], d / "s.zarr", z=0.2, scheduler="synchronous")
    >>> ds = open_survey(d / "s.zarr")
    >>> dict(ds["image"].sizes), bool(ds["done"][0])
    ({'frame': 1, 'z': 1, 'y': 8, 'x': 8, 'iq': 2}, True)
    """
    import dask.array as da
    import xarray as xr

    idx = read_index(Path(store))
    n = idx["n"]
    arr = idx["group"]["image"]
    image = da.from_array(_Checked(arr, str(store)), chunks=(arr.chunks[0], *arr.shape[1:]),
                          name=False, asarray=True, fancy=False)[:n]
    per_frame = {k: ("frame", idx[k]) for k in ("frame_x", "frame_y", "frame_z", "finished")}
    coords: dict[str, Any] = {
        "z": ("z", idx["z"], {"units": "m", "long_name": "range of the plane from the aperture"}),
        "y": ("y", idx["y"], {"units": "m", "long_name": "pixel y offset from the frame centre"}),
        "x": ("x", idx["x"], {"units": "m", "long_name": "pixel x offset from the frame centre"}),
        "frame_name": ("frame", idx["frame_name"].astype(str)),
        "frame_path": ("frame", idx["frame_path"].astype(str)),
        **per_frame,
    }
    ds = xr.Dataset({"image": (("frame", "z", "y", "x", "iq"), image,
                               {"long_name": "reconstructed field, I (iq = 0), Q (iq = 1)"}),
                     "done": ("frame", idx["done"])}, coords=coords, attrs=idx["attrs"])
    for k in ("frame_x", "frame_y", "frame_z"):
        ds[k].attrs["units"] = "m"
    ds["finished"].attrs["units"] = "seconds since 1970-01-01 00:00:00"
    return ds


class _Checked:
    """A store's image array whose read errors are a ``ValueError`` naming the store.

    A damaged chunk (a flipped bit in a compressed chunk, a truncated file) makes the
    codecs raise their own errors (``RuntimeError`` from Blosc...) when the lazy
    dataset is computed, far from :func:`open_survey`.
    """

    def __init__(self, arr: Any, store: str) -> None:
        self.arr, self.store = arr, store
        self.shape, self.dtype, self.ndim = arr.shape, arr.dtype, arr.ndim

    def __getitem__(self, key: Any) -> np.ndarray:
        try:
            return np.asarray(self.arr[key])
        except ValueError:
            raise
        except Exception as exc:  # zarr, numcodecs and the file system fail in many ways
            raise ValueError(f"store {self.store!r} is damaged or unreadable "
                             f"({type(exc).__name__}: {exc})") from None


def frame_image(store: str | os.PathLike[str], frame: int | str) -> Image:
    """One frame's complex image, on world pixel coordinates.

    Parameters
    ----------
    store : path
        The ``.zarr`` store.
    frame : int or str
        The frame's index in the store, or its file name, or its path.

    Returns
    -------
    Image
        ``data`` (nz, ny', nx'), the exact result of migrating the frame; ``x``,
        ``y`` world coordinates in metres (``frame_x`` + offsets), ``z`` the
        planes' ranges.

    Raises
    ------
    ValueError
        No such frame, or it is not done.

    Examples
    --------
    >>> import pathlib, tempfile, numpy as np
    >>> import holoradar as hr
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> x = (np.arange(8) - 3.5) * 0.01
    >>> h = hr.Hologram(np.ones((8, 8)), x, x, 9.9e9, pose=hr.Pose((1.0, 2.0, 0.0)))
    >>> p = hr.save(h, d / "f.nc")
    >>> _ = hr.survey.run_batch([p], d / "s.zarr", z=0.2, scheduler="synchronous")
    >>> img = frame_image(d / "s.zarr", "f.nc")
    >>> bool(np.array_equal(img.data, hr.migrate(h, [0.2], dtype=np.complex128).data))
    True
    >>> round(float(img.x[0]), 3)
    0.965
    """
    idx = read_index(Path(store))
    names, paths = list(idx["frame_name"]), list(idx["frame_path"])
    if isinstance(frame, int | np.integer) and not isinstance(frame, bool):
        i = int(frame)
        if not 0 <= i < idx["n"]:
            raise ValueError(f"frame index {i} is out of range: the store holds {idx['n']}")
    else:
        key = str(frame)
        hits = [j for j in range(idx["n"]) if key in (names[j], paths[j])
                or (Path(key).exists() and str(Path(key).resolve()) == paths[j])]
        if not hits:
            raise ValueError(f"frame {key!r} is not in the store")
        i = hits[0]
    if not idx["done"][i]:
        raise ValueError(f"frame {i} ({names[i]}) is not done (skipped, or its run was cut "
                         "short): run the batch again to finish it")
    geo = idx["attrs"]["geometry"]
    f = np.asarray(geo["frequency_hz"], float)
    freq: Any = f if geo["wideband"] else float(f[0])
    return Image(read_images(idx, [i])[0], idx["frame_x"][i] + idx["x"],
                 idx["frame_y"][i] + idx["y"], idx["z"].copy(), freq,
                 str(idx["attrs"]["settings"]["method"]), has_z_axis=True)
