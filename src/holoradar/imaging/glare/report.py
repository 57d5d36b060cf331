"""What a glare removal reports (:class:`SuppressionReport`), warns
(:class:`FitWarning`) and what each method hands back to it (:class:`GlareFit`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["FitWarning", "GlareFit", "SuppressionReport", "db"]


class FitWarning(UserWarning):
    """A glare fit did not converge or explains little of the data."""


@dataclass(frozen=True)
class SuppressionReport:
    """What :func:`suppress_surface` found and removed.

    Attributes
    ----------
    method : str
    mirror_plane : float or None
        Range z_m = 2*z0 - z_s of the mirror image, metres.
    mirror_position : tuple of float or None
        Where the glare was found (x, y, z), metres.
    amplitude : complex or None
        Fitted complex amplitude of the glare model (``"gaussian"``: of
        ``exp(i*k*Rc)/Rc``; ``"image_source"``: the source amplitude).
    phase : float or None
        ``angle(amplitude)``, radians.
    waist : float or None
        Fitted beam waist w0, metres (``"gaussian"``); the disk radius (``"cut"``).
    glare_suppression_db : float
        Peak of |image| at the mirror spot before / after, in the z_m plane, dB.
    glare_removed_db, direct_removed_db : float or None
        Energy of the removed glare and direct wave relative to the energy left
        in the hologram, dB.
    direct_amplitude : complex or None
        Fitted complex amplitude of the direct wave (the source's, if calibrated).
    reflection_coefficient : complex or None
        Estimated normal-incidence reflection coefficient V of the ground.
    eps : complex or None
        Permittivity of the top layer (from V or fitted), with ``eps_std`` the
        1-sigma uncertainty of its real and imaginary parts.
    converged : bool
    parameters : dict
        The fitted parameters, to warm-start the next frame (``initial=``).
    """

    method: str
    mirror_plane: float | None = None
    mirror_position: tuple[float, float, float] | None = None
    amplitude: complex | None = None
    phase: float | None = None
    waist: float | None = None
    glare_suppression_db: float | None = None
    glare_removed_db: float | None = None
    direct_removed_db: float | None = None
    direct_amplitude: complex | None = None
    reflection_coefficient: complex | None = None
    eps: complex | None = None
    eps_std: tuple[float, float] | None = None
    converged: bool = True
    parameters: dict[str, Any] = field(default_factory=dict)


@dataclass
class GlareFit:
    """One method's answer: the glare and the direct wave removed (flattened views),
    the direct wave's amplitude, whether the fit converged, its parameters (to
    warm-start the next frame) and what it adds to the report."""

    glare: np.ndarray
    direct_part: np.ndarray
    direct_amplitude: complex | None
    converged: bool
    parameters: dict[str, Any]
    report: dict[str, Any]


def db(a: float, b: float) -> float:
    """``10 log10(a / b)``, both floored at 1e-300."""
    return float(10 * np.log10(max(a, 1e-300) / max(b, 1e-300)))
