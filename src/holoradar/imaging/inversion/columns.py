"""How strongly each voxel reaches the data: the operator's column norms.

``c_j^2 = sum_e |A_ej|^2``, the energy a unit reflectivity at voxel j puts into the
samples (the illumination, the aperture's view of it, the spreading), sets how far
noise goes in the reflectivity there (``sigma / c_j``). It is the diagonal of
``A^H A``, which a random data vector ``v`` of unit variance per sample gives in
expectation: ``E |A^H v|_j^2 = c_j^2`` (Hutchinson's estimator, one adjoint per probe).
Each probe's estimate is exponential (relative spread 1); but ``c_j`` varies over the
illumination's and the aperture's scales, much longer than a resolution cell, while
a probe's fluctuations are correlated over one cell only: averaging ``P`` probes and
smoothing each plane over a few cells (a Gaussian of ``SMOOTH_CELLS`` cells) leaves a
relative error of about ``1 / sqrt(P * cells averaged)``, a few percent.
"""

from __future__ import annotations

import numpy as np

from ..._lazy import lazy_module

ndimage = lazy_module("scipy.ndimage")

__all__ = ["PROBES", "SMOOTH_CELLS", "column_norms"]

PROBES = 8
SMOOTH_CELLS = 1.5


def column_norms(A: object, cell_px: float, seed: int = 0) -> np.ndarray:
    """``c_j``, the operator's column norms on its image grid (``A.image_shape``).

    Parameters
    ----------
    A : MigrationOperator
    cell_px : float
        A lateral resolution cell, in pixels (the smoothing's scale).
    seed : int
        The probes' random generator.

    Returns
    -------
    ndarray, float
        Shape ``A.image_shape``, > 0.
    """
    rng = np.random.default_rng(seed)
    M = A.shape[0]
    V = (rng.standard_normal((M, PROBES)) + 1j * rng.standard_normal((M, PROBES))) / np.sqrt(2)
    est = np.mean(np.abs(A.H @ V.astype(A.dtype)) ** 2, axis=1).reshape(A.image_shape)
    sigma = [0.0] * (est.ndim - 2) + [SMOOTH_CELLS * cell_px] * 2
    smooth = ndimage.gaussian_filter(est, sigma, mode="nearest")
    floor = 1e-12 * float(smooth.max(initial=0.0)) or 1e-300
    return np.sqrt(np.maximum(smooth, floor))
