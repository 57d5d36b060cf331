"""Suppression of the surface glare (paper section 3.3, docs/glare.md).

The radiator's specular reflection from a flat ground is the wave of its mirror
image at range ``z_m = 2*z0 - z_s``: migrated through AIR it focuses there into a
compact bright spot, while buried objects stay defocused. Methods:

``"cut"``
    Migrate to z_m (the whole padded grid: the spot may lie beside the array),
    mask the spot with a hard disk or a raised-cosine taper, propagate the masked
    part back to the aperture and subtract it (paper's "biting off"). The sharp
    edge leaves parasitic ripples (paper Fig. 14c).
``"gaussian"``
    Fit a Gaussian beam to the glare and subtract it. The beam is the exact
    complex-source-point beam ``exp(i*k*Rc)/Rc`` with
    ``Rc = sqrt((x - xc)^2 + (y - yc)^2 + (zc - i*b)^2)``: waist
    ``w0 = sqrt(2*b/k)`` at range zc, a spherical wave from the mirror image when
    b -> 0. It is evaluated on the array's elements, i.e. as seen through the
    finite rectangular aperture, and fitted there (centre, range, waist, complex
    amplitude) by least squares; subtracting it from the hologram equals
    subtracting its aperture-limited image at z_m and propagating back.
``"image_source"``
    The physical model: the exact reflected field of the source from the layered
    ground (Sommerfeld integral with the angle-dependent reflection coefficient,
    :func:`~holoradar.physics.green.layered_green`), with the ground's
    permittivity and the source's complex amplitude fitted. It yields the
    permittivity of the top layer with its uncertainty.
``"background"``
    Subtract a measured or simulated hologram of the empty scene.

The radiator's direct wave into the aperture (its own spherical wave times its
pattern, known in shape) is fitted jointly, with a free complex amplitude, and
removed too (``direct=True``). It would focus at the radiator's own range, which
is usually the aperture plane or behind it, where no image can be formed.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
import scipy.fft as sfft
from scipy.optimize import brentq, least_squares

from ..analysis.theory import lateral_resolution
from ..data.hologram import Hologram
from ..physics.medium import Medium
from ..physics.propagation import AngularSpectrum
from ..physics.sources import GaussianBeam, PointSource

__all__ = ["FitWarning", "SuppressionReport", "estimate_permittivity", "suppress_surface"]

Method = Literal["gaussian", "cut", "image_source", "background"]


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


def _db(a: float, b: float) -> float:
    return float(10 * np.log10(max(a, 1e-300) / max(b, 1e-300)))


def _mirror_operator(h: Hologram, z_m: float) -> AngularSpectrum:
    dx, dy = h.pitch
    return AngularSpectrum(h.data.shape[-2:], dx, dy, h.k, z_m, None, True)


def _mirror_image(op: AngularSpectrum, data: np.ndarray) -> np.ndarray:
    """Free-space back-propagation to z_m on the whole padded grid (no crop)."""
    H = op.spectrum(data)
    return sfft.ifft2(H * op.adjoint_transfers[0], axes=(-2, -1), workers=op.workers)


def _grid_coords(h: Hologram, op: AngularSpectrum) -> tuple[np.ndarray, np.ndarray]:
    """Coordinates of the padded grid's samples, unwrapped around the aperture."""
    My, Mx = op.fft_shape
    dx, dy = h.pitch
    ix = np.arange(Mx)
    iy = np.arange(My)
    ix = np.where(ix < Mx - (Mx - h.x.size) // 2, ix, ix - Mx)
    iy = np.where(iy < My - (My - h.y.size) // 2, iy, iy - My)
    return h.x[0] + ix * dx, h.y[0] + iy * dy


def _find_spot(h: Hologram, op: AngularSpectrum, E: np.ndarray, guess: np.ndarray,
               radius: float) -> tuple[float, float, float]:
    """Peak of |E| within ``radius`` of the predicted mirror position."""
    gx, gy = _grid_coords(h, op)
    a = np.abs(E.reshape((-1, *E.shape[-2:]))).max(axis=0)
    near = np.hypot(gx[None, :] - guess[0], gy[:, None] - guess[1]) <= radius
    if not near.any():
        raise ValueError("the mirror image lies outside the imaged grid; pad more")
    iy, ix = np.unravel_index(int(np.argmax(np.where(near, a, -1))), a.shape)
    return float(gx[ix]), float(gy[iy]), float(a[iy, ix])


def _check(hologram: Hologram, medium: Medium, source: object, method: str) -> None:
    if not isinstance(hologram, Hologram):
        raise ValueError(f"hologram must be a holoradar.Hologram, got {type(hologram).__name__}")
    if not isinstance(medium, Medium) or medium.is_free_space:
        raise ValueError("medium must be a holoradar.Medium with a ground surface (not free "
                         "space): the glare is the reflection from that surface")
    if method not in ("gaussian", "cut", "image_source", "background"):
        raise ValueError("method must be 'gaussian', 'cut', 'image_source' or 'background', "
                         f"got {method!r}")
    if method != "background" and not isinstance(source, PointSource | GaussianBeam):
        raise ValueError(f"method {method!r} needs the radiator as a PointSource or a "
                         "GaussianBeam (its mirror image focuses); for a plane wave the glare "
                         "is a plane wave: use method='background'")
    z0 = medium.z_interfaces[0]
    if method != "background" and isinstance(source, PointSource) \
            and float(source.position[2]) >= z0:
        raise ValueError(f"source range {float(source.position[2])} m must lie above the "
                         f"ground surface ({z0} m)")
    if method != "background" and isinstance(source, GaussianBeam) \
            and float(source.center[2]) > z0:
        raise ValueError(f"source: the beam's waist (range {float(source.center[2])} m) must "
                         f"not lie below the ground surface ({z0} m)")


def suppress_surface(hologram: Hologram, medium: Medium, source: Any = None,
                     method: Method = "gaussian", *, background: Hologram | None = None,
                     direct: bool = True, cut_radius: float | None = None, taper: bool = True,
                     reference_amplitude: complex | None = None,
                     fit_domain: Literal["mirror", "aperture"] = "aperture",
                     initial: dict[str, Any] | None = None) -> tuple[Hologram, SuppressionReport]:
    """Remove the surface glare (and the direct wave) from a hologram.

    Parameters
    ----------
    hologram : Hologram
        One view, on a uniform grid.
    medium : Medium
        The ground (its surface range z0 sets the mirror plane).
    source : PointSource or GaussianBeam, optional
        The radiator; default ``hologram.source``. A Gaussian beam's glare is the
        beam reflected by the stack (each plane-wave component with its own
        reflection coefficient): a beam from the mirror image of its waist,
        travelling along the mirrored axis; its incoming beam crossing the array
        is the direct wave. For a Gaussian beam ``"gaussian"`` reports no eps (the
        beam's own amplitude is not a point source's): use ``"image_source"``.
    method : {"gaussian", "cut", "image_source", "background"}
        See the module docstring.
    background : Hologram, optional
        The empty-scene hologram, for ``"background"``.
    direct : bool
        Also fit and remove the radiator's direct wave (default True). With
        ``"image_source"`` it is then the amplitude reference of the glare and must
        be in the data; without it, say ``direct=False`` (the reference is then
        ``reference_amplitude`` or ``source.amplitude``).
    cut_radius : float, optional
        ``"cut"``: radius of the mask, metres (default 1.5 resolution cells,
        ``1.5*lambda*z_m/A``).
    taper : bool
        ``"cut"``: raised-cosine edge from ``cut_radius`` to ``1.5*cut_radius``
        (default) instead of a hard edge.
    reference_amplitude : complex, optional
        The radiator's complex amplitude, default ``source.amplitude`` (a
        calibration); ``report.direct_amplitude`` of a previous call is the
        direct-path reference. It turns the glare's strength into the reflection
        coefficient V and the permittivity (``"gaussian"``). ``"image_source"``
        with ``direct=True`` takes the direct wave in the data as its reference.
    fit_domain : {"aperture", "mirror"}
        ``"gaussian"``: fit the beam on the elements themselves (default; no
        FFT), or in a window of 2 resolution cells around the spot in the mirror
        plane (the paper's way). The window keeps distant objects out of the
        fit but not a buried planar reflector under the horn, whose own specular
        focus lies within the depth resolution of the glare's: there it is
        mostly spot-like too, and the fit takes part of it (the paper's lab stand
        simulated in ``examples/paper_figures.py``: 15.7 dB of glare removed and
        the letter damaged, against 22.2 dB and the letter kept on the elements).
    initial : dict, optional
        ``report.parameters`` of a previous frame, to warm-start the fit.

    Returns
    -------
    cleaned : Hologram
    report : SuppressionReport

    Raises
    ------
    ValueError
        No surface, no point radiator for a model method, mismatched background.

    Warns
    -----
    FitWarning
        When a fit does not converge or explains little of the data.

    Examples
    --------
    >>> import holoradar as hr
    >>> sand = hr.Medium.half_space(0.3, 2.5)
    >>> horn = hr.PointSource((0.0, 0.0, -0.05))
    >>> scene = hr.Scene(sand, horn, [hr.PointTarget((0.05, 0.0, 0.42), 0.01)])
    >>> h = hr.simulate(scene, hr.Aperture.grid(32, 0.0125), 9.9e9)
    >>> clean, rep = suppress_surface(h, sand)
    >>> rep.glare_suppression_db > 20
    True
    """
    src = source if source is not None else getattr(hologram, "source", None)
    if src is None and method != "background":
        raise ValueError("source must be given (the radiator as a PointSource or a "
                         "GaussianBeam), or carried "
                         "by the hologram (Hologram(..., source=...))")
    if fit_domain not in ("aperture", "mirror"):
        raise ValueError(f"fit_domain must be 'aperture' or 'mirror', got {fit_domain!r}")
    if cut_radius is not None and not (np.isfinite(cut_radius) and cut_radius > 0):
        raise ValueError(f"cut_radius must be a radius > 0 in metres, got {cut_radius!r}")
    if initial is not None:
        need = {"gaussian": {"x", "y", "b"}, "image_source": {"eps"}}.get(method, set())
        if not isinstance(initial, dict) or not need <= set(initial):
            raise ValueError(f"initial must be the parameters dict of a previous {method!r} "
                             f"report (keys {sorted(need)}), got {initial!r}")
    _check(hologram, medium, src, method)
    data = hologram.data
    pose = hologram.pose
    if method != "background":
        # Everything below happens in the aperture's own frame (x, y along its
        # axes, z' along its normal): the mirror image's spherical wave focuses, in
        # free space, at its own coordinates there, for any tilt (frontal: the
        # mirror plane z_m = 2 z0 - z_s).
        mirror_local = pose.to_local(src.mirror_position(medium))
        z_m = float(mirror_local[2])
        if z_m <= 0:
            raise ValueError("hologram.pose: the source's mirror image in the surface lies "
                             "behind the aperture's plane, where no image of it forms; "
                             "use method='background'")
    if method == "background":
        if not isinstance(background, Hologram):
            raise ValueError("background must be the empty-scene Hologram for method "
                             "'background'")
        if background.data.shape != data.shape or not (
                np.allclose(background.x, hologram.x) and np.allclose(background.y, hologram.y)):
            raise ValueError("background must be sampled on the hologram's grid, with the "
                             f"same shape {data.shape}")
        if not np.isclose(background.frequency, hologram.frequency, rtol=1e-9, atol=0):
            raise ValueError("background must be at the hologram's frequency")
        cleaned = data - background.data
        return hologram.with_data(cleaned), SuppressionReport(
            "background", glare_removed_db=_db(np.sum(np.abs(background.data) ** 2),
                                               np.sum(np.abs(cleaned) ** 2)))
    if data.ndim != 2:
        raise ValueError(f"suppress_surface takes one view (ny, nx), got shape {data.shape}")
    k = hologram.k
    pts = hologram.points                      # world: the direct wave, the image source
    X, Y = np.meshgrid(hologram.x, hologram.y)
    local = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)   # the beam fit
    op = _mirror_operator(hologram, z_m)
    A = hologram.aperture_size
    cell = lateral_resolution(hologram.wavelength, z_m, min(A))
    predicted = mirror_local[:2]
    E_before = _mirror_image(op, data)
    xs, ys, peak_before = _find_spot(hologram, op, E_before, predicted, 3 * cell)
    D = _direct_wave(src, k, pts) if direct else None
    h = data.ravel()
    report_kw: dict[str, Any] = {"mirror_plane": z_m}
    if method == "cut":
        r = cut_radius if cut_radius is not None else 1.5 * cell
        if cut_radius is None and isinstance(src, GaussianBeam):
            # the reflected beam's spot is its waist blurred by the aperture: cover
            # two waists (the beam's amplitude there is e^-4, -35 dB)
            r = float(np.hypot(1.5 * cell, 2 * src.waist))
        gx, gy = _grid_coords(hologram, op)
        dist = np.hypot(gx[None, :] - xs, gy[:, None] - ys)
        if taper:
            mask = np.clip((1.5 * r - dist) / (0.5 * r), 0, 1)
            mask = 0.5 - 0.5 * np.cos(np.pi * mask)
        else:
            mask = (dist <= r).astype(float)
        def bite(v: np.ndarray) -> np.ndarray:
            E = _mirror_image(op, v.reshape(data.shape))
            back = sfft.ifft2(sfft.fft2(E * mask, workers=op.workers) * op.transfers[0],
                              workers=op.workers)
            return back[:data.shape[0], :data.shape[1]].ravel()

        glare = bite(h)
        dcoef, glare, direct_part = _joint_direct(h, glare, D)
        if D is not None:
            # The direct wave leaves part of itself in the masked spot: take it out
            # first and bite again (a second pass changes the result by the direct
            # wave's share of the spot, no more).
            glare = bite(h - direct_part)
            dcoef, glare, direct_part = _joint_direct(h, glare, D)
        report_kw.update(mirror_position=_world(pose, xs, ys, z_m), waist=r, amplitude=None)
        converged, params = True, {"x": xs, "y": ys}
    elif method == "gaussian":
        transform = None
        if fit_domain == "mirror":
            gx, gy = _grid_coords(hologram, op)
            window = np.hypot(gx[None, :] - xs, gy[:, None] - ys) <= 2 * cell

            def transform(v: np.ndarray) -> np.ndarray:
                return _mirror_image(op, v.reshape(data.shape))[window]

        u_beam, b0 = None, None
        if isinstance(src, GaussianBeam):
            # The reflected beam's axis (the incident one mirrored), in the aperture's
            # frame, and its waist: the fit starts from them and lets the waist vary.
            d = src.direction * np.array([1.0, 1.0, -1.0])
            u_beam = np.array([d @ pose.u, d @ pose.v, d @ pose.normal])
            b0 = k * src.waist**2 / 2
        glare, direct_part, dcoef, fit = _fit_gaussian(k, local, h, D, xs, ys, z_m, cell,
                                                       initial, transform, u_beam, b0)
        xc, yc, zc, b = fit["x"], fit["y"], fit["z"], fit["b"]
        report_kw.update(mirror_position=_world(pose, xc, yc, zc), amplitude=fit["a"],
                         phase=float(np.angle(fit["a"])), waist=float(np.sqrt(2 * b / k)))
        converged, params = fit["converged"], fit
    else:  # image_source
        glare, direct_part, dcoef, fit = _fit_image_source(
            k, medium, src, pts, h, D, reference_amplitude, initial,
            lambda v: v.reshape(data.shape))
        report_kw.update(mirror_position=tuple(src.mirror_position(medium)),
                         amplitude=fit["a"], phase=float(np.angle(fit["a"])),
                         eps=fit["eps"], eps_std=fit["eps_std"])
        converged, params = fit["converged"], fit
    cleaned = h - glare - direct_part
    E_after = _mirror_image(op, cleaned.reshape(data.shape))
    _, _, peak_after = _find_spot(hologram, op, E_after, np.array([xs, ys]), 0.5 * cell)
    left = float(np.sum(np.abs(cleaned) ** 2))
    report_kw.update(
        glare_suppression_db=2 * _db(peak_before, peak_after),  # amplitudes: 20 log10
        glare_removed_db=_db(float(np.sum(np.abs(glare) ** 2)), left),
        direct_removed_db=None if D is None else _db(float(np.sum(np.abs(direct_part) ** 2)),
                                                     left),
        direct_amplitude=dcoef, converged=converged, parameters=params)
    if method == "gaussian" and isinstance(src, PointSource):
        # The radiator's amplitude: given, or the direct wave's when one was found (it
        # carries at least 1% of the hologram's energy), else the source's own.
        ref = reference_amplitude
        if ref is None and D is not None and dcoef is not None and (
                np.sum(np.abs(direct_part) ** 2) > 0.01 * np.sum(np.abs(h) ** 2)):
            ref = dcoef
        if ref is None:
            ref = src.amplitude
        V, eps = _eps_from_gaussian(report_kw["amplitude"], params["b"], complex(ref), src,
                                    hologram, medium, k)
        if not np.isfinite(eps.real):
            warnings.warn("suppress_surface: the glare is stronger than the reference "
                          "amplitude allows (|V| >= 1): give reference_amplitude (a "
                          "calibration of the radiator) to estimate eps", FitWarning,
                          stacklevel=2)
        report_kw.update(reflection_coefficient=V, eps=eps)
    if not converged:
        warnings.warn(f"suppress_surface: the {method} fit did not converge; the glare may "
                      "be only partly removed", FitWarning, stacklevel=2)
    return hologram.with_data(cleaned.reshape(data.shape)), SuppressionReport(method,
                                                                               **report_kw)


def _direct_wave(src: PointSource | GaussianBeam, k: float, pts: np.ndarray) -> np.ndarray:
    """The radiator's own wave at air points, for unit amplitude: ``exp(ikR)/R`` times its
    pattern along the straight ray, or the incoming Gaussian beam (the shape the
    direct-wave fit scales)."""
    return replace(src, amplitude=1.0).field(k, Medium.free_space(), pts)


def _joint_direct(h: np.ndarray, glare: np.ndarray, D: np.ndarray | None
                  ) -> tuple[complex | None, np.ndarray, np.ndarray]:
    """Fit the direct wave's amplitude to what the glare leaves."""
    if D is None:
        return None, glare, np.zeros_like(h)
    rest = h - glare
    d = complex(np.vdot(D, rest) / np.vdot(D, D))
    return d, glare, d * D


def _linear_fit(h: np.ndarray, basis: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares complex coefficients of ``basis`` columns; returns (coef, model)."""
    B = np.stack(basis, axis=1)
    coef, *_ = np.linalg.lstsq(B, h, rcond=None)
    return coef, B @ coef


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


def _fit_gaussian(k: float, pts: np.ndarray, h: np.ndarray, D: np.ndarray | None, xs: float,
                  ys: float, z_m: float, cell: float, initial: dict[str, Any] | None,
                  transform: Callable[[np.ndarray], np.ndarray] | None = None,
                  u: np.ndarray | None = None, b0: float | None = None):
    """Fit ``a*beam + d*D`` to the data, in the domain ``transform`` maps them to.

    ``transform`` is the windowed image of the mirror plane (the paper's choice:
    there the glare is a compact spot and buried objects are defocused); ``None``
    fits on the elements themselves.
    """
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
    sol = least_squares(resid, np.clip(np.zeros(3), lo, hi), bounds=(lo, hi), xtol=1e-10,
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


def _sandwich_std(fun: np.ndarray, jac: np.ndarray, shape: tuple[int, int]
                  ) -> tuple[float, float]:
    """1-sigma of least-squares parameters when the residual is spatially correlated.

    What the glare model leaves is mostly the object's own field and the noise:
    smooth over the aperture, not white, so ``s^2 (J^T J)^-1`` would be far too
    optimistic. The sandwich (Huber-White / Newey-West) estimator
    ``B^-1 M B^-1``, ``B = Re(J^H J)``, ``M = Cov(Re(J^H r)) = Re(J^H S J)/2`` for a
    circular complex residual, uses the residual's covariance S, taken stationary
    and estimated from its autocorrelation over the aperture with a Bartlett lag
    window reaching half the aperture (Newey & West 1987): the raw all-lag
    estimate would give ``J^H S J ~ |J^H r|^2``, which vanishes at the fit.
    """
    n = fun.size // 2
    r = (fun[:n] + 1j * fun[n:]).reshape(shape)
    J = (jac[:n] + 1j * jac[n:]).reshape((*shape, -1))
    ny, nx = shape
    s = (2 * ny, 2 * nx)
    acf = sfft.ifft2(np.abs(sfft.fft2(r, s=s)) ** 2) / r.size  # lags in FFT order
    ly, lx = max(ny / 2, 2.0), max(nx / 2, 2.0)
    ty = np.abs(sfft.fftfreq(s[0], 1.0 / s[0]))
    tx = np.abs(sfft.fftfreq(s[1], 1.0 / s[1]))
    bartlett = np.outer(np.clip(1 - ty / ly, 0, None), np.clip(1 - tx / lx, 0, None))
    acf_spec = sfft.fft2(acf * bartlett)
    SJ = sfft.ifft2(sfft.fft2(J, s=s, axes=(0, 1)) * acf_spec[..., None], axes=(0, 1))
    SJ = SJ[:ny, :nx]
    Jf = J.reshape(-1, J.shape[-1])
    meat = 0.5 * np.real(Jf.conj().T @ SJ.reshape(-1, J.shape[-1]))
    bread = np.real(Jf.conj().T @ Jf)
    try:
        binv = np.linalg.inv(bread)
    except np.linalg.LinAlgError:
        return np.inf, np.inf
    cov = binv @ meat @ binv
    return float(np.sqrt(max(cov[0, 0], 0))), float(np.sqrt(max(cov[1, 1], 0)))


def _fit_image_source(k: float, medium: Medium, src: PointSource, pts: np.ndarray,
                      h: np.ndarray, D: np.ndarray | None, ref: complex | None,
                      initial: dict[str, Any] | None,
                      transform: Callable[[np.ndarray], np.ndarray]):
    """Fit the ground's permittivity from the exact reflected field.

    The glare's strength relative to the radiator's fixes |V|: the radiator's
    amplitude is either fitted jointly with the direct wave (one complex amplitude
    for both, since both are its fields: the direct path is the reference) or
    given (``ref``, a calibration). Fitting it freely for the glare alone would
    leave eps to the weak angle dependence of V across the aperture.
    """
    eps0 = complex(initial["eps"]) if initial and "eps" in initial else complex(medium.eps[1])

    def glare_of(e: np.ndarray) -> np.ndarray:
        eps = complex(max(e[0], 1e-3), max(e[1], 0.0))
        m = Medium(medium.z_interfaces, (1.0, eps, *medium.eps[2:]), medium.polarization)
        return replace(src, amplitude=1.0).reflected(k, m, pts)

    th = transform(h)
    tD = None if D is None else transform(D)

    def parts(e: np.ndarray) -> tuple[complex, np.ndarray, np.ndarray]:
        G = glare_of(e)
        tG = transform(G)
        if tD is not None and ref is None:
            basis = tD + tG
            a = complex(np.vdot(basis, th) / np.vdot(basis, basis))
        else:
            a = complex(ref if ref is not None else src.amplitude)
        return a, G, tG

    def resid(e: np.ndarray) -> np.ndarray:
        a, _, tG = parts(e)
        r = (th - a * tG - (0 if tD is None else a * tD)).ravel()
        return np.concatenate([r.real, r.imag])

    e_start = np.array([eps0.real, max(eps0.imag, 0.0)])
    sol = least_squares(resid, e_start, x_scale=np.array([0.1, 0.01]) * max(e_start[0], 1.0),
                        bounds=([1e-3, 0.0], [np.inf, np.inf]), xtol=1e-12, max_nfev=200)
    a, G, _ = parts(sol.x)
    std = _sandwich_std(sol.fun, sol.jac, th.shape)
    eps = complex(sol.x[0], sol.x[1])
    explained = 1 - np.sum(sol.fun**2) / max(np.sum(np.abs(h) ** 2), 1e-300)
    fit = {"eps": eps, "eps_std": std, "a": a,
           "converged": bool(sol.success and explained > 0.5)}
    dcoef = None if D is None else a
    return a * G, (np.zeros_like(h) if D is None else a * D), dcoef, fit


def _world(pose: Any, x: float, y: float, z: float) -> tuple[float, float, float]:
    """A point of the aperture's frame (x, y along its axes, z along its normal) in
    the world."""
    w = pose.to_world(np.array(x), np.array(y)) + z * pose.normal
    return float(w[0]), float(w[1]), float(w[2])


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
    return complex(V), complex(brentq(excess, 1.0 + 1e-9, 1e4, xtol=1e-10))


def estimate_permittivity(hologram: Hologram, medium: Medium, source: Any = None, *,
                          direct: bool = True) -> tuple[complex, tuple[float, float]]:
    """Permittivity of the ground's top layer from the glare, with its 1-sigma uncertainty.

    Fits the exact reflected field of the radiator (``method="image_source"``).
    The glare's strength against the radiator's fixes |V| and hence eps: the
    radiator's amplitude is the direct wave's, fitted jointly (``direct=True``,
    the direct-path reference; it must be in the data), or ``source.amplitude``
    (``direct=False``, a calibration). ``medium`` supplies the geometry and the
    starting value. The 1-sigma covers receiver noise and diffuse clutter (a
    sandwich estimate); it does not cover model error (a vector source seen as
    a scalar one) nor the bias of a single strong buried object, at most
    ``4 n |V| e / (1 + V)^2`` for an object ``e`` times weaker than the glare.

    Examples
    --------
    >>> import holoradar as hr
    >>> m = hr.Medium.half_space(0.3, 4.0)
    >>> h = hr.simulate(hr.Scene(m, hr.PointSource((0.0, 0.0, -0.05))),
    ...                 hr.Aperture.grid(24, 0.015), 9.9e9, include_direct=True)
    >>> eps, std = estimate_permittivity(h, hr.Medium.half_space(0.3, 3.0))
    >>> round(eps.real, 2)
    4.0
    """
    src = source if source is not None else getattr(hologram, "source", None)
    if direct and isinstance(src, PointSource | GaussianBeam):
        D = _direct_wave(src, hologram.k, hologram.points)
        h = hologram.data.ravel()
        share = abs(np.vdot(D, h)) ** 2 / (np.vdot(D, D).real * np.vdot(h, h).real)
        if share < 0.01:
            raise ValueError("direct=True takes the radiator's direct wave as the amplitude "
                             "reference, but the hologram holds almost none of it (the direct "
                             "wave explains <1% of it): pass direct=False with a calibrated "
                             "source amplitude")
    _, rep = suppress_surface(hologram, medium, source, "image_source", direct=direct)
    return rep.eps, rep.eps_std
