"""Which backend computes a plan: the one asked for, or the first that applies.

``algorithm="auto"`` tries, in order of expected speed, the backends that compute
the same operator (to rounding) and takes the first whose :meth:`~.backend.Backend.refuses`
answers None: for a band of uniform planes the compiled column sum, then its NumPy
twin, then plane by plane; for one frequency, plane by plane with the transfer
functions cached, or the phase step from plane to plane when they would not fit in
the cache; for ``frame="ground"`` the finufft sum where the measured costs favour
it, else the direct one. ``"stolt"`` (an approximation) is taken only when asked.
A backend asked for by name that refuses raises a ``ValueError`` with its reason.
A hologram with a transmitter beside the receiver (``tx_offset``) has one backend,
``"offset"``, whose two-leg kernel no other backend models.
"""

from __future__ import annotations

import math

from ...physics.propagation import transfer_cache_bytes
from .backends.base import Backend
from .backends.ground import GroundDirect, GroundNufft
from .backends.offset import Offset
from .backends.phase_shift import Columns, PhaseShift, Stolt
from .backends.planes import FresnelPlanes, PlaneByPlane
from .plan import MigrationPlan

__all__ = ["BACKENDS", "choose"]

#: Every backend by name.
BACKENDS: dict[str, Backend] = {b.name: b for b in (
    PlaneByPlane(), FresnelPlanes(), PhaseShift(), Columns(), Stolt(), GroundDirect(),
    GroundNufft(), Offset())}


def choose(plan: MigrationPlan) -> Backend:
    """The backend that computes ``plan`` (see the module docstring).

    Raises
    ------
    ValueError
        The backend named by ``plan.settings.algorithm`` cannot compute it: the message
        says what it needs.
    """
    name = plan.settings.algorithm
    if plan.geometry.tx_offset is not None:
        offset = BACKENDS["offset"]
        if name not in ("auto", "frequency", "offset"):
            raise ValueError(f"algorithm={name!r} does not model a transmitter beside the "
                             "receiver (hologram.tx_offset): use 'auto' (or 'offset')")
        why = offset.refuses(plan)
        if why is not None:
            raise ValueError(f"a hologram with tx_offset is imaged by its two-leg kernel, "
                             f"which needs {why}")
        return offset
    if name == "auto":
        candidates = _preferences(plan)
    elif name == "frequency":
        # Plane by plane, whatever the frame or kernel: no phase-step shortcut.
        candidates = [BACKENDS["fresnel"], *_ground(plan), BACKENDS["frequency"]]
    else:
        backend = BACKENDS[name]
        why = backend.refuses(plan)
        if why is not None:
            raise ValueError(f"algorithm={name!r} needs {why}; use 'auto'")
        return backend
    for backend in candidates:
        if backend.refuses(plan) is None:
            return backend
    reasons = "; ".join(f"{b.name}: {b.refuses(plan)}" for b in candidates)
    raise ValueError(f"no migration backend applies to these settings ({reasons})")


def _preferences(plan: MigrationPlan) -> list[Backend]:
    if plan.settings.frame == "ground":
        return _ground(plan)
    if plan.settings.method == "fresnel":
        return [BACKENDS["fresnel"]]
    if plan.wideband:
        return [BACKENDS["columns"], BACKENDS["kspace"], BACKENDS["frequency"]]
    # (one plane: nothing to step to)
    step = [BACKENDS["kspace"]] if plan.z.size > 1 and _too_big_to_cache(plan) else []
    return [*step, BACKENDS["frequency"]]


def _ground(plan: MigrationPlan) -> list[Backend]:
    if plan.settings.frame != "ground":
        return []
    nufft = BACKENDS["ground-nufft"]
    assert isinstance(nufft, GroundNufft)
    fast = nufft.refuses(plan) is None and nufft.prefer(plan)
    return [nufft, BACKENDS["ground-direct"]] if fast else [BACKENDS["ground-direct"]]


def _too_big_to_cache(plan: MigrationPlan) -> bool:
    """True when the planes' transfer functions would not fit in the transfer cache:
    one transfer and a phase step per plane then spare building one per plane on
    every call."""
    planes = BACKENDS["frequency"]
    assert isinstance(planes, PlaneByPlane)
    grid = planes.propagator(plan, 0).fft_shape
    return plan.z.size * math.prod(grid) * plan.work.itemsize > transfer_cache_bytes() // 2
