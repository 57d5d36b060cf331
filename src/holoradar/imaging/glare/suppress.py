"""Removing the surface glare from one view: :func:`suppress_surface`.

The entry point checks its arguments, subtracts a background where one is given, and
otherwise finds the mirror plane and the glare's spot (:class:`.spot.MirrorSpot`),
hands it to the method's own module (:mod:`.cut`, :mod:`.beams` for the Gaussian
beam, :mod:`.image_source`), and reports what was removed
(:class:`.report.SuppressionReport`).
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import Any, Literal

import numpy as np

from ...data.hologram import Hologram
from ...physics.dipole import Dipole
from ...physics.medium import Medium
from ...physics.sources import GaussianBeam, PointSource
from .beams import _eps_from_gaussian, remove_gaussian
from .cut import remove_cut
from .image_source import remove_image_source
from .report import FitWarning, GlareFit, SuppressionReport, db
from .spot import MirrorSpot, find_spot

__all__ = ["FitWarning", "SuppressionReport", "suppress_surface"]

Method = Literal["gaussian", "cut", "image_source", "background"]


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
    _check_arguments(hologram, medium, src, method, fit_domain, cut_radius, initial)
    if method == "background":
        return _subtract_background(hologram, background)
    spot = MirrorSpot.find(hologram, medium, src, direct)
    if method == "cut":
        fit = remove_cut(spot, cut_radius, taper)
    elif method == "gaussian":
        fit = remove_gaussian(spot, fit_domain, initial)
    else:
        fit = remove_image_source(spot, medium, reference_amplitude, initial)
    cleaned = spot.h - fit.glare - fit.direct_part
    report = {"mirror_plane": spot.z_m, **fit.report, **_removed(spot, fit, cleaned)}
    if method == "gaussian" and isinstance(src, PointSource | Dipole):
        report.update(_gaussian_eps(spot, fit, medium, reference_amplitude, exact_eps))
    if not fit.converged:
        warnings.warn(f"suppress_surface: the {method} fit did not converge; the glare may "
                      "be only partly removed", FitWarning, stacklevel=2)
    return hologram.with_data(cleaned.reshape(spot.shape)), SuppressionReport(method,
                                                                               **report)


def _removed(spot: MirrorSpot, fit: GlareFit, cleaned: np.ndarray) -> dict[str, Any]:
    """How much was removed: the spot's peak before and after (amplitudes: 20 log10),
    the glare's and the direct wave's energy against what is left."""
    _, _, peak_after = find_spot(spot.op, spot.image(cleaned), np.array([spot.xs, spot.ys]),
                                 0.5 * spot.cell)
    left = float(np.sum(np.abs(cleaned) ** 2))
    return {"glare_suppression_db": 2 * db(spot.peak_before, peak_after),
            "glare_removed_db": db(float(np.sum(np.abs(fit.glare) ** 2)), left),
            "direct_removed_db": None if spot.D is None else db(
                float(np.sum(np.abs(fit.direct_part) ** 2)), left),
            "direct_amplitude": fit.direct_amplitude, "converged": fit.converged,
            "parameters": fit.parameters}


def _gaussian_eps(spot: MirrorSpot, fit: GlareFit, medium: Medium,
                  reference_amplitude: complex | None, exact_eps: bool) -> dict[str, Any]:
    """V and eps from the Gaussian's strength against the radiator's amplitude: given,
    or the direct wave's when one was found (it carries at least 1% of the hologram's
    energy), else the source's own; with ``exact_eps``, eps and its 1-sigma from the
    exact image-source fit with that same reference."""
    h, src = spot.h, spot.src
    ref = reference_amplitude
    dcoef = fit.direct_amplitude
    from_direct = ref is None and spot.D is not None and dcoef is not None and bool(
        np.sum(np.abs(fit.direct_part) ** 2) > 0.01 * np.sum(np.abs(h) ** 2))
    if from_direct:
        ref = dcoef
    if ref is None:
        ref = src.amplitude
    V, eps = _eps_from_gaussian(fit.report["amplitude"], fit.parameters["b"], complex(ref),
                                src, spot.hologram, medium, spot.k)
    if not np.isfinite(eps.real):
        warnings.warn("suppress_surface: the glare is stronger than the reference "
                      "amplitude allows (|V| >= 1): give reference_amplitude (a "
                      "calibration of the radiator) to estimate eps", FitWarning,
                      stacklevel=3)
    out: dict[str, Any] = {"reflection_coefficient": V, "eps": eps}
    if exact_eps:
        out["parameters"] = dict(fit.parameters, eps_gaussian=eps)
        # The exact fit from the same spot, the direct wave the reference where it was
        # found, else ``ref`` (its own warnings are the caller's fit's to say).
        exact = replace(spot, D=spot.D if from_direct else None)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FitWarning)
            sol = remove_image_source(exact, medium, None if from_direct else complex(ref),
                                      None)
        out.update(eps=sol.report["eps"], eps_std=sol.report["eps_std"])
    return out


def _subtract_background(hologram: Hologram, background: Any
                         ) -> tuple[Hologram, SuppressionReport]:
    """The ``"background"`` method: the empty scene's hologram subtracted."""
    data = hologram.data
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
        "background", glare_removed_db=db(np.sum(np.abs(background.data) ** 2),
                                          np.sum(np.abs(cleaned) ** 2)))


def _check_arguments(hologram: Any, medium: Any, src: Any, method: Any, fit_domain: Any,
                     cut_radius: Any, initial: Any) -> None:
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
