"""Polarised plane waves through the stack: the TE/TM split of one vector component.

A plane wave travelling down in the air with transverse wavenumbers (p, q)
and a (transverse) electric field ``e`` is split into its TE part, along
``h = (-sin(phi), cos(phi), 0)``, and its TM part, along
``v+ = (kz0 cos(phi), kz0 sin(phi), -kappa)/k``. Each crosses the stack with the
Fresnel law of its own polarisation (both laws give the tangential electric
field, :func:`holoradar.physics.medium.fresnel`):

* in a ground layer the TE field is ``tau_h a_h h``; the TM field has the
  tangential part ``tau_v a_v kz0/k`` along ``(cos(phi), sin(phi), 0)`` and the
  vertical part ``-kappa sigma_v a_v kz0/(k kz_m)`` (``div E = 0`` for the down-
  and the up-going wave: ``tau`` = down + up, ``sigma`` = down - up);
* reflected into the air it is ``R_h a_h h - R_v a_v v-`` with
  ``v- = (-kz0 cos(phi), -kz0 sin(phi), -kappa)/k`` (the reflected wave's TM
  vector: its tangential field is ``R_v`` times the incident one).

At normal incidence phi is taken as 0 (both laws agree there). The lateral
phase ``exp(i(p x + q y))`` is left to the caller.
"""

from __future__ import annotations

import numpy as np

from .medium import Medium

__all__ = ["transverse", "vector_transfer", "wave_polarization"]


def transverse(direction: np.ndarray, polarization: np.ndarray, name: str = "polarization"
               ) -> np.ndarray:
    """The part of ``polarization`` across the unit ``direction`` of travel, normalised.

    Raises
    ------
    ValueError
        When the polarisation lies along the direction of travel (no field).

    Examples
    --------
    >>> transverse(np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 1.0])).round(6).tolist()
    [1.0, 0.0, 0.0]
    """
    u = np.asarray(polarization, float)
    d = np.asarray(direction, float)
    e = u - (u @ d) * d
    n = float(np.linalg.norm(e))
    if n < 1e-6:
        raise ValueError(f"{name} lies along the wave's direction of travel "
                         f"{np.round(d, 6).tolist()}: a plane wave has no field along it; give "
                         "a direction across it, e.g. (0, 1, 0)")
    return e / n


def wave_polarization(direction: np.ndarray, value: object
                      ) -> tuple[float, float, float] | None:
    """A wave's ``polarization`` argument checked (a real non-zero 3-vector, normalised)
    and made transverse to its unit ``direction``; None stays None.

    Examples
    --------
    >>> wave_polarization(np.array([0.0, 0.0, 1.0]), (0, 2, 1))
    (0.0, 1.0, 0.0)
    """
    from .._validate import as_polarization

    pol = as_polarization(value, "polarization")
    if pol is None:
        return None
    return tuple(float(v) for v in transverse(direction, pol))


def _basis(k: float, p: np.ndarray, q: np.ndarray, kz0: np.ndarray):
    kap = np.hypot(p, q)
    phi = np.arctan2(q, p)
    c, s = np.cos(phi), np.sin(phi)
    zero = np.zeros_like(kap)
    h = np.stack([-s, c, zero], axis=-1)
    vp = np.stack([kz0 * c, kz0 * s, -kap + 0j], axis=-1) / k
    vm = np.stack([-kz0 * c, -kz0 * s, -kap + 0j], axis=-1) / k
    return kap, c, s, h, vp, vm


def vector_transfer(k: float, medium: Medium, p: np.ndarray, q: np.ndarray, e: np.ndarray,
                    z_from: float, z: float, *, reflected: bool = False) -> np.ndarray:
    """Field vectors at range ``z`` of down-going plane waves given at ``z_from`` (air).

    Parameters
    ----------
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
    p, q : ndarray, shape S
        Transverse wavenumbers, rad/m (propagating in the air).
    e : ndarray, shape S + (3,) or (3,)
        Electric field vector of each wave at ``z_from`` (its part along the
        direction of travel is ignored).
    z_from, z : float
        Ranges, metres; ``z_from`` in the air.
    reflected : bool
        The stack's reflection, seen at ``z`` in the air, instead of the wave
        travelling down (direct in the air, transmitted in the ground).

    Returns
    -------
    ndarray, shape S + (3,)

    Examples
    --------
    >>> m = Medium.half_space(0.3, 4.0)
    >>> E = vector_transfer(200.0, m, np.array(0.0), np.array(0.0), np.array([1.0, 0, 0]),
    ...                     0.0, 0.0, reflected=True)
    >>> np.round(np.abs(E), 4).tolist()   # |(1 - n)/(1 + n)| at normal incidence, E along x
    [0.3333, 0.0, 0.0]
    """
    p = np.asarray(p, float)
    q = np.asarray(q, float)
    k2 = p * p + q * q
    kz0 = medium.kz(k, k2, 0)
    kap, c, s, h, vp, vm = _basis(k, p, q, kz0)
    e = np.broadcast_to(np.asarray(e, complex), (*p.shape, 3))
    a_h = np.sum(e * h, axis=-1)
    a_v = np.sum(e * vp, axis=-1)
    if reflected:
        z0 = medium.z_interfaces[0]
        ph = np.exp(1j * kz0 * ((z0 - z_from) + (z0 - z)))
        Rh = medium.with_polarization("TE").reflection(k, k2)
        Rv = medium.with_polarization("TM").reflection(k, k2)
        return ((Rh * a_h)[..., None] * h - (Rv * a_v)[..., None] * vm) * ph[..., None]
    if z < z_from or medium.region_of(float(z)) == 0:
        # In the air (or above the reference plane): the wave itself.
        return ((a_h[..., None] * h + a_v[..., None] * vp)
                * np.exp(1j * kz0 * (z - z_from))[..., None])
    dh, uh = medium.with_polarization("TE").transfer_parts(k, k2, z_from, z)
    dv, uv = medium.with_polarization("TM").transfer_parts(k, k2, z_from, z)
    kzm = medium.kz(k, k2, medium.region_of(float(z)))
    tang = (dv + uv) * a_v * kz0 / k
    vert = -kap * (dv - uv) * a_v * kz0 / (k * kzm)
    return ((dh + uh) * a_h)[..., None] * h + np.stack([tang * c, tang * s, vert], axis=-1)
