"""Removing the surface glare from one view: :func:`suppress_surface`.

Holds the public entry point with its report (:class:`SuppressionReport`) and
warning (:class:`FitWarning`), the ``"cut"`` and ``"background"`` methods, the
mirror-plane image (the migration operator onto the mirror plane) and spot search
(``_mirror_*``, ``_find_spot``) and the argument checks (``_check``); the model fits
live in :mod:`.beams` and :mod:`.image_source`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from ...data.hologram import Hologram
from ...physics.dipole import Dipole
from ...physics.medium import Medium
from ...physics.sources import GaussianBeam, PointSource
from ...theory import lateral_resolution
from ..migration.image import Migration
from ..migration.settings import MigrationSettings
from ._common import _joint_direct, _require_direct_wave, direct_wave, recorded_polarization
from .beams import _eps_from_gaussian, _fit_gaussian
from .image_source import _fit_image_source

__all__ = ["FitWarning", "SuppressionReport", "suppress_surface"]

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


def _mirror_operator(h: Hologram, z_m: float) -> Migration:
    """Free-space migration to the mirror plane z_m over the whole padded grid (the
    mirror source may lie beside the array), in double precision."""
    return Migration(h, z_m, None, MigrationSettings(fov="full", compensate_loss=False,
                                                     dtype=np.complex128, progress=False))


def _mirror_image(op: Migration, data: np.ndarray) -> np.ndarray:
    """The mirror plane's image of ``data`` (its grid: ``op.x``, ``op.y``)."""
    return op.adjoint(data)


def _find_spot(op: Migration, E: np.ndarray, guess: np.ndarray,
               radius: float) -> tuple[float, float, float]:
    """Peak of |E| within ``radius`` of the predicted mirror position."""
    gx, gy = op.x, op.y
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
    if method != "background" and not isinstance(source, PointSource | GaussianBeam | Dipole):
        raise ValueError(f"method {method!r} needs the radiator as a PointSource, a Dipole or "
                         "a GaussianBeam (its mirror image focuses); for a plane wave the glare "
                         "is a plane wave: use method='background'")
    z0 = medium.z_interfaces[0]
    if method != "background" and isinstance(source, PointSource | Dipole) \
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
                     initial: dict[str, Any] | None = None,
                     exact_eps: bool = False) -> tuple[Hologram, SuppressionReport]:
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
        See :mod:`holoradar.imaging.glare`.
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
    exact_eps : bool
        ``"gaussian"`` with a point radiator or dipole: take the report's ``eps`` and
        ``eps_std`` from the exact image-source fit of the same data (what
        :func:`~holoradar.estimate_permittivity` does; about as long again as the
        Gaussian fit) instead of the beam's strength, which is rough (no
        uncertainty; 5-15 % off where the beam shape does not match the radiator's
        glare). The Gaussian's own estimate is then ``parameters["eps_gaussian"]``.
        The amplitude reference is the Gaussian's: the direct wave where one was found
        in the data, else ``reference_amplitude`` or the source's. Default False
        (the cleaned hologram is the same either way).

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
    xs, ys, peak_before = _find_spot(op, E_before, predicted, 3 * cell)
    pol = recorded_polarization(hologram, src)
    D = direct_wave(src, k, pts, pol) if direct else None
    h = data.ravel()
    if D is not None and method == "image_source":
        _require_direct_wave(D, h)
    report_kw: dict[str, Any] = {"mirror_plane": z_m}
    if method == "cut":
        r = cut_radius if cut_radius is not None else 1.5 * cell
        if cut_radius is None and isinstance(src, GaussianBeam):
            # the reflected beam's spot is its waist blurred by the aperture: cover
            # two waists (the beam's amplitude there is e^-4, -35 dB)
            r = float(np.hypot(1.5 * cell, 2 * src.waist))
        gx, gy = op.x, op.y
        dist = np.hypot(gx[None, :] - xs, gy[:, None] - ys)
        if taper:
            mask = np.clip((1.5 * r - dist) / (0.5 * r), 0, 1)
            mask = 0.5 - 0.5 * np.cos(np.pi * mask)
        else:
            mask = (dist <= r).astype(float)
        def bite(v: np.ndarray) -> np.ndarray:
            # The masked spot carried back to the aperture: the operator's forward map.
            return op.forward(_mirror_image(op, v.reshape(data.shape)) * mask).ravel()

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
            gx, gy = op.x, op.y
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
            lambda v: v.reshape(data.shape), pol)
        report_kw.update(mirror_position=tuple(src.mirror_position(medium)),
                         amplitude=fit["a"], phase=float(np.angle(fit["a"])),
                         eps=fit["eps"], eps_std=fit["eps_std"])
        converged, params = fit["converged"], fit
    cleaned = h - glare - direct_part
    E_after = _mirror_image(op, cleaned.reshape(data.shape))
    _, _, peak_after = _find_spot(op, E_after, np.array([xs, ys]), 0.5 * cell)
    left = float(np.sum(np.abs(cleaned) ** 2))
    report_kw.update(
        glare_suppression_db=2 * _db(peak_before, peak_after),  # amplitudes: 20 log10
        glare_removed_db=_db(float(np.sum(np.abs(glare) ** 2)), left),
        direct_removed_db=None if D is None else _db(float(np.sum(np.abs(direct_part) ** 2)),
                                                     left),
        direct_amplitude=dcoef, converged=converged, parameters=params)
    if method == "gaussian" and isinstance(src, PointSource | Dipole):
        # The radiator's amplitude: given, or the direct wave's when one was found (it
        # carries at least 1% of the hologram's energy), else the source's own.
        ref = reference_amplitude
        from_direct = ref is None and D is not None and dcoef is not None and bool(
            np.sum(np.abs(direct_part) ** 2) > 0.01 * np.sum(np.abs(h) ** 2))
        if from_direct:
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
        if exact_eps:
            report_kw["parameters"] = dict(params, eps_gaussian=eps)
            report_kw.update(_exact_eps(hologram, medium, src, complex(ref), from_direct))
    if not converged:
        warnings.warn(f"suppress_surface: the {method} fit did not converge; the glare may "
                      "be only partly removed", FitWarning, stacklevel=2)
    return hologram.with_data(cleaned.reshape(data.shape)), SuppressionReport(method,
                                                                               **report_kw)


def _exact_eps(hologram: Hologram, medium: Medium, src: Any, ref: complex,
               direct: bool) -> dict[str, Any]:
    """eps and its 1-sigma from the exact image-source fit (started from ``medium``'s
    eps), with the Gaussian's amplitude reference: the direct wave in the data, or
    ``ref``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitWarning)   # the caller's own fit says its own
        _, rep = suppress_surface(hologram, medium, src, "image_source", direct=direct,
                                  reference_amplitude=None if direct else ref)
    return {"eps": rep.eps, "eps_std": rep.eps_std}


def _world(pose: Any, x: float, y: float, z: float) -> tuple[float, float, float]:
    """A point of the aperture's frame (x, y along its axes, z along its normal) in
    the world."""
    w = pose.to_world(np.array(x), np.array(y)) + z * pose.normal
    return float(w[0]), float(w[1]), float(w[2])
