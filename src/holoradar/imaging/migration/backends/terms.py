"""What the phase-shift sum's terms depend on, as one typed, hashable key.

The three backends of uniform planes in the deepest layer (the NumPy recurrence of
:mod:`.kspace`, the compiled sum of :mod:`.columns`, Stolt's resampling of
:mod:`.stolt`) build the same per-frequency terms (:func:`.kspace.frequency_terms`):
a conjugate transfer to the first plane and a step from plane to plane on every
spectral component, and the last plane each takes part in. Those depend on the FFT
grid, the pitch, the band, the planes, the layers, the round trip, the model's
factors (a receiver array's normal plane wave, the point unit, the recorded
polarisation), the working precision, which frequencies carry weight and the
fraction below which a term is dropped: :class:`TermsKey` holds exactly these, so
that one key made from a plan (:meth:`TermsKey.of`) is what the backends are called
with and what their cached plans are filed under. Adding a physical factor is one
field here and its use in ``frequency_terms``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ....physics.medium import Medium
from ....physics.propagation import padded_shape
from .. import units
from ..plan import MigrationPlan

__all__ = ["TINY", "TermsKey", "band_grid", "band_weights"]

#: A term whose weight has fallen below this fraction of its frequency's largest is
#: dropped (zero to rounding in double precision).
TINY = 1e-17


def band_grid(shape: tuple[int, int], pitch: tuple[float, float], ks: np.ndarray, mono: bool,
              pad: Any, z_max: float) -> tuple[int, int]:
    """The FFT grid a band shares: sized for its longest wavelength (half of it for a
    transceiver's round trip) and the deepest plane (:func:`padded_shape`).

    Examples
    --------
    A transceiver at 9.5 GHz (k = 200 rad/m, round-trip wavelength 1.57 cm) over 16 x
    16 elements at 1 cm: twice the size would do for 5 cm, the deepest plane at 30 cm
    needs ``lambda z / dx^2`` = 47 samples (the next fast size, 48):

    >>> band_grid((16, 16), (0.01, 0.01), np.array([200.0]), True, True, 0.05)
    (32, 32)
    >>> band_grid((16, 16), (0.01, 0.01), np.array([200.0]), True, True, 0.3)
    (48, 48)
    """
    lam = (0.5 if mono else 1.0) * 2 * np.pi / float(np.min(ks))
    return padded_shape(shape, pad, pitch=pitch, wavelength=lam, z_max=z_max)


def band_weights(plan: MigrationPlan) -> np.ndarray:
    """The plan's weight per frequency, with a transceiver's point unit folded in.

    The transceiver's point unit ``2 pi i / (2 k n L dA)`` factors into a real weight
    per frequency, ``pi / (k dA)``, and a factor per plane, ``i / (n L)`` (applied by
    the backend to the image).
    """
    g = plan.geometry
    weights = np.asarray(plan.weights, dtype=float)
    if units.is_point(plan) and plan.monostatic:
        weights = weights * np.pi / (plan.wavenumbers * g.pitch[0] * g.pitch[1])
    return weights


@dataclass(frozen=True)
class TermsKey:
    """The phase-shift terms' dependencies (see the module docstring); hashable.

    Attributes
    ----------
    grid : (int, int)
        The padded FFT grid ``(My, Mx)``.
    pitch : (float, float)
        Element pitch ``(dx, dy)``, metres.
    ks : tuple of float
        Wavenumbers in air, rad/m.
    z0, dz : float
        The first plane's range and the planes' step, metres.
    nz : int
        Number of planes.
    medium : Medium
        The layers (the planes all in the deepest).
    mono : bool
        A scanned transceiver's round trip.
    incident : {"none", "phase", "field"}
        A receiver array's normal plane wave factor.
    point_area : float or None
        A receiver array's voxels as point scatterers of that cell, m^2.
    pol : (float, float) or None
        The vector model's recorded component (its x, y): the dipole factor.
    work : numpy.dtype
        The working complex dtype.
    used : tuple of bool
        Which frequencies carry a nonzero weight (the others take part nowhere).
    tiny : float
        The fraction of a frequency's largest term below which a term is dropped.
    """

    grid: tuple[int, int]
    pitch: tuple[float, float]
    ks: tuple[float, ...]
    z0: float
    dz: float
    nz: int
    medium: Medium
    mono: bool
    incident: str
    point_area: float | None
    pol: tuple[float, float] | None
    work: np.dtype
    used: tuple[bool, ...]
    tiny: float = TINY

    @classmethod
    def of(cls, plan: MigrationPlan) -> TermsKey:
        """The key of a plan's terms (uniform planes in the deepest layer)."""
        g = plan.geometry
        zs = plan.z
        ks = tuple(float(k) for k in plan.wavenumbers)
        point = units.is_point(plan)
        pol = units.polarization(plan) if point else None
        grid = band_grid(plan.grid, g.pitch, np.asarray(ks), g.monostatic, plan.pad,
                         float(zs.max()))
        return cls(grid, (float(g.pitch[0]), float(g.pitch[1])), ks, float(zs[0]),
                   float(zs[1] - zs[0]), int(zs.size), plan.local, bool(g.monostatic),
                   "none" if plan.monostatic else plan.illumination,
                   g.pitch[0] * g.pitch[1] if point and not plan.monostatic else None,
                   None if pol is None else (float(pol[0]), float(pol[1])),
                   np.dtype(plan.work), tuple(bool(w != 0) for w in band_weights(plan)))

    def with_tiny(self, tiny: float) -> TermsKey:
        """The same terms with another drop fraction."""
        return self if tiny == self.tiny else replace(self, tiny=float(tiny))

    @property
    def nf(self) -> int:
        return len(self.ks)
