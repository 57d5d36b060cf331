"""Values made plain for JSON: NumPy scalars and arrays as Python numbers and lists,
complex numbers as ``{"re", "im"}``, paths as text, NaN and infinities as null."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["plain"]


def plain(v: Any) -> Any:
    """``v`` (dicts, lists and tuples walked through) in values ``json.dumps`` writes as
    strict JSON.

    Examples
    --------
    >>> plain({"a": np.float64(0.5), "b": (1, float("nan")), "c": 2 + 1j})
    {'a': 0.5, 'b': [1, None], 'c': {'re': 2.0, 'im': 1.0}}
    """
    if isinstance(v, dict):
        return {str(k): plain(e) for k, e in v.items()}
    if isinstance(v, list | tuple):
        return [plain(e) for e in v]
    if isinstance(v, np.ndarray):
        return plain(v.tolist())
    if isinstance(v, complex | np.complexfloating):
        return {"re": float(v.real), "im": float(v.imag)}
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, Path):
        return str(v)
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v
