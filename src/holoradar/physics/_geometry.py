"""Small geometric helpers of the source models.

``_points`` checks and shapes the (N, 3) points the sources' fields are asked at;
it lives here, not in :mod:`.sources`, so that the source modules need not import
the module that re-exports them.
"""

from __future__ import annotations

import numpy as np


def _points(points: np.ndarray) -> np.ndarray:
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (N, 3) (x, y, z in metres), got {pts.shape}")
    return pts
