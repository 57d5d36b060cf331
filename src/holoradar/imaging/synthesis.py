"""Multi-view synthesis: summing holograms taken with different illumination.

Each view k, lit by ``E0_k``, sees the object's spectrum through its own shifted
spectral window (paper section 3.1). Removing the view's incident phase at
the image plane, ``g_k * conj(E0_k)/|E0_k|``, puts every view in the frame of the
object; then

* ``"coherent"``: the views add as complex fields; the spectral windows add up
  to their union, and the point-spread function narrows accordingly;
* ``"amplitude"``: ``sum_k |g_k|``; needs no phase, gains no resolution,
  smooths speckle;
* ``"quasi-coherent"``: coherent after removing an unknown constant phase per
  view estimated from the data, for field data whose view-to-view phase
  reference drifts (:func:`align_phases`). Start: ``phi_k = arg <r, g'_k>``, the
  phase of the inner product of the view (incident phase removed) with the
  strongest view ``r`` (our reading of the paper's term). That inner product is,
  by Parseval, the overlap of the two views' spectra: views whose windows do not
  overlap leave it to leakage and noise. So the phases are then refined to
  maximise the sharpness ``sum |I|^4`` of the summed image (Fienup & Miller's
  metric), one view at a time in closed form. The relative phase of two views
  is observable only through the object frequencies both record: an extended
  scene needs overlapping windows (a quarter overlap suffices in the tests);
  with windows that merely touch, the sharpest sum need not be the true one
  (a point, with its flat spectrum, is still aligned). The common phase of the
  result is arbitrary.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np

from ..data.hologram import Hologram, Image
from ..physics.incident import remove_incident_phase
from ..physics.medium import Medium
from ..physics.sources import PlaneWave
from .migrate import migrate
from .migration.image import image_of
from .migration.settings import MigrationSettings

__all__ = ["align_phases", "synthesize"]

Mode = Literal["coherent", "amplitude", "quasi-coherent"]


def check_views(holograms: Sequence[Hologram]) -> list[Hologram]:
    views = list(holograms) if not isinstance(holograms, Hologram) else [holograms]
    if len(views) == 0:
        raise ValueError("holograms must hold at least one Hologram")
    for i, h in enumerate(views):
        if not isinstance(h, Hologram):
            raise ValueError(f"holograms[{i}] must be a holoradar.Hologram, got "
                             f"{type(h).__name__}")
        if h.source is None:
            raise ValueError(f"holograms[{i}] has no source: each view must carry the "
                             "illumination it was taken with (Hologram(..., source=...))")
    h0 = views[0]
    for i, h in enumerate(views[1:], start=1):
        if h.nf != h0.nf or not np.allclose(h.frequencies, h0.frequencies, rtol=1e-9, atol=0):
            raise ValueError(f"holograms[{i}] has frequencies {h.frequencies} Hz but "
                             f"holograms[0] {h0.frequencies} Hz: views must share their "
                             "frequencies")
        if h.x.shape != h0.x.shape or h.y.shape != h0.y.shape or not (
                np.allclose(h.x, h0.x) and np.allclose(h.y, h0.y)):
            raise ValueError(f"holograms[{i}] is sampled on another aperture grid than "
                             "holograms[0]: views must share one aperture")
        if h.pose != h0.pose:
            raise ValueError(f"holograms[{i}] has pose {h.pose} but holograms[0] {h0.pose}: "
                             "views must share one aperture (move the source, not the array)")
        if h.data.shape != h0.data.shape:
            raise ValueError(f"holograms[{i}] has data shape {h.data.shape}, holograms[0] "
                             f"{h0.data.shape}")
    return views


def align_phases(images: np.ndarray, *, passes: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Estimate and remove an unknown constant phase per view.

    Parameters
    ----------
    images : ndarray, shape (K, ...)
        Complex images of the K views, incident phase already removed.
    passes : int
        Sharpness-refinement sweeps over the views after the inner-product start.

    Returns
    -------
    aligned : ndarray, shape (K, ...)
    phases : ndarray, shape (K,)
        The phases removed, radians (``aligned[k] = images[k] * exp(-1j*phases[k])``).

    Examples
    --------
    >>> g = np.ones((3, 4, 4)) * np.exp(1j * np.array([0.0, 1.0, -2.0]))[:, None, None]
    >>> _, ph = align_phases(g)
    >>> np.round(ph - ph[0], 6)
    array([ 0.,  1., -2.])
    """
    g = np.asarray(images)
    if g.ndim < 2 or g.shape[0] == 0 or g[0].size == 0:
        raise ValueError(f"images must be a stack (K, ...) of K >= 1 complex images, got shape "
                         f"{g.shape}")
    flat = g.reshape(g.shape[0], -1)
    ref = flat[int(np.argmax(np.sum(np.abs(flat) ** 2, axis=1)))]
    phases = np.angle(flat @ ref.conj())  # arg <ref, g_k>
    grid = np.linspace(-np.pi, np.pi, 721)[:-1]
    for _ in range(max(0, passes)):
        total = np.sum(flat * np.exp(-1j * phases)[:, None], axis=0)
        for i in range(flat.shape[0]):
            gi = flat[i] * np.exp(-1j * phases[i])
            rest = total - gi
            # |rest + gi e^{-i t}|^2 = a + 2 Re(c e^{-i t}), c = conj(rest) gi, so
            # sum |.|^4 = sum (a + 2 cr cos t + 2 ci sin t)^2: a trigonometric
            # polynomial of degree 2 in t, maximised on a fine grid.
            a = np.abs(rest) ** 2 + np.abs(gi) ** 2
            c = rest.conj() * gi
            cr, ci = c.real, c.imag
            coef = [np.sum(a * a) + 2 * np.sum(cr * cr + ci * ci), 4 * np.sum(a * cr),
                    4 * np.sum(a * ci), 2 * np.sum(cr * cr - ci * ci), 4 * np.sum(cr * ci)]
            s = (coef[0] + coef[1] * np.cos(grid) + coef[2] * np.sin(grid)
                 + coef[3] * np.cos(2 * grid) + coef[4] * np.sin(2 * grid))
            t = grid[int(np.argmax(s))]
            phases[i] = np.angle(np.exp(1j * (phases[i] + t)))
            total = rest + gi * np.exp(-1j * t)
    return g * np.exp(-1j * phases).reshape((-1,) + (1,) * (g.ndim - 1)), phases


def synthesize(holograms: Sequence[Hologram], z: float | Sequence[float], *,
               medium: Medium | None = None, mode: Mode = "coherent", upsample: int = 1,
               fov: Literal["aperture", "full"] = "aperture",
               return_views: bool = False, frame: Literal["aperture", "ground"] = "aperture",
               x: np.ndarray | None = None, y: np.ndarray | None = None,
               dtype: Any = None) -> Image | tuple[Image, np.ndarray]:
    """Image several views of one scene and sum them (synthetic aperture).

    Parameters
    ----------
    holograms : sequence of Hologram
        The views: one frequency, one aperture grid, each with its ``source``
        (plane-wave angle, radiator position or beam).
    z : float or sequence of float
        Image ranges, metres.
    medium : Medium, optional
        Layered ground: the views are migrated through it, and their incident
        fields are computed through it (both cross the surface).
    mode : {"coherent", "amplitude", "quasi-coherent"}
        How the views add (module docstring).
    upsample, fov
        As for :func:`holoradar.migrate`.
    return_views : bool
        Also return the per-view images with their incident phase removed,
        shape (K, nz, ny, nx) (or (K, ny, nx) for a scalar z).
    frame, x, y
        As in :func:`holoradar.migrate`: ``frame="ground"`` images the views of a
        tilted aperture (all with one ``pose``) on horizontal world planes through
        the layers, where each view's incident field is removed (the oblique
        layout with the horn moved along the ground).
    dtype : numpy dtype, optional
        As in :func:`holoradar.migrate` (default single precision).

    Returns
    -------
    Image
        The sum; its ``method`` names the mode. Amplitude mode gives a real image.

    Examples
    --------
    >>> import holoradar as hr
    >>> ap = hr.Aperture.grid(25, 0.015)
    >>> views = [hr.simulate(hr.Scene(source=hr.PlaneWave(a, 0.0),
    ...                               targets=[hr.PointTarget((0.0, 0.0, 0.5))]), ap, 9.9e9)
    ...          for a in np.radians([-20, 0, 20])]
    >>> img = synthesize(views, 0.5)
    >>> [round(v, 3) for v in img.peak()[:2]]
    [0.0, 0.0]
    """
    views = check_views(holograms)
    if mode not in ("coherent", "amplitude", "quasi-coherent"):
        raise ValueError(f"mode must be 'coherent', 'amplitude' or 'quasi-coherent', got "
                         f"{mode!r}")
    med = medium if medium is not None else Medium.free_space()
    # A tilted aperture's views are imaged on horizontal world planes ("ground"),
    # where the sources' incident fields are known.
    where = {"frame": frame, "x": x, "y": y} if frame != "aperture" or x is not None \
        or y is not None else {}
    where["dtype"] = dtype
    if not views[0].pose.is_identity and frame == "aperture" and not views[0].pose.is_level:
        raise ValueError("views from a tilted aperture are summed on ground planes: pass "
                         "frame='ground' (the incident fields are known in the world frame)")
    if views[0].is_wideband:
        # Each view's frequencies are summed coherently after their own incident phases
        # (migrate does that with the view's source); the views then add as below.
        imgs = [migrate(v, z, medium=medium, upsample=upsample, fov=fov, **where)
                for v in views]
        img = imgs[0]
        aligned = np.stack([im.data if im.has_z_axis else im.data[None] for im in imgs])
        return _combine(aligned, img, mode, return_views)
    stack = views[0].with_data(np.stack([v.data for v in views]))
    img = migrate(stack, z, medium=medium, upsample=upsample, fov=fov, **where)
    g = img.data if img.has_z_axis else img.data[:, None]
    k = views[0].k
    # conj(E0)/|E0|, the unit phasor of the incident field (0 where it vanishes),
    # at the pixels' world positions (a raised or shifted level view included).
    if frame == "ground" or all(v.pose.is_identity for v in views):
        sources = [v.source if v.source is not None else PlaneWave() for v in views]
        aligned = g  # migrate's own new array: the phase comes off in place
        remove_incident_phase(aligned, sources, k, med, img.x, img.y, img.z)
    else:
        # A raised or shifted level view: each imaged with its own incident phase
        # removed (the migration operator's "phase" illumination, at the pixels'
        # world positions).
        one = MigrationSettings(upsample=upsample, fov=fov, illumination="phase", **where)
        aligned = np.stack([image_of(v, img.z if img.has_z_axis else float(img.z[0]),
                                     medium, one).data for v in views])
        aligned = aligned if img.has_z_axis else aligned[:, None]
    return _combine(aligned, img, mode, return_views)


def _combine(aligned: np.ndarray, img: Image, mode: str,
             return_views: bool) -> Image | tuple[Image, np.ndarray]:
    """Add the views, incident phase removed, (K, nz, ny, nx), as ``mode`` says."""
    if mode == "coherent":
        total = aligned.sum(axis=0)
    elif mode == "amplitude":
        total = np.abs(aligned).sum(axis=0).astype(aligned.real.dtype)
    else:
        aligned, _ = align_phases(aligned)
        total = aligned.sum(axis=0)
    data = total if img.has_z_axis else total[0]
    out = Image(data, img.x, img.y, img.z, img.frequency, f"synthesis:{mode}",
                has_z_axis=img.has_z_axis)
    if return_views:
        return out, (aligned if img.has_z_axis else aligned[:, 0])
    return out
