"""Reflectivity by inversion of the migration operator: :func:`invert`.

:mod:`.noise` (the receiver noise a solver stops at), :mod:`.columns` (how strongly
each voxel reaches the data), :mod:`.solvers` (damped least squares stopped at the
noise; L1-sparse with the noise's threshold), :mod:`.api` (``invert``).
See docs/inversion.md.
"""

from .api import invert
from .noise import NoiseWarning

__all__ = ["NoiseWarning", "invert"]
