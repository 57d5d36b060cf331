"""The migration backends: each computes one linear map and its exact adjoint.

Every backend implements :class:`~.base.Backend` (``refuses(plan)``,
``forward(plan, image)``, ``adjoint(plan, data)``, ``axes(plan)``) and keeps its own
numerics beside it in this folder: plane by plane (:mod:`.planes`: the angular
spectrum and the Fresnel kernel), the phase-shift sum over uniform planes
(:mod:`.phase_shift`, computed by :mod:`.kspace` in NumPy, :mod:`.columns` compiled,
:mod:`.stolt` resampled), the tilted array's ground frame (:mod:`.ground`, through
:mod:`.oblique` and the sums of :mod:`.oblique_sum` / :mod:`.oblique_nufft`) and a
transmitter beside the receiver (:mod:`.offset`). Which one computes a plan is
decided in :mod:`holoradar.imaging.migration.choose`.
"""
