"""PyLops's FISTA at one ``matvec`` and one ``rmatvec`` a step.

PyLops's :class:`~pylops.optimization.cls_sparsity.FISTA` computes, each step, the
operator on the extrapolated point ``z`` (for the gradient) and again on the new
iterate ``x`` (for its cost): two forward maps and one adjoint. By linearity the
first follows from the second: with ``z = x + b (x - x_old)``,
``Op z = Op x + b (Op x - Op x_old)``, so keeping ``Op x`` makes a step one forward
and one adjoint map, the floor of any gradient method. The step is otherwise
PyLops's: its soft threshold (at ``eps alpha / 2``, its objective
``|y - Op x|^2 + eps |x|_1``; computed as ``x max(1 - t / |x|, 0)``), its momentum and
its update norm; its cost only when shown (a norm of each vector a step).
"""

from __future__ import annotations

from math import sqrt
from typing import Any

import numpy as np
from pylops.optimization.cls_sparsity import FISTA

__all__ = ["OnePairFISTA"]


class OnePairFISTA(FISTA):
    """:class:`pylops.optimization.cls_sparsity.FISTA` with ``Op x`` kept between steps
    (soft thresholding, no ``SOp``, no percentile thresholds).

    Examples
    --------
    >>> import numpy as np, pylops
    >>> rng = np.random.default_rng(0)
    >>> Op = pylops.MatrixMult(rng.standard_normal((40, 60)))
    >>> x0 = np.zeros(60); x0[[5, 30]] = (1.0, -2.0)
    >>> y = Op @ x0
    >>> ref = FISTA(Op); mine = OnePairFISTA(Op)
    >>> a = ref.solve(y, niter=50, eps=0.1, alpha=1e-3, tol=0)[0]
    >>> b = mine.solve(y, niter=50, eps=0.1, alpha=1e-3, tol=0)[0]
    >>> bool(np.allclose(a, b))
    True
    """

    def setup(self, y: np.ndarray, x0: np.ndarray | None = None, *args: Any,
              **kwargs: Any) -> np.ndarray:
        x = super().setup(y, x0, *args, **kwargs)
        if self.SOp is not None or self.perc is not None or self.preallocate:
            raise ValueError("OnePairFISTA: soft thresholding of the model itself only "
                             "(no SOp, perc or preallocate)")
        self._Ax = self.Opmatvec(x) if np.any(x) else np.zeros_like(y)
        self._Az = self._Ax
        return x

    def step(self, x: np.ndarray, z: np.ndarray, show: bool = False
             ) -> tuple[np.ndarray, np.ndarray, float]:
        Axold = self._Ax
        x_unthresh = z + self.alpha * self.Oprmatvec(self.y - self._Az)
        decay = self.decay if isinstance(self.decay, int | float) else self.decay[self.iiter]
        xnew = _soft(x_unthresh, decay * self.thresh)
        Ax = self.Opmatvec(xnew)
        told = self.t
        self.t = (1.0 + sqrt(1.0 + 4.0 * self.t**2)) / 2.0
        b = (told - 1.0) / self.t
        dx = xnew - x
        z = xnew + b * dx
        self._Az = Ax + b * (Ax - Axold)
        self._Ax = Ax
        xupdate = float(np.linalg.norm(dx))
        self.iiter += 1
        if show:
            costdata = 0.5 * float(np.linalg.norm(self.y - Ax)) ** 2
            costreg = self.eps * float(np.linalg.norm(xnew, ord=1))
            self.cost.append(costdata + costreg)
            self._print_step(xnew, costdata, costreg, xupdate)
        return xnew, z, xupdate


def _soft(x: np.ndarray, t: float) -> np.ndarray:
    """PyLops's soft threshold, ``max(|x| - t, 0) x / |x|`` (complex: the phase kept),
    without its exponential of the angle."""
    m = np.abs(x)
    scale = np.maximum(1.0 - t / np.maximum(m, 1e-300), 0.0)
    return x * scale.astype(m.dtype, copy=False)
