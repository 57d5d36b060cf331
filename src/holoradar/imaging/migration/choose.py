"""Which backend computes a plan: the one asked for, or the first that applies.

``algorithm="auto"`` tries, in order of expected speed, the backends that compute
the same operator (to rounding) and takes the first whose :meth:`~.backend.Backend.refuses`
answers None: for a band of uniform planes the compiled column sum, then its NumPy
twin, then plane by plane (the NumPy twin first while the compiled loop is not yet
loaded in this process and the work is smaller than what loading it costs:
:func:`compiled_pays`); for one frequency, plane by plane with the transfer
functions cached, or the phase step from plane to plane when they would not fit in
the cache; for ``frame="ground"`` the finufft sum where the measured costs favour
it, else the direct one. ``"stolt"`` (an approximation) is taken only when asked.
A backend asked for by name that refuses raises a ``ValueError`` with its reason.
A hologram with a transmitter beside the receiver (``tx_offset``) has one backend,
``"offset"``, whose two-leg kernel no other backend models.
"""

from __future__ import annotations

import math
import threading

from ...physics.propagation import transfer_cache_bytes
from .backends.base import Backend
from .backends.ground import GroundDirect, GroundNufft
from .backends.offset import Offset
from .backends.phase_shift import Columns, PhaseShift, Stolt
from .backends.planes import FresnelPlanes, PlaneByPlane
from .backends.terms import band_grid
from .plan import MigrationPlan

__all__ = ["BACKENDS", "COLD_LOAD_WORK", "choose", "compiled_pays"]

#: Complex multiply-adds of the NumPy phase-shift sum that take as long as loading the
#: compiled loop in a fresh process: numba's import and its on-disk cache, 0.35-0.45 s
#: on the 2-core machine, where the NumPy sum runs ~1e9 multiply-adds a second and the
#: compiled one 4-5 times faster (``benchmarks/bench_defaults.py``).
COLD_LOAD_WORK = 4e8

_NUMPY_WORK = [0.0]   # multiply-adds this process has run through the NumPy sum so far
_LOCK = threading.Lock()

#: Every backend by name.
BACKENDS: dict[str, Backend] = {b.name: b for b in (
    PlaneByPlane(), FresnelPlanes(), PhaseShift(), Columns(), Stolt(), GroundDirect(),
    GroundNufft(), Offset())}


def choose(plan: MigrationPlan, *, repeated: bool = False) -> Backend:
    """The backend that computes ``plan`` (see the module docstring). ``repeated``: the
    plan is an operator's, to be applied many times (a solver's steps): a band takes
    the compiled sum whether or not it is loaded yet.

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
        candidates = _preferences(plan, repeated)
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


def _preferences(plan: MigrationPlan, repeated: bool = False) -> list[Backend]:
    if plan.settings.frame == "ground":
        return _ground(plan)
    if plan.settings.method == "fresnel":
        return [BACKENDS["fresnel"]]
    if plan.wideband:
        sums = [BACKENDS["columns"], BACKENDS["kspace"]]
        fast = repeated or compiled_pays(plan)
        return [*(sums if fast else sums[::-1]), BACKENDS["frequency"]]
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


def compiled_pays(plan: MigrationPlan) -> bool:
    """Whether the compiled column sum is worth taking for ``plan``: it is loaded
    already (an earlier call, :func:`~.backends.columns.warm`), or this call's work
    together with what the process has summed in NumPy so far passes
    :data:`COLD_LOAD_WORK`. A single small migration in a fresh process (the command
    line on one scan) is then not charged the load; a process that migrates many
    loads it once the NumPy sums have cost as much.
    """
    from .backends import columns

    if columns.loaded():
        return True
    zs = plan.z
    grid = band_grid(plan.grid, plan.geometry.pitch, plan.wavenumbers, plan.geometry.monostatic,
                     plan.pad, float(zs.max()))
    work = float(plan.nf) * math.prod(grid) * zs.size
    with _LOCK:
        if _NUMPY_WORK[0] + work > COLD_LOAD_WORK:
            return True
        _NUMPY_WORK[0] += work
    return False
