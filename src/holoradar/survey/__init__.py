"""Surveys: many frames imaged with the same settings, stored together, mapped.

A survey is a set of hologram files (frames) recorded along a path. Three steps:

* :func:`run_batch` images every frame with the same settings (in this process,
  on a local cluster of worker processes, or on a ``dask.distributed`` cluster)
  into one Zarr store, each frame with its world position; it skips (or,
  strict, stops at) frames it cannot read, remembers them, and a rerun resumes
  where a run stopped;
* :func:`open_survey` opens the store as an ``xarray.Dataset``;
  :func:`frame_image` gives one frame's complex image; :func:`describe_store`
  says what a store holds (frames stored and missing, planes, settings);
* :func:`mosaic` blends the frames into one plan-view map at a chosen depth.

See docs/surveys.md. Importing this package loads neither Dask nor Zarr; they
are imported when used.
"""

from .batch import BatchInterrupted, SettingsMismatchError, run_batch
from .frames import FrameGeometry, frame_position
from .mosaic import mosaic
from .reader import frame_image, open_survey
from .settings import Settings
from .store import describe_store

__all__ = ["BatchInterrupted", "FrameGeometry", "Settings", "SettingsMismatchError",
           "describe_store", "frame_image", "frame_position", "mosaic", "open_survey",
           "run_batch"]
