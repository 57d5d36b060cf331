"""Planning an oblique layout: where the horn's specular reflection falls, how much
of it reaches the elements, and how far the target appears.

Geometry (world frame: z the range below the reference plane, the ground's
surface at ``z_s``): the horn's boresight ``d`` from its position ``h`` meets the
surface at the specular point ``P = h + d (z_s - h_z)/d_z``; the reflected axis
leaves ``P`` along ``d' = (d_x, d_y, -d_z)``. It misses the aperture when it
crosses the aperture's plane outside the elements' rectangle (or not at all).

Glare fraction (geometric optics): the reflected wave radiates from the horn's
mirror image with the horn's pattern times the reflection coefficient at each
ray's incidence; the fraction is ``integral |r(theta)|^2 |pattern|^2 dOmega``
over the rays that cross the elements' rectangle, over the same integral on the
whole hemisphere. (``simulate`` gives the same power from the exact reflected
field: tested.)

Target: the ray from the aperture's centre to the target refracts at the
surface and at every interface above the target (Snell, ``Re(n)`` of each
layer: the path of least optical length). With ``L_m`` its length and
``theta_m`` its angle from vertical in region ``m`` (the air ``m = 0``), its
apparent distance in free space is ``sum L_m/Re(n_m)`` for the fan of rays
across the plane of incidence (sagittal) and ``sum L_m cos^2(theta_0) /
(Re(n_m) cos^2(theta_m))`` within it (tangential); the effective distance is
their mean, where a free-space depth sweep parallel to the aperture focuses
best. Lateral resolution there: ``lambda L_eff / A`` (``A`` the aperture's
width seen across the ray).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data.hologram import C0
from ..physics.medium import Medium
from ..physics.sources import GaussianBeam, PointSource

__all__ = ["ObliquePlan", "plan_oblique"]


@dataclass(frozen=True)
class ObliquePlan:
    """The layout's key numbers (world frame, metres, radians; see the module text).

    Attributes
    ----------
    specular_point : ndarray (3,)
        Where the horn's boresight meets the surface.
    reflected_direction : ndarray (3,)
        Direction of the reflected boresight.
    miss_distance : float
        Distance in the aperture's plane from the elements' rectangle to where the
        reflected boresight crosses that plane; negative inside the rectangle
        (minus the distance to its nearest edge); ``inf`` when it never crosses.
    glare_fraction : float
        Fraction of the reflected power that crosses the elements' area.
    refraction_point : ndarray (3,)
        Where the ray from the aperture's centre to the target crosses the surface.
    effective_distance : float
        Apparent (free-space) distance of the target along that ray.
    sagittal_distance, tangential_distance : float
        The two apparent distances whose mean is ``effective_distance``.
    lateral_resolution : tuple of float
        ``lambda L_eff / A`` across the aperture's x' and y' axes.
    tilts_missing : ndarray
        Tilts (radians) in 0..80 degrees at which the reflection misses, other
        things equal.
    heights_missing : ndarray
        Horn heights above the surface (metres, 0.02..0.5) at which it misses.
    """

    specular_point: np.ndarray
    reflected_direction: np.ndarray
    miss_distance: float
    glare_fraction: float
    refraction_point: np.ndarray
    effective_distance: float
    sagittal_distance: float
    tangential_distance: float
    lateral_resolution: tuple[float, float]
    tilts_missing: np.ndarray
    heights_missing: np.ndarray


def _horn(source: object) -> tuple[np.ndarray, np.ndarray]:
    """Position and boresight (unit) of a localised source."""
    if isinstance(source, PointSource):
        axis = np.asarray(source.axis, float)
        return np.asarray(source.position, float), axis / np.linalg.norm(axis)
    if isinstance(source, GaussianBeam):
        sa, sb = np.sin(source.alpha), np.sin(source.beta)
        return np.asarray(source.center, float), np.array([sa, sb, np.sqrt(1 - sa**2 - sb**2)])
    raise ValueError("source must be a PointSource (a horn) or a GaussianBeam: a plane wave "
                     f"reflects everywhere and has no specular spot to miss; got "
                     f"{type(source).__name__}")


def _miss(aperture: object, origin: np.ndarray, direction: np.ndarray) -> float:
    """Signed distance from the elements' rectangle to where the ray crosses the plane."""
    pose = aperture.pose
    n = pose.normal
    c = np.asarray(pose.center)
    denom = direction @ n
    if abs(denom) < 1e-12:
        return np.inf
    s = ((c - origin) @ n) / denom
    if s <= 0:
        return np.inf
    q = origin + s * direction - c
    xl, yl = q @ pose.u, q @ pose.v
    dx = (aperture.x[-1] - aperture.x[0]) / max(aperture.x.size - 1, 1)
    dy = (aperture.y[-1] - aperture.y[0]) / max(aperture.y.size - 1, 1)
    x0, x1 = aperture.x[0] - dx / 2, aperture.x[-1] + dx / 2
    y0, y1 = aperture.y[0] - dy / 2, aperture.y[-1] + dy / 2
    ox = max(x0 - xl, 0.0, xl - x1)
    oy = max(y0 - yl, 0.0, yl - y1)
    if ox == 0 and oy == 0:
        return -min(xl - x0, x1 - xl, yl - y0, y1 - yl)
    return float(np.hypot(ox, oy))


def _glare_fraction(k: float, medium: Medium, source: object, horn: np.ndarray,
                    axis: np.ndarray, aperture: object) -> float:
    """Share of the reflected power (mirror-image rays) that crosses the elements."""
    th = np.linspace(0, np.pi / 2, 721)[1:-1]
    ph = np.linspace(0, 2 * np.pi, 721)[:-1]
    T, Ph = np.meshgrid(th, ph, indexing="ij")
    down = np.stack([np.sin(T) * np.cos(Ph), np.sin(T) * np.sin(Ph), np.cos(T)], axis=-1)
    if isinstance(source, PointSource):
        pat = np.abs(source.pattern(down.reshape(-1, 3))).reshape(T.shape) ** 2
    else:  # a Gaussian beam's far field: exp(-(k w0 sin psi)^2/2) in power
        cospsi = np.clip(down @ axis, -1, 1)
        pat = np.exp(-(k * source.waist) ** 2 * (1 - cospsi**2) / 2) * (cospsi > 0)
    w = np.abs(medium.reflection(k, (k * np.sin(T)) ** 2)) ** 2 * pat * np.sin(T)
    total = w.sum()
    if total <= 0:
        return 0.0
    # Reflected rays leave the mirror image upwards: (dx, dy, -dz).
    zs = medium.z_interfaces[0]
    mirror = np.array([horn[0], horn[1], 2 * zs - horn[2]])
    up = down * np.array([1.0, 1.0, -1.0])
    pose = aperture.pose
    n, c = pose.normal, np.asarray(pose.center)
    denom = up @ n
    with np.errstate(divide="ignore", invalid="ignore"):
        s = ((c - mirror) @ n) / denom
    hit_pt = mirror + s[..., None] * up - c
    xl, yl = hit_pt @ pose.u, hit_pt @ pose.v
    dx = aperture.size[0] / aperture.x.size
    dy = aperture.size[1] / aperture.y.size
    inside = ((s > 0) & (xl >= aperture.x[0] - dx / 2) & (xl <= aperture.x[-1] + dx / 2)
              & (yl >= aperture.y[0] - dy / 2) & (yl <= aperture.y[-1] + dy / 2))
    # Rays that cross the surface on their way up from the mirror image are the
    # reflected ones (the mirror lies below it): all do, by construction.
    return float(w[inside].sum() / total)


def plan_oblique(aperture: object, source: object, medium: Medium, target: object, *,
                 frequency: float = 9.9e9) -> ObliquePlan:
    """Plan an oblique layout (see the module text for every formula).

    Parameters
    ----------
    aperture : Aperture
        The receiver array, placed by its ``pose``.
    source : PointSource or GaussianBeam
        The horn: position and boresight.
    medium : Medium
        The ground (at least one interface).
    target : (x, y, z)
        A point of interest under the surface, world frame, metres.
    frequency : float
        Hz (default 9.9 GHz).

    Returns
    -------
    ObliquePlan

    Raises
    ------
    ValueError
        A horn inside the ground, elements below the surface, a target above the
        surface or outside the aperture's field of view, a plane-wave source.

    Examples
    --------
    >>> import numpy as np, holoradar as hr
    >>> sand = hr.Medium.half_space(0.30, 2.5)
    >>> pose = hr.Pose((0.0, -0.15, 0.05), tilt=np.radians(35), azimuth=np.radians(90))
    >>> ap = hr.Aperture.grid(16, 0.025, pose=pose)
    >>> horn = hr.PointSource((0.0, -0.08, 0.25), pattern_exponent=20, axis=(0, 0.13, 0.17))
    >>> plan = hr.plan_oblique(ap, horn, sand, (0.0, 0.05, 0.42))
    >>> bool(plan.miss_distance > 0), round(plan.effective_distance, 2)
    (True, 0.37)
    """
    from ..model.scene import Aperture

    if not isinstance(aperture, Aperture):
        raise ValueError(f"aperture must be a holoradar.Aperture, got {type(aperture).__name__}")
    if not isinstance(medium, Medium) or medium.is_free_space:
        raise ValueError("medium must be a holoradar.Medium with a ground surface")
    horn, axis = _horn(source)
    zs = medium.z_interfaces[0]
    if horn[2] >= zs:
        raise ValueError(f"source: the horn must lie above the ground surface (z < {zs} m), "
                         f"got z = {horn[2]:.4g} m")
    pts = aperture.points
    if np.any(pts[:, 2] >= zs):
        raise ValueError("aperture: its pose puts elements at or below the ground surface")
    try:
        tgt = np.asarray(target, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise ValueError(f"target must be a world position (x, y, z) in metres, got "
                         f"{target!r}") from None
    if not np.all(np.isfinite(tgt)) or tgt[2] <= zs:
        raise ValueError(f"target must lie under the surface (z > {zs} m), got {target!r}")
    pose = aperture.pose
    c = np.asarray(pose.center)
    if (tgt - c) @ pose.normal <= 0:
        raise ValueError("target lies behind the aperture's plane: outside its field of view")
    k = 2 * np.pi * frequency / C0
    if axis[2] <= 0:
        spec, refl, miss = np.full(3, np.nan), np.array([axis[0], axis[1], -axis[2]]), np.inf
    else:
        spec = horn + axis * (zs - horn[2]) / axis[2]
        refl = np.array([axis[0], axis[1], -axis[2]])
        miss = _miss(aperture, spec, refl)
    fraction = _glare_fraction(k, medium, source, horn, axis, aperture)
    # The refracted ray to the target (Fermat) and its apparent distances.
    s_pt, sag, tan = _refracted_ray(medium, c, tgt)
    l_air = float(np.linalg.norm(s_pt - c))
    eff = 0.5 * (sag + tan)
    ray = (s_pt - c) / l_air
    lam = C0 / frequency
    width = aperture.size
    res = tuple(float(lam * eff / (w * np.sqrt(max(1 - (ray @ ax) ** 2, 1e-12))))
                for w, ax in zip(width, (pose.u, pose.v), strict=True))
    # Tilts and horn heights at which the reflection misses, other things equal.
    from ..data.pose import Pose
    from ..model.scene import Aperture as Ap

    tilts = np.radians(np.arange(0, 81, 1.0))
    miss_t = [_miss(Ap(aperture.x, aperture.y, aperture.elements, aperture.monostatic,
                       Pose(pose.center, t, pose.azimuth)), spec, refl) > 0
              if np.all(np.isfinite(spec)) else True for t in tilts]
    heights = np.arange(0.02, 0.5001, 0.01)
    miss_h = []
    for hh in heights:
        hz = zs - hh
        sp = np.array([horn[0], horn[1], hz]) + axis * (zs - hz) / axis[2] if axis[2] > 0 \
            else None
        miss_h.append(True if sp is None else _miss(aperture, sp, refl) > 0)
    return ObliquePlan(spec, refl, float(miss), float(fraction), s_pt, float(eff), float(sag),
                       float(tan), res, tilts[np.array(miss_t)], heights[np.array(miss_h)])


def _refracted_ray(medium: Medium, c: np.ndarray, tgt: np.ndarray
                   ) -> tuple[np.ndarray, float, float]:
    """Ray from ``c`` (air) to ``tgt`` (ground) through the layers: where it crosses
    the surface, and its sagittal and tangential apparent distances (metres)."""
    from scipy.optimize import brentq  # here, not at import: holoradar._lazy

    m_t = int(medium.region_of(tgt[2]))
    tops = [float(c[2])] + [medium.z_interfaces[m] for m in range(m_t)]
    bottoms = [*tops[1:], float(tgt[2])]
    h = np.array(bottoms) - np.array(tops)                 # vertical run in each region
    n = np.array([1.0] + [medium.n(m).real for m in range(1, m_t + 1)])
    d_xy = tgt[:2] - c[:2]
    dist = float(np.hypot(*d_xy))
    u = d_xy / dist if dist > 0 else np.zeros(2)

    def offset(s: float) -> float:   # horizontal run for sin(theta_air) = s
        return float(np.sum(h * s / np.sqrt(n**2 - s**2))) - dist

    s = brentq(offset, 0.0, 1 - 1e-15, xtol=1e-15) if dist > 0 else 0.0
    cos_m = np.sqrt(1 - (s / n) ** 2)
    lengths = h / cos_m
    s_pt = np.array([*(c[:2] + u * h[0] * s / cos_m[0]), medium.z_interfaces[0]])
    sag = float(np.sum(lengths / n))
    tan = float(np.sum(lengths * cos_m[0] ** 2 / (n * cos_m**2)))
    return s_pt, sag, tan
