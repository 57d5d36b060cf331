"""The migration operator: one linear map per measurement geometry, its backends.

A :class:`~.settings.MigrationSettings` and a hologram's geometry make a
:class:`~.plan.MigrationPlan` (:func:`~.plan.make_plan`, what depends on the data
computed once); :func:`~.choose.choose` picks the :class:`~.backend.Backend` that
computes it (plane by plane, the phase-shift sum in NumPy or compiled, Stolt's
resampling, the Fresnel kernel, the tilted ground frame by direct sums or finufft),
each with a forward map and its exact adjoint. :func:`holoradar.migrate` is the
adjoint applied to the data (:func:`~.image.image_of`);
:func:`~.linear.migration_operator` wraps the pair as a
``scipy.sparse.linalg.LinearOperator`` for solvers. See docs/imaging.md.
"""

from .settings import MigrationSettings

__all__ = ["MigrationSettings"]
