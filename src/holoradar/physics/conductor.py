"""A perfect conductor as the ground (a metal plate): which permittivities stand for one.

A region of permittivity ``|eps| >= CONDUCTOR_EPS`` is taken as a perfect
conductor. As the ground's surface (the first region below the air) it reflects
every plane wave with the tangential electric field reversed, ``R_h = R_v = -1``
(:func:`~holoradar.physics.medium.fresnel`'s convention; the usual magnetic-field
``r_p`` is +1), so the glare is the field of the source's mirror image in closed
form: ``-exp(i*k*R')/R'`` for the scalar model, and for a dipole the image dipole
with its horizontal moment reversed and its vertical one kept
(:func:`~holoradar.physics.green.green_at_distances`,
:func:`~holoradar.physics.dyadic.reflected_dyadic`). The Sommerfeld integrals are
not used there: their quadrature and radial grid are sized by the ground's
largest refractive index, which for ``PEC_EPS`` asked for an exabyte.

Why ``1e20``: above it a half space reflects as a perfect conductor to within the
integrals' own accuracy (1e-9). Its TE coefficient is
``r = (kz0 - kz1)/(kz0 + kz1)``, so ``|1 + r| = 2 kz0/|kz0 + kz1| <= 2/|n|`` for
every wave that travels in the air, 2e-10 at ``|n| = 1e10``; the TM coefficient
departs from -1 only within ``kz0/k < 1/|n|`` of grazing.

A perfect conductor under another layer, or a field inside or beneath one (a
target buried under a metal plate), needs the integrals and is refused by them
with a message instead.
"""

from __future__ import annotations

from typing import Any

__all__ = ["CONDUCTOR_EPS", "PEC_EPS", "is_perfect_conductor", "refuse_perfect_conductor",
           "surface_is_perfect_conductor"]

PEC_EPS = 1e30 + 1e30j
"""Permittivity standing for a perfect conductor (a metal plate): reflection -1 to 2e-15."""

CONDUCTOR_EPS = 1e20
"""``|eps|`` from which a region is a perfect conductor (module text)."""


def is_perfect_conductor(eps: complex) -> bool:
    """Whether a region of permittivity ``eps`` is a perfect conductor (``|eps| >= 1e20``).

    Examples
    --------
    >>> is_perfect_conductor(PEC_EPS), is_perfect_conductor(5.0 + 1e8j)   # copper at 10 GHz
    (True, False)
    """
    return abs(complex(eps)) >= CONDUCTOR_EPS


def surface_is_perfect_conductor(medium: Any) -> bool:
    """Whether the ground below the air is a perfect conductor (the glare in closed form)."""
    return not medium.is_free_space and is_perfect_conductor(medium.eps[1])


def refuse_perfect_conductor(medium: Any) -> None:
    """Refuse a perfect conductor where a Sommerfeld integral would be needed.

    Raises
    ------
    ValueError
        Some region below the air is a perfect conductor (module text).
    """
    bad = [j for j in range(1, len(medium.eps)) if is_perfect_conductor(medium.eps[j])]
    if bad:
        raise ValueError(
            f"region {bad[0]} of the ground is a perfect conductor (|eps| >= "
            f"{CONDUCTOR_EPS:g}, e.g. PEC_EPS): holoradar models one only as the ground's "
            "surface seen from the air, whose glare is the source's mirror image (no field "
            "reaches into or below it: targets must lie above it; under another layer it is "
            "not modelled)")
