"""The interface every migration backend implements.

A backend computes one linear map and its exact adjoint for a
:class:`~.plan.MigrationPlan`:

* :meth:`Backend.forward` (``matvec``): a reflectivity on the image grid, ``(B, nz,
  oy, ox)`` (``(B, nf, nz, oy, ox)`` when each frequency keeps its own image), to the
  hologram's samples ``(B, nf, ny, nx)``;
* :meth:`Backend.adjoint` (``rmatvec``): samples to image, the migration.

``B`` counts frames (views, time steps) processed together. :meth:`Backend.refuses`
says, in words, why the backend cannot compute a plan (None when it can);
``algorithm="auto"`` takes the first of its preferences that does not refuse.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from ..plan import MigrationPlan

__all__ = ["Backend", "uniform_planes"]


class Backend(ABC):
    """One way of computing the migration operator (see the module docstring)."""

    name: ClassVar[str]

    @abstractmethod
    def refuses(self, plan: MigrationPlan) -> str | None:
        """Why this backend cannot compute ``plan`` (what it needs), or None."""

    @abstractmethod
    def adjoint(self, plan: MigrationPlan, data: np.ndarray) -> np.ndarray:
        """Samples ``(B, nf, ny, nx)`` -> image ``(B, [nf,] nz, oy, ox)``."""

    @abstractmethod
    def forward(self, plan: MigrationPlan, image: np.ndarray) -> np.ndarray:
        """Image ``(B, [nf,] nz, oy, ox)`` -> samples ``(B, nf, ny, nx)``."""

    @abstractmethod
    def axes(self, plan: MigrationPlan) -> tuple[np.ndarray, np.ndarray]:
        """The image's pixel coordinates ``(x, y)``, metres."""

    def method(self, plan: MigrationPlan) -> str:
        """The ``Image.method`` label of what this backend computes."""
        return plan.settings.method


def uniform_planes(zs: np.ndarray) -> bool:
    """Two or more planes, increasing in equal steps (to 1e-9 relative).

    Examples
    --------
    >>> uniform_planes(np.array([0.1, 0.2, 0.3])), uniform_planes(np.array([0.1, 0.3]))
    (True, True)
    >>> uniform_planes(np.array([0.1, 0.2, 0.4]))
    False
    """
    if zs.size < 2:
        return False
    steps = np.diff(zs)
    return bool(np.allclose(steps, steps[0], rtol=1e-9, atol=0) and steps[0] > 0)
