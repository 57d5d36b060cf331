"""Shape checks shared by the calibration steps."""

from __future__ import annotations

from typing import Any

import numpy as np


def complex_field(values: Any, name: str, *, ndim: tuple[int, ...] = (2, 3)) -> np.ndarray:
    """A finite complex array of shape (ny, nx) or (nf, ny, nx) (or as ``ndim`` says)."""
    arr = np.asarray(values)
    if not np.issubdtype(arr.dtype, np.number):
        raise ValueError(f"{name} must be a numeric array, got dtype {arr.dtype}")
    arr = arr.astype(complex)
    if arr.ndim not in ndim:
        raise ValueError(f"{name} must have {' or '.join(map(str, ndim))} dimensions, got "
                         f"shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite")
    return arr


def same_shape(a: np.ndarray, b: np.ndarray, names: str) -> None:
    if a.shape != b.shape:
        raise ValueError(f"{names} must have one shape, got {a.shape} and {b.shape}")


def element_mask(mask: Any, shape: tuple[int, int]) -> np.ndarray:
    """A boolean (ny, nx) mask of bad elements (all good if None)."""
    if mask is None:
        return np.zeros(shape, bool)
    m = np.asarray(mask)
    if m.dtype != bool or m.shape != shape:
        raise ValueError(f"mask must be a boolean array of shape {shape} (True = bad element), "
                         f"got dtype {m.dtype} and shape {m.shape}")
    if m.all():
        raise ValueError("mask flags every element: nothing is left to calibrate")
    return m
