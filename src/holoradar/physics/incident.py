"""The incident field of a source on a whole image plane, fast.

Multi-view synthesis removes each view's incident phase at every pixel of the
image planes (docs/synthesis.md), so it needs ``E0`` on grids of 1e4-1e6
pixels. A plane wave is analytic. A point source is axially symmetric about its
own vertical line: its Sommerfeld field is computed once on a fine radial grid
(lambda_medium/16 apart) and interpolated in amplitude and unwrapped phase,
which is smooth; the horn pattern is then applied along each pixel's ray.
A Gaussian beam is summed directly.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np

from .dipole import Dipole
from .dyadic import RadialDyadic
from .green import free_space_green, layered_green, transmitted_profiles
from .medium import Medium
from .sources import GaussianBeam, PlaneWave, PointSource, ray_direction

__all__ = ["incident_on_plane", "incident_on_planes", "incident_phasors", "remove_incident_phase"]

_RADIAL_STEP_WAVELENGTHS = 1 / 16


def incident_on_plane(source: object, k: float, medium: Medium, x: np.ndarray, y: np.ndarray,
                      z: float) -> np.ndarray:
    """Incident field ``E0`` of ``source`` on the grid ``(y, x)`` at range ``z``.

    Parameters
    ----------
    source : PlaneWave, PointSource or GaussianBeam
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
    x, y : ndarray
        Pixel coordinates, metres.
    z : float
        Range of the plane, metres.

    Returns
    -------
    ndarray, shape (y.size, x.size)

    Examples
    --------
    >>> e = incident_on_plane(PlaneWave(), 200.0, Medium.free_space(), np.zeros(2),
    ...                       np.zeros(1), 0.1)
    >>> np.round(e, 6)
    array([[0.408082+0.912945j, 0.408082+0.912945j]])
    """
    X, Y = np.meshgrid(np.asarray(x, float), np.asarray(y, float))
    if isinstance(source, PlaneWave | GaussianBeam):
        pts = np.stack([X.ravel(), Y.ravel(), np.full(X.size, z)], axis=1)
        return source.field(k, medium, pts).reshape(X.shape)
    if isinstance(source, Dipole):
        return _dipole_on_plane(source, k, medium, X, Y, z)
    if not isinstance(source, PointSource):
        raise ValueError(f"source must be a PlaneWave, PointSource, Dipole or GaussianBeam, "
                         f"got {type(source).__name__}")
    source._check_air(medium)  # a radiator below the surface is refused, as elsewhere
    src = source.position
    rho = np.hypot(X - src[0], Y - src[1])
    n = abs(medium.n(medium.region_of(z)))
    step = 2 * np.pi / (k * n) * _RADIAL_STEP_WAVELENGTHS
    r = np.arange(0.0, rho.max() + 2 * step, step)
    line = np.stack([src[0] + r, np.full(r.size, src[1]), np.full(r.size, z)], axis=1)
    g = (free_space_green(k, src, line) if medium.is_free_space
         else layered_green(k, medium, src, line))
    amp = np.interp(rho, r, np.abs(g))
    phase = np.interp(rho, r, np.unwrap(np.angle(g)))
    e0 = source.amplitude * amp * np.exp(1j * phase)
    if source.has_pattern:
        pts = np.stack([X.ravel(), Y.ravel(), np.full(X.size, z)], axis=1)
        e0 = e0 * source.pattern(ray_direction(k, medium, src, pts)).reshape(X.shape)
    return e0


def _dipole_on_plane(source: Dipole, k: float, medium: Medium, X: np.ndarray, Y: np.ndarray,
                     z: float) -> np.ndarray:
    """A dipole's field along its axis on a plane: the dyadic's radial table in the
    ground (one Sommerfeld quadrature for the plane), the closed form in the air."""
    source._check_air(medium)
    off = np.stack([X.ravel() - source.position[0], Y.ravel() - source.position[1]], axis=1)
    if medium.is_free_space or medium.region_of(float(z)) == 0:
        pts = np.c_[X.ravel(), Y.ravel(), np.full(X.size, z)]
        return source.field(k, medium, pts).reshape(X.shape)
    rho_max = float(np.hypot(off[:, 0], off[:, 1]).max(initial=0.0))
    G = RadialDyadic(k, medium, float(source.position[2]), float(z), rho_max)(off)
    return (source.amplitude * (G @ source.moment) @ source.polarization).reshape(X.shape)


def incident_on_planes(source: object, k: float, medium: Medium, x: np.ndarray, y: np.ndarray,
                       z: np.ndarray) -> np.ndarray:
    """:func:`incident_on_plane` on several ranges at once, shape (len(z), y.size, x.size).

    For a point source in layered ground the radial profiles of all planes come
    from one Sommerfeld quadrature (:func:`~holoradar.physics.green.transmitted_profiles`).

    Examples
    --------
    >>> m = Medium.half_space(0.3, 2.5)
    >>> src = PointSource((0.0, -0.2, 0.0))
    >>> xs = np.linspace(-0.1, 0.1, 5)
    >>> a = incident_on_planes(src, 200.0, m, xs, xs, np.array([0.35, 0.4]))
    >>> b = incident_on_plane(src, 200.0, m, xs, xs, 0.4)
    >>> bool(np.allclose(a[1], b, rtol=1e-9))
    True
    """
    zs = np.atleast_1d(np.asarray(z, dtype=float))
    if not isinstance(source, PointSource) or medium.is_free_space:
        return np.stack([incident_on_plane(source, k, medium, x, y, float(zj)) for zj in zs])
    source._check_air(medium)
    X, Y = np.meshgrid(np.asarray(x, float), np.asarray(y, float))
    src = source.position
    rho = np.hypot(X - src[0], Y - src[1])
    n = max(abs(medium.n(m)) for m in range(medium.n_regions))
    step = 2 * np.pi / (k * n) * _RADIAL_STEP_WAVELENGTHS
    r = np.arange(0.0, rho.max() + 2 * step, step)
    prof = transmitted_profiles(k, medium, float(src[2]), zs, r)
    out = np.empty((zs.size, *X.shape), complex)
    for j, zj in enumerate(zs):
        amp = np.interp(rho, r, np.abs(prof[j]))
        phase = np.interp(rho, r, np.unwrap(np.angle(prof[j])))
        e0 = source.amplitude * amp * np.exp(1j * phase)
        if source.has_pattern:
            pts = np.stack([X.ravel(), Y.ravel(), np.full(X.size, zj)], axis=1)
            e0 = e0 * source.pattern(ray_direction(k, medium, src, pts)).reshape(X.shape)
        out[j] = e0
    return out


def incident_phasors(sources: list[object], k: float, medium: Medium, x: np.ndarray,
                     y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Unit phasors ``conj(E0)/|E0|`` of several sources on the same planes (0 where
    ``E0`` vanishes), shape (len(sources), len(z), y.size, x.size).

    This is what multi-view synthesis multiplies each view's image by
    (:func:`remove_incident_phase` does it in place, one plane at a time, without
    this array). Point sources at one height above layered ground share one
    Sommerfeld quadrature (:func:`~holoradar.physics.green.transmitted_profiles`
    on a radial grid long enough for all of them): their radial profiles differ
    only by the lateral shift of the source. Other sources go through
    :func:`incident_on_plane` plane by plane.

    Parameters
    ----------
    sources : list of PlaneWave, PointSource or GaussianBeam
        The views' illuminations (complex amplitudes included in the phase).
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
    x, y : ndarray
        Pixel coordinates, metres.
    z : float or ndarray
        Ranges of the planes, metres.

    Returns
    -------
    ndarray, complex, shape (len(sources), len(z), y.size, x.size)

    Examples
    --------
    >>> m = Medium.half_space(0.3, 2.5)
    >>> srcs = [PointSource((0.0, -0.2, 0.0)), PointSource((0.1, 0.2, 0.0))]
    >>> xs = np.linspace(-0.1, 0.1, 5)
    >>> u = incident_phasors(srcs, 200.0, m, xs, xs, np.array([0.4]))
    >>> e = incident_on_plane(srcs[1], 200.0, m, xs, xs, 0.4)
    >>> bool(np.allclose(u[1, 0], e.conj() / abs(e), atol=1e-9))
    True
    """
    zs = np.atleast_1d(np.asarray(z, dtype=float))
    out = np.empty((len(sources), zs.size, np.size(y), np.size(x)), complex)
    for i, plane in enumerate(_phasor_makers(sources, k, medium, x, y, zs)):
        for j in range(zs.size):
            out[i, j] = plane(j)
    return out


def remove_incident_phase(images: np.ndarray, sources: list[object], k: float,
                          medium: Medium, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> None:
    """Multiply ``images[i, j]`` (len(sources), len(z), y.size, x.size) in place by
    source i's unit phasor ``conj(E0)/|E0|`` on the plane at range ``z[j]``.

    The same phasors as :func:`incident_phasors`, made one plane at a time (a depth
    sweep of many views never holds them all).

    Parameters
    ----------
    images : ndarray, complex, shape (len(sources), len(z), y.size, x.size)
        Changed in place.
    sources, k, medium, x, y, z
        As for :func:`incident_phasors` (rad/m, metres).

    Raises
    ------
    ValueError
        ``images`` of another shape.

    Examples
    --------
    >>> m = Medium.half_space(0.3, 2.5)
    >>> srcs = [PointSource((0.0, -0.2, 0.0))]
    >>> xs = np.linspace(-0.1, 0.1, 5)
    >>> e = incident_on_plane(srcs[0], 200.0, m, xs, xs, 0.4)
    >>> img = e[None, None].copy()
    >>> remove_incident_phase(img, srcs, 200.0, m, xs, xs, np.array([0.4]))
    >>> bool(np.allclose(img, abs(e), atol=1e-9))
    True
    """
    zs = np.atleast_1d(np.asarray(z, dtype=float))
    want = (len(sources), zs.size, np.size(y), np.size(x))
    if images.shape != want:
        raise ValueError(f"images must have shape (sources, planes, y, x) = {want}, got "
                         f"{images.shape}")
    for i, plane in enumerate(_phasor_makers(sources, k, medium, x, y, zs)):
        for j in range(zs.size):
            images[i, j] *= plane(j)


def _phasor_makers(sources: list[object], k: float, medium: Medium, x: np.ndarray,
                   y: np.ndarray, zs: np.ndarray) -> list[Callable[[int], np.ndarray]]:
    """For each source, a function of the plane index giving its unit phasor there
    (y.size, x.size); what the sources share is computed here, once."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    makers: list[Callable[[int], np.ndarray] | None] = [None] * len(sources)
    shared: dict[float, list[int]] = {}
    for i, src in enumerate(sources):
        if isinstance(src, PointSource) and not medium.is_free_space:
            src._check_air(medium)
            shared.setdefault(round(float(src.position[2]), 12), []).append(i)
        else:
            makers[i] = functools.partial(_direct_phasor, src, k, medium, x, y, zs)
    if shared:
        X, Y = np.meshgrid(x, y)
        n = max(abs(medium.n(m)) for m in range(medium.n_regions))
        step = 2 * np.pi / (k * n) * _RADIAL_STEP_WAVELENGTHS
        for members in shared.values():
            srcs = [sources[i] for i in members]
            rhos = [np.hypot(X - s.position[0], Y - s.position[1]) for s in srcs]
            r = np.arange(0.0, max(float(p.max()) for p in rhos) + 2 * step, step)
            prof = transmitted_profiles(k, medium, float(srcs[0].position[2]), zs, r)
            phase = np.unwrap(np.angle(prof), axis=-1)
            amp = np.abs(prof) if not np.all(np.abs(prof) > 0) else None
            # Snell's law along the radial grid: the take-off angle depends only on rho
            # and on the heights, so it is the same for every source of the group.
            sin_line = ([_take_off_sines(k, medium, srcs[0].position, float(zj), r)
                         for zj in zs] if any(s.has_pattern for s in srcs) else [])
            for i, s, rho in zip(members, srcs, rhos, strict=True):
                makers[i] = functools.partial(_radial_phasor, s, zs, r, phase, amp, sin_line,
                                              rho, X, Y)
    return makers  # type: ignore[return-value]


def _direct_phasor(source: object, k: float, medium: Medium, x: np.ndarray, y: np.ndarray,
                   zs: np.ndarray, j: int) -> np.ndarray:
    return _unit(incident_on_plane(source, k, medium, x, y, float(zs[j])))


def _radial_phasor(source: PointSource, zs: np.ndarray, r: np.ndarray, phase: np.ndarray,
                   amp: np.ndarray | None, sin_line: list[np.ndarray], rho: np.ndarray,
                   X: np.ndarray, Y: np.ndarray, j: int) -> np.ndarray:
    # Only the phase is needed: one interpolation instead of two; the source's complex
    # amplitude is part of E0 and of its phase.
    u = np.exp(-1j * np.interp(rho, r, phase[j])) * _unit(np.asarray(complex(source.amplitude)))
    if amp is not None:  # the field vanishes somewhere on the radial grid
        u[np.interp(rho, r, amp[j]) == 0] = 0
    if source.has_pattern:
        dirs = _radial_directions(source, float(zs[j]), r, sin_line[j], rho, X, Y)
        u *= _unit(source.pattern(dirs)).reshape(X.shape)
    return u


def _take_off_sines(k: float, medium: Medium, src: np.ndarray, z: float,
                    r: np.ndarray) -> np.ndarray:
    """Sine of the angle, in the air, at which the refracted ray leaves ``src`` for a
    point at lateral distance ``r`` and range ``z`` (Snell's law, as ray_direction)."""
    line = np.stack([src[0] + r, np.full(r.size, src[1]), np.full(r.size, z)], axis=1)
    return ray_direction(k, medium, src, line)[:, 0]


def _radial_directions(source: PointSource, z: float, r: np.ndarray, sin_line: np.ndarray,
                       rho: np.ndarray, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Directions (N, 3) in which the refracted rays leave ``source`` for the pixels
    ``(X, Y, z)``: the take-off sines along the radial grid ``r`` interpolated at each
    pixel's lateral distance ``rho``, with the pixel's own azimuth. A pattern's phase (its
    sign, for the real patterns) is all the phasor needs: exact except next to the
    pattern's zeros."""
    src = source.position
    sin_t = np.interp(rho, r, sin_line)
    # cos and sin of the azimuth are (X - x_s)/rho and (Y - y_s)/rho (0 under the source).
    s_rho = np.divide(sin_t, rho, out=np.zeros_like(rho), where=rho > 0)
    cz = np.sqrt(np.clip(1 - sin_t**2, 0, None)) * (1.0 if z >= src[2] else -1.0)
    return np.stack([(s_rho * (X - src[0])).ravel(), (s_rho * (Y - src[1])).ravel(),
                     cz.ravel()], axis=1)


def _unit(e: np.ndarray) -> np.ndarray:
    """``conj(e)/|e|``, 0 where ``e`` is 0."""
    mag = np.abs(e)
    return np.divide(e.conj(), mag, out=np.zeros_like(e), where=mag > 0)
