"""Forward simulation: the hologram a receiver array records from a scene.

The recorded field is the sum of (each optional):

* the field scattered by the targets, carried up through the stack with each
  layer's own kz and each interface's Fresnel transmission (refraction,
  transmission both ways, absorption);
* the specular reflection of the source from the ground (the glare: the wave of
  the mirror-image source, reflection coefficient of the whole stack);
* the direct field of the source at the aperture;
* circular complex Gaussian receiver noise at a given SNR.

Point targets use the exact Sommerfeld integral (:mod:`..physics.green`).

Vector model: when the elements record one component ``u`` of the electric
field (``Aperture(..., polarization=u)``) and the source's field is a vector (a
:class:`~holoradar.Dipole`, or a source given a ``polarization``), every wave
is the electric dipole's: the incident field (direct, or transmitted through the
stack with the TE and TM coefficients), each point target an induced dipole
``p = alpha E`` (a line a row of them), its field at the elements ``G p`` with
the dyadic Green's function (:mod:`..physics.dyadic`), and the recorded value
``u . E``. A scanned transceiver sends and receives along ``u``. Planar targets
keep the scalar Kirchhoff model, lit by the incident field's component along
``u``. A target in the air (above the surface) is lit, and seen, by the direct
wave and its reflection from the ground.

A
planar target's reflected field ``f*E0`` is carried by its angular spectrum
(non-paraxial), evaluated exactly at the receivers by a direct (non-uniform)
Fourier sum. Rays that would land far (> 10 wavelengths) off every receiver are
tapered off smoothly, and the spectral sampling is chosen so that the periodic
copies of the object lie farther than any kept ray can travel (a band-limited
angular spectrum in the spirit of Matsushima and Shimobaba's), so nothing wraps.
Against a direct Rayleigh-Sommerfeld sum the field agrees to about 0.1%.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_polarization, as_real, check_frequency
from ..data.hologram import C0, Hologram, frequency_axis, has_polarization
from ..physics.dyadic import (
    RadialDyadic,
    free_space_dyadic,
    reflected_dyadic,
    transmitted_dyadic,
)
from ..physics.green import free_space_green, green_at_distances
from ..physics.medium import Medium
from ..physics.propagation import lateral_travel
from .scene import Aperture, Scene
from .targets import LineTarget, PlanarTarget, PointTarget

__all__ = ["simulate"]

_MARGIN_WAVELENGTHS = 10.0


def simulate(scene: Scene, aperture: Aperture | np.ndarray, frequency: float | np.ndarray, *,
             include_targets: bool = True, include_surface: bool = True,
             include_direct: bool = False, snr_db: float | None = None,
             seed: int | None = None, monostatic: bool | None = None,
             polarization: object = None, progress: bool = False) -> Hologram | np.ndarray:
    """Simulate the hologram of ``scene`` recorded by ``aperture`` at ``frequency``.

    Parameters
    ----------
    scene : Scene
        Medium, source and targets.
    aperture : Aperture or ndarray of shape (N, 2) or (N, 3)
        Receiver array (:meth:`Aperture.grid`, :meth:`Aperture.paper`,
        :meth:`Aperture.from_positions`), or element positions (x, y[, z]) in metres.
    frequency : float or array_like
        Hz; an array of nf strictly increasing frequencies gives a wideband
        hologram, data (nf, ny, nx).
    include_targets : bool
        Add the field scattered by the targets (default True).
    include_surface : bool
        Add the specular reflection of the source from the ground (default True;
        nothing in free space). Monostatic: each transceiver's own reflection.
    include_direct : bool
        Add the source's own field at the aperture (default False: a horn beside
        the array radiates away from it; a plane wave passes through it).
    snr_db : float, optional
        Add receiver noise: ``10*log10(mean |signal|^2 / noise variance)``, for
        each frequency.
    seed : int, optional
        Seed of the noise generator.
    monostatic : bool, optional
        A scanned transceiver: each element is a point source ``exp(i*k*R)/R`` that
        receives its own echo, so a point target of amplitude ``a`` returns
        ``a * G(element, target)^2`` (``G`` the exact layered Green's function,
        symmetric by reciprocity); the scene's source is not used. Default: the
        aperture's own ``monostatic`` (False for bare positions).
    polarization : (float, float, float), optional
        The field component the elements record (world axes); default the
        aperture's own ``polarization``. With a polarised source (or a
        monostatic aperture) the vector model is used (module notes).
    progress : bool, optional
        Show a progress bar over the frequencies once the work has taken a second
        (default False).

    Returns
    -------
    Hologram
        For a grid :class:`Aperture` (its ``source`` is the scene's); for elements
        at arbitrary positions, a complex array (N,) or (nf, N) of their fields.

    Examples
    --------
    >>> import holoradar as hr
    >>> scene = hr.Scene(hr.Medium.half_space(0.3, 2.5 + 0.0125j),
    ...                  hr.PlaneWave(), [hr.PointTarget((0.0, 0.0, 0.42))])
    >>> h = hr.simulate(scene, hr.Aperture.paper(), 9.9e9, include_surface=False)
    >>> h.shape
    (16, 16)
    >>> w = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))]),
    ...                 hr.Aperture.grid(8, 0.005, monostatic=True), [9e9, 10e9, 11e9])
    >>> w.shape, w.monostatic
    ((3, 8, 8), True)
    """
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be a holoradar.Scene, got {type(scene).__name__}")
    if np.ndim(frequency) == 0:
        freqs, wide = np.array([check_frequency(frequency)]), False
    else:
        freqs, wide = frequency_axis(frequency, (np.size(frequency), 1, 1)), True
    if isinstance(aperture, Aperture):
        pts = aperture.points
    else:
        pts = np.asarray(aperture, dtype=float)
        if pts.ndim != 2 or pts.shape[1] not in (2, 3) or not np.all(np.isfinite(pts)):
            raise ValueError("aperture must be an Aperture or finite element positions of shape "
                             f"(N, 2) or (N, 3) in metres, got shape {pts.shape}")
        if pts.shape[1] == 2:
            pts = np.c_[pts, np.zeros(len(pts))]
    mono = (bool(getattr(aperture, "monostatic", False)) if monostatic is None
            else bool(monostatic))
    medium, source = scene.medium, scene.source
    pol = as_polarization(polarization if polarization is not None
                          else getattr(aperture, "polarization", None), "polarization")
    vector = pol is not None and (mono or has_polarization(source))
    if pol is not None and not vector:
        import warnings

        warnings.warn("simulate: the elements record a polarisation but the source has none "
                      "(give it one, or use a Dipole): the scalar model is used",
                      UserWarning, stacklevel=2)
    if not medium.is_free_space and np.any(pts[:, 2] > medium.z_interfaces[0]):
        raise ValueError(f"aperture: its elements must lie above the ground surface (z < "
                         f"{medium.z_interfaces[0]} m); the deepest is at z = "
                         f"{pts[:, 2].max():.4g} m (check the pose's centre and tilt)")
    if mono and include_direct:
        raise ValueError("include_direct has no meaning for a monostatic aperture (a "
                         "transceiver's coupling to itself is not modelled)")
    offset = getattr(aperture, "tx_offset", None)
    if offset is not None and pol is not None:
        raise ValueError("polarization: the vector model of a transmitter beside the "
                         "receiver (aperture.tx_offset) is not modelled; give "
                         "polarization=None (the scalar model)")
    if offset is not None and not _pose_is_identity(aperture):
        raise ValueError("aperture.tx_offset is modelled on an untilted aperture at z = 0 "
                         "(pose the identity)")
    if mono and any(isinstance(t, PlanarTarget) for t in scene.targets):
        raise ValueError("planar targets are not modelled for a monostatic aperture (each "
                         "transceiver would need its own Kirchhoff integral); use point "
                         "targets, e.g. a grid of them over the object")
    rng = np.random.default_rng(seed)
    rows = []
    from tqdm.auto import tqdm  # here, not at import: holoradar._lazy

    for f in tqdm(freqs, desc="simulate", unit="frequency", disable=not progress, delay=1.0):
        k = 2 * np.pi * f / C0
        if vector and mono:
            total = _monostatic_vector(k, medium, scene, pts, pol, include_targets,
                                       include_surface)
        elif vector:
            total = _bistatic_vector(k, medium, scene, pts, pol, include_targets,
                                     include_surface, include_direct)
        elif mono:
            total = _monostatic(k, medium, scene, pts, include_targets, include_surface,
                                offset)
        else:
            total = _bistatic(k, medium, scene, pts, include_targets, include_surface,
                              include_direct)
        if snr_db is not None:
            power = float(np.mean(np.abs(total) ** 2))
            sigma = np.sqrt(power / 10 ** (as_real(snr_db, "snr_db") / 10) / 2)
            total = total + sigma * (rng.standard_normal(total.shape)
                                     + 1j * rng.standard_normal(total.shape))
        rows.append(total)
    data = np.stack(rows) if wide else rows[0]
    if isinstance(aperture, Aperture) and aperture.is_grid:
        shape = (*data.shape[:-1], aperture.y.size, aperture.x.size)
        return Hologram(data.reshape(shape), aperture.x, aperture.y,
                        freqs if wide else float(freqs[0]),
                        source=None if mono else source, monostatic=mono, pose=aperture.pose,
                        polarization=pol, tx_offset=offset)
    return data


def _scalar_points(k: float, medium: Medium, targets: object) -> list[PointTarget]:
    """Point targets, and each line as a row of points: the scalar model sees a line's
    response to a field along its axis."""
    out = [t for t in targets if isinstance(t, PointTarget)]
    for t in targets:
        if isinstance(t, LineTarget):
            pos, alpha = t.dipoles(k, _region_eps(medium, t.start[2]))
            along = complex(t.direction @ alpha[0] @ t.direction)
            out += [PointTarget(p, along) for p in pos]
    return out


def _region_eps(medium: Medium, z: float) -> complex:
    return complex(medium.eps[medium.region_of(float(z))])


def _dipoles(k: float, medium: Medium, targets: list) -> tuple[np.ndarray, np.ndarray]:
    """Every point and line target as induced dipoles: positions (M, 3), tensors (M, 3, 3)."""
    pos, alpha = [], []
    for t in targets:
        if isinstance(t, PointTarget):
            pos.append(t.position[None, :])
            alpha.append(t.tensor[None])
        elif isinstance(t, LineTarget):
            zs = (t.start[2], t.end[2])
            if medium.region_of(min(zs)) != medium.region_of(max(zs)):
                raise ValueError("a LineTarget must lie within one layer of the ground (it "
                                 "crosses an interface)")
            p, a = t.dipoles(k, _region_eps(medium, zs[0]))
            pos.append(p)
            alpha.append(np.asarray(a))
    if not pos:
        return np.zeros((0, 3)), np.zeros((0, 3, 3), complex)
    return np.concatenate(pos), np.concatenate(alpha)


def _receiving(k: float, medium: Medium, z_e: float, z_t: float, offsets: np.ndarray
               ) -> np.ndarray:
    """G(r_t, r_e) (N, 3, 3): the field at targets (offsets r_t - r_e, range z_t) of a
    dipole at each element (range z_e); its transpose is the target's field at the
    element (reciprocity). A target in the air gets the direct wave and the ground's
    reflection."""
    src = np.array([0.0, 0.0, z_e])
    pts = np.c_[offsets, np.full(len(offsets), z_t)]
    if medium.is_free_space or medium.region_of(z_t) == 0:
        if z_t >= z_e:
            G = transmitted_dyadic(k, medium, src, pts)
        else:
            G = free_space_dyadic(k, src, pts)
        if not medium.is_free_space:
            G = G + reflected_dyadic(k, medium, src, pts)
        return G
    rho_max = float(np.hypot(offsets[:, 0], offsets[:, 1]).max(initial=0.0))
    table_size = rho_max / (2 * np.pi / (k * max(abs(medium.n(m)) for m in
                                                 range(medium.n_regions))) / 16)
    if len(offsets) > 2 * table_size:
        return RadialDyadic(k, medium, z_e, z_t, rho_max)(offsets)
    return transmitted_dyadic(k, medium, src, pts)


def _incident_vector(k: float, medium: Medium, source: object, pos: np.ndarray) -> np.ndarray:
    E = source.field_vector(k, medium, pos)
    if not medium.is_free_space:
        air = np.asarray(medium.region_of(pos[:, 2])) == 0
        if np.any(air):
            E[air] = E[air] + source.reflected_vector(k, medium, pos[air])
    return E


def _bistatic_vector(k: float, medium: Medium, scene: Scene, pts: np.ndarray, pol: np.ndarray,
                     include_targets: bool, include_surface: bool,
                     include_direct: bool) -> np.ndarray:
    """A receiver array recording ``pol . E`` of a polarised source's scene."""
    source = scene.source
    total = np.zeros(len(pts), complex)
    if include_targets:
        pos, alpha = _dipoles(k, medium, list(scene.targets))
        if len(pos):
            P = np.einsum("mij,mj->mi", alpha, _incident_vector(k, medium, source, pos))
            for zt in np.unique(pos[:, 2]):
                st = np.nonzero(pos[:, 2] == zt)[0]
                for ze in np.unique(pts[:, 2]):
                    se = np.nonzero(pts[:, 2] == ze)[0]
                    off = (pos[st, None, :2] - pts[None, se, :2]).reshape(-1, 2)
                    G = _receiving(k, medium, float(ze), float(zt), off)      # G(r_t, r_e)
                    Gu = (G @ pol).reshape(st.size, se.size, 3)
                    total[se] += np.einsum("mi,mei->e", P[st], Gu)
        planar = [t for t in scene.targets if isinstance(t, PlanarTarget)]
        if planar:
            along = _AlongPolarization(source, pol)
            for t in planar:
                total += _planar_target(k, medium, along, t, pts)
    if include_surface and not medium.is_free_space:
        total += source.reflected_vector(k, medium, pts) @ pol
    if include_direct:
        total += source.field_vector(k, medium, pts) @ pol
    return total


class _AlongPolarization:
    """A polarised source seen through one field component (the scalar Kirchhoff model)."""

    def __init__(self, source: object, pol: np.ndarray) -> None:
        self.source, self.pol = source, pol

    def field(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        return self.source.field_vector(k, medium, points) @ self.pol


def _monostatic_vector(k: float, medium: Medium, scene: Scene, pts: np.ndarray,
                       pol: np.ndarray, include_targets: bool,
                       include_surface: bool) -> np.ndarray:
    """Scanned transceivers sending and receiving along ``pol``: ``v . alpha v``, with
    ``v = G(r_t, r_e) pol`` the transceiver's field at the target (reciprocity)."""
    total = np.zeros(len(pts), complex)
    if include_targets:
        if any(isinstance(t, PlanarTarget) for t in scene.targets):
            raise ValueError("planar targets are not modelled for a monostatic aperture")
        pos, alpha = _dipoles(k, medium, list(scene.targets))
        for zt in np.unique(pos[:, 2]):
            st = np.nonzero(pos[:, 2] == zt)[0]
            for ze in np.unique(pts[:, 2]):
                se = np.nonzero(pts[:, 2] == ze)[0]
                off = (pos[st, None, :2] - pts[None, se, :2]).reshape(-1, 2)
                v = (_receiving(k, medium, float(ze), float(zt), off) @ pol).reshape(
                    st.size, se.size, 3)
                total[se] += np.einsum("mei,mij,mej->e", v, alpha[st], v)
    if include_surface and not medium.is_free_space:
        for ze in np.unique(pts[:, 2]):
            se = pts[:, 2] == ze
            G = reflected_dyadic(k, medium, np.array([0.0, 0.0, ze]),
                                 np.array([[0.0, 0.0, ze]]))[0]
            total[se] += pol @ G @ pol
    return total


def _bistatic(k: float, medium: Medium, scene: Scene, pts: np.ndarray, include_targets: bool,
              include_surface: bool, include_direct: bool) -> np.ndarray:
    """A receiver array lit by the scene's source."""
    source = scene.source
    total = np.zeros(len(pts), complex)
    if include_targets:
        points = _scalar_points(k, medium, scene.targets)
        if points:
            total += _point_targets(k, medium, source, points, pts)
        for t in scene.targets:
            if isinstance(t, PlanarTarget):
                total += _planar_target(k, medium, source, t, pts)
    if include_surface and not medium.is_free_space:
        total += source.reflected(k, medium, pts)
    if include_direct:
        total += source.field(k, medium, pts)
    return total


def _monostatic(k: float, medium: Medium, scene: Scene, pts: np.ndarray,
                include_targets: bool, include_surface: bool,
                offset: tuple[float, float, float] | None = None) -> np.ndarray:
    """Scanned transceivers: each element's echo of its own point-source wave; with
    ``offset``, of a transmitter at the element + offset (``g_rx g_tx``)."""
    total = np.zeros(len(pts), complex)
    if offset is not None:
        return _offset_pair(k, medium, scene, pts, include_targets, include_surface, offset)
    if include_targets:
        targets = _scalar_points(k, medium, scene.targets)
        for zt in sorted({float(t.position[2]) for t in targets}):
            group = [t for t in targets if t.position[2] == zt]
            pos = np.array([t.position for t in group])
            amp = np.array([t.amplitude for t in group])
            for zr in np.unique(pts[:, 2]):
                sel = pts[:, 2] == zr
                d = pts[None, sel, :2] - pos[:, None, :2]
                rho = np.hypot(d[..., 0], d[..., 1])
                if medium.is_free_space:
                    R = np.hypot(rho, zt - zr)
                    g = np.exp(1j * k * R) / R
                else:
                    g = green_at_distances(k, medium, float(zt), float(zr), rho)
                total[sel] += amp @ (g * g)  # reciprocity: down and up are the same G
    if include_surface and not medium.is_free_space:
        # Each transceiver's own glare: the reflected field at its own position.
        for zr in np.unique(pts[:, 2]):
            sel = pts[:, 2] == zr
            total[sel] += green_at_distances(k, medium, float(zr), float(zr), np.zeros(1),
                                             kind="reflected")[0]
    return total


def _offset_pair(k: float, medium: Medium, scene: Scene, pts: np.ndarray,
                 include_targets: bool, include_surface: bool,
                 offset: tuple[float, float, float]) -> np.ndarray:
    """A receiver at each element and a transmitter at the element + ``offset``: a
    point target returns ``a g(rx, t) g(tx, t)`` (Born), the surface the transmitter's
    reflected wave at the receiver."""
    dx, dy, dz = offset
    total = np.zeros(len(pts), complex)
    if include_targets:
        targets = _scalar_points(k, medium, scene.targets)
        for t in targets:
            zt = float(t.position[2])
            legs = []
            for shift, zr in (((0.0, 0.0), 0.0), ((dx, dy), dz)):
                rho = np.hypot(pts[:, 0] + shift[0] - t.position[0],
                               pts[:, 1] + shift[1] - t.position[1])
                legs.append(green_at_distances(k, medium, zt, zr, rho))
            total += t.amplitude * legs[0] * legs[1]
    if include_surface and not medium.is_free_space:
        glare = green_at_distances(k, medium, float(dz), 0.0, np.array([np.hypot(dx, dy)]),
                                   kind="reflected")[0]
        total += glare
    return total


def _pose_is_identity(aperture: object) -> bool:
    pose = getattr(aperture, "pose", None)
    return pose is None or pose.is_identity


def _point_targets(k: float, medium: Medium, source: object, targets: list[PointTarget],
                   pts: np.ndarray) -> np.ndarray:
    """Sum of ``a * E0(r_t) * G(r_t -> element)`` over the point targets (Born)."""
    pos = np.array([t.position for t in targets])
    amp = np.array([t.amplitude for t in targets]) * source.field(k, medium, pos)
    if medium.is_free_space:
        return sum(a * free_space_green(k, p, pts) for a, p in zip(amp, pos, strict=True))
    out = np.zeros(len(pts), complex)
    # Targets at one range seen by elements at one range share one radial profile.
    for zt in np.unique(pos[:, 2]):
        sel_t = pos[:, 2] == zt
        for zr in np.unique(pts[:, 2]):
            sel_r = pts[:, 2] == zr
            d = pts[None, sel_r, :2] - pos[sel_t, None, :2]
            g = green_at_distances(k, medium, float(zt), float(zr), np.hypot(d[..., 0], d[..., 1]))
            out[sel_r] += amp[sel_t] @ g
    return out


def _planar_target(k: float, medium: Medium, source: object, t: PlanarTarget,
                   pts: np.ndarray) -> np.ndarray:
    f = t.reflectivity
    iy, ix = np.nonzero(f)
    if iy.size == 0:
        return np.zeros(len(pts), complex)
    # Only the rows/columns that hold the object matter.
    ys, xs = t.y[iy.min():iy.max() + 1], t.x[ix.min():ix.max() + 1]
    fsub = f[iy.min():iy.max() + 1, ix.min():ix.max() + 1]
    X, Y = np.meshgrid(xs, ys)
    sel = fsub != 0
    pix = np.stack([X[sel], Y[sel], np.full(int(sel.sum()), t.z)], axis=1)
    s = np.zeros(fsub.shape, complex)
    s[sel] = fsub[sel] * source.field(k, medium, pix)
    dx, dy = t.pitch
    # Lateral extent D that any useful ray must bridge, and a margin for diffraction.
    lo = np.minimum([xs[0], ys[0]], pts[:, :2].min(axis=0))
    hi = np.maximum([xs[-1], ys[-1]], pts[:, :2].max(axis=0))
    D = float(np.hypot(*(hi - lo)))
    reach = D + max(_MARGIN_WAVELENGTHS * 2 * np.pi / k, 0.5 * D)
    # Components whose rays travel laterally beyond `reach` land off every receiver;
    # they are tapered off smoothly between reach and 2*reach (a sharp cut would ring),
    # and the spectral period is wide enough that no kept ray from a periodic copy of
    # the object lands on a receiver.
    period = 4 * reach + D
    dp = 2 * np.pi / period
    kmax = min(np.pi / max(dx, dy), k)  # the pixels carry no more; air carries no more
    m = int(np.ceil(kmax / dp))
    p = np.arange(-m, m + 1) * dp
    P, Q = np.meshgrid(p, p)
    kap2 = P * P + Q * Q
    travel0 = np.sqrt(kap2) * lateral_travel(k, medium, kap2, t.z)  # from t.z up to range 0
    kz0 = medium.kz(k, kap2, 0).real
    # Continuous FT of the object's field: S(q, p) = sum s exp(-i(p x + q y)) d^2.
    Ey = np.exp(-1j * np.outer(p, ys))
    Ex = np.exp(-1j * np.outer(xs, p))
    S = Ey @ s @ Ex * (dx * dy)
    out = np.empty(len(pts), complex)
    # Each receiver range has its own transfer (and its rays their own lateral travel).
    for zr in np.unique(pts[:, 2]):
        idx = np.nonzero(pts[:, 2] == zr)[0]
        U = medium.vertical_transfer(k, kap2, t.z, float(zr))
        with np.errstate(invalid="ignore", divide="ignore"):
            travel = travel0 - np.sqrt(kap2) * zr / np.where(kz0 > 0, kz0, np.nan)
            u = np.clip((travel - reach) / reach, 0, 1)
        taper = np.where(np.isfinite(travel) & (kap2 < k * k), 0.5 * (1 + np.cos(np.pi * u)), 0)
        A = S * U * taper * dp * dp / (4 * np.pi**2)
        # Direct (non-uniform) inverse Fourier sum at the receivers.
        for c0 in range(0, idx.size, 2048):
            c = pts[idx[c0:c0 + 2048]]
            ey = np.exp(1j * np.outer(c[:, 1], p))      # (N, nq)
            ex = np.exp(1j * np.outer(c[:, 0], p))      # (N, np)
            out[idx[c0:c0 + 2048]] = np.sum((ey @ A) * ex, axis=1)
    return out
