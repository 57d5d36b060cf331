"""The Gaussian-beam fit of the glare (``method="gaussian"``).

The exact complex-source-point beam ``exp(i*k*Rc)/Rc`` (:func:`_csp_beam`), its
least-squares fit on the elements or in the mirror plane (:func:`_fit_gaussian`),
and the reflection coefficient and permittivity from the fitted spot's strength
(:func:`_eps_from_gaussian`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..._lazy import lazy_module
from ...data.hologram import Hologram
from ...physics.medium import Medium
from ...physics.sources import GaussianBeam, PointSource
from ._common import _linear_fit
from .report import GlareFit
from .spot import MirrorSpot

# Imported on first use (holoradar._lazy): `import holoradar` should cost little more
# than numpy.
_opt = lazy_module("scipy.optimize")


def _csp_beam(k: float, pts: np.ndarray, x: float, y: float, z: float, b: float,
              u: np.ndarray | None = None) -> np.ndarray:
    """Complex-source-point beam exp(i k Rc)/Rc seen at ``pts``: waist at (x, y, z),
    travelling along the unit vector ``u`` (default -z, towards the aperture).

    The source sits at the complex point ``c + i*b*u``: ``Rc = |r - c - i*b*u|`` is, on
    the axis, the distance along it less ``i*b``, a Gaussian beam of waist
    ``sqrt(2*b/k)``.
    """
    ux, uy, uz = (0.0, 0.0, -1.0) if u is None else (float(u[0]), float(u[1]), float(u[2]))
    Rc = np.sqrt((pts[:, 0] - x - 1j * b * ux) ** 2 + (pts[:, 1] - y - 1j * b * uy) ** 2
                 + (pts[:, 2] - z - 1j * b * uz) ** 2)
    Rc = np.where(Rc.real < 0, -Rc, Rc)
    return np.exp(1j * k * Rc) / Rc


def _fit_gaussian(spot: MirrorSpot, initial: dict[str, Any] | None,
                  transform: Callable[[np.ndarray], np.ndarray] | None = None,
                  u: np.ndarray | None = None, b0: float | None = None):
    """Fit ``a*beam + d*D`` to the data, in the domain ``transform`` maps them to.

    ``transform`` is the windowed image of the mirror plane (the paper's choice:
    there the glare is a compact spot and buried objects are defocused); ``None``
    fits on the elements themselves (in the aperture's frame: ``spot.local``).
    """
    k, pts, h, D = spot.k, spot.local, spot.h, spot.D
    xs, ys, z_m, cell = spot.xs, spot.ys, spot.z_m, spot.cell
    scale = cell
    # The spot lies in the mirror plane by construction: its range is not fitted (a
    # free range lets the beam swallow a buried reflector's own, deeper, focus).
    start_b = 0.01 * cell if b0 is None else b0
    x0 = np.array([xs, ys, start_b]) if not initial else np.array(
        [initial["x"], initial["y"], max(initial["b"], 1e-6)])
    T = transform if transform is not None else (lambda v: v)
    th = T(h).ravel()
    tD = None if D is None else T(D).ravel()

    def parts(theta: np.ndarray):
        G = _csp_beam(k, pts, theta[0], theta[1], z_m, theta[2], u)
        # exp(ik Rc)/Rc grows as exp(k b) with the waist (1e33 for a 6 cm beam at
        # 10 GHz): scale it to unit norm so that the joint fit with the direct wave is
        # well conditioned, and scale its coefficient back.
        norm = float(np.linalg.norm(G)) or 1.0
        tG = T(G / norm).ravel()
        basis = [tG] if tD is None else [tG, tD]
        coef, model = _linear_fit(th, basis)
        coef = coef.copy()
        coef[0] /= norm
        return coef, model, G

    def resid(u: np.ndarray) -> np.ndarray:
        theta = x0 + u * scale
        theta[2] = abs(theta[2])
        _, model, _ = parts(theta)
        r = th - model
        return np.concatenate([r.real, r.imag])

    # The mirror image of a horn is a spot no wider than the horn's mouth: its waist is
    # bounded by one wavelength. A wider beam would swallow the defocused, but nearby
    # in range, specular return of a buried planar reflector.
    # A Gaussian-beam radiator's reflected beam has the radiator's own waist: allow it
    # half to twice that (the stack's reflection reshapes the spectrum a little).
    b_max = k * (2 * np.pi / k) ** 2 / 2 if b0 is None else 4 * b0
    lo = np.array([-3.0, -3.0, (-x0[2] if b0 is None else 0.25 * b0 - x0[2]) / scale])
    hi = np.array([3.0, 3.0, (b_max - x0[2]) / scale])
    sol = _opt.least_squares(resid, np.clip(np.zeros(3), lo, hi), bounds=(lo, hi), xtol=1e-10,
                             ftol=1e-12, max_nfev=400)
    theta = x0 + sol.x * scale
    theta[2] = abs(theta[2])
    coef, _, G = parts(theta)
    a = complex(coef[0])
    dcoef = None if D is None else complex(coef[1])
    explained = 1 - np.sum(sol.fun**2) / max(np.sum(np.abs(th) ** 2), 1e-300)
    fit = {"x": float(theta[0]), "y": float(theta[1]), "z": float(z_m),
           "b": float(theta[2]), "a": a, "converged": bool(sol.success and explained > 0.5)}
    return a * G, (np.zeros_like(h) if D is None else dcoef * D), dcoef, fit


def _eps_from_gaussian(a: complex, b: float, ref: complex, src: PointSource,
                       hologram: Hologram, medium: Medium, k: float
                       ) -> tuple[complex, complex]:
    """V and eps from the mirror spot's strength.

    The fitted beam ``a*exp(ik Rc)/Rc``, ``Rc ~ s - i*b`` on its axis, is the mirror
    image's spherical wave ``V * ref * pattern * exp(iks)/s`` for a source of
    amplitude ``ref``: V = a*exp(k*b) / (ref * pattern), to first order in b/s,
    the pattern taken along the specular ray from the radiator to the aperture's
    centre. Its phase is traded against the fitted range of the beam (a
    millimetre is 0.2 rad), so only |V| is used: for a ground denser than air
    V = -|V| and n = (1 + |V|)/(1 - |V|), real (loss is not seen this way).

    A posed (tilted or shifted) aperture sees the surface at the specular angle
    theta of the ray to its centre: eps' then solves ``|r(eps', theta)| = |V|``
    for the medium's polarization (Fresnel, a half-space), monotonic in eps'.
    """
    z0 = medium.z_interfaces[0]
    centre = hologram.pose.to_world(np.array(np.mean(hologram.x)),
                                    np.array(np.mean(hologram.y)))
    # The ray leaves the radiator towards the aperture centre's mirror point, downwards.
    d = np.array([centre[0] - src.position[0], centre[1] - src.position[1],
                  2 * z0 - centre[2] - src.position[2]])
    d /= np.linalg.norm(d)
    pat = src.pattern(d[None, :])[0] if src.has_pattern else 1.0
    if pat == 0:
        return complex(np.nan), complex(np.nan)
    V = -abs(a * np.exp(k * b) / (ref * pat))
    if V <= -1:
        return complex(V), complex(np.nan)
    if hologram.pose.is_identity:
        n = (1 - V) / (1 + V)
        return complex(V), complex(n * n)
    kappa2 = np.array(k * k * (1 - d[2] ** 2))

    def excess(e: float) -> float:
        half = Medium((z0,), (1.0, e), medium.polarization)
        return float(abs(half.reflection(k, kappa2))) - abs(V)

    if excess(1.0 + 1e-9) >= 0 or excess(1e4) <= 0:
        return complex(V), complex(np.nan)
    return complex(V), complex(_opt.brentq(excess, 1.0 + 1e-9, 1e4, xtol=1e-10))


def remove_gaussian(spot: MirrorSpot, fit_domain: str, initial: dict[str, Any] | None
                    ) -> GlareFit:
    """The ``"gaussian"`` method: the beam fitted at ``spot`` (on the elements, or in a
    window of two resolution cells around the spot in the mirror plane) and removed.

    Examples
    --------
    Through :func:`holoradar.suppress_surface` (the default method).
    """
    transform = None
    if fit_domain == "mirror":
        window = np.hypot(spot.op.x[None, :] - spot.xs,
                          spot.op.y[:, None] - spot.ys) <= 2 * spot.cell

        def transform(v: np.ndarray) -> np.ndarray:
            return spot.image(v)[window]

    u_beam, b0 = None, None
    src, pose, k = spot.src, spot.hologram.pose, spot.k
    if isinstance(src, GaussianBeam):
        # The reflected beam's axis (the incident one mirrored), in the aperture's
        # frame, and its waist: the fit starts from them and lets the waist vary.
        d = src.direction * np.array([1.0, 1.0, -1.0])
        u_beam = np.array([d @ pose.u, d @ pose.v, d @ pose.normal])
        b0 = k * src.waist**2 / 2
    glare, direct_part, dcoef, fit = _fit_gaussian(spot, initial, transform, u_beam, b0)
    b = fit["b"]
    report = {"mirror_position": spot.world(fit["x"], fit["y"], fit["z"]),
              "amplitude": fit["a"], "phase": float(np.angle(fit["a"])),
              "waist": float(np.sqrt(2 * b / k))}
    return GlareFit(glare, direct_part, dcoef, fit["converged"], fit, report)
