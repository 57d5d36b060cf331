"""Figures with labelled axes and units; rendered off-screen to PNG bytes.

Every function returns a :class:`matplotlib.figure.Figure` built without pyplot
(no global state, no display needed); :func:`to_png` renders it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from .._figures import edges as _edges
from .._figures import to_png
from ..data.hologram import Hologram, Image
from ..theory import SpectralWindow
from .view.display import CM, scaled

__all__ = ["plot_depth_sweep", "plot_hologram", "plot_image", "plot_planes", "plot_section",
           "plot_spectrum", "to_png"]


def plot_hologram(h: Hologram, title: str = "Hologram") -> Figure:
    """Amplitude and phase of a hologram (x, y in cm); its first frame and frequency."""
    fig = Figure(figsize=(10, 4.3), layout="constrained")
    data = h.data.reshape((-1, *h.data.shape[-2:]))[0]
    for ax, val, lab, cmap in zip(fig.subplots(1, 2),
                                  (np.abs(data), np.angle(data)),
                                  ("|E| (per unit source amplitude)", "phase (rad)"),
                                  ("viridis", "twilight"), strict=True):
        m = ax.pcolormesh(_edges(h.x) * CM, _edges(h.y) * CM, val, cmap=cmap, shading="flat")
        ax.set_aspect("equal")
        ax.set_xlabel("x (cm)")
        ax.set_ylabel("y (cm)")
        ax.set_title(f"{title}: {'amplitude' if 'E' in lab else 'phase'}")
        fig.colorbar(m, ax=ax, label=lab)
    f = h.frequencies
    band = (f"f = {f[0] / 1e9:.3g} GHz" if f.size == 1 else
            f"f = {f[0] / 1e9:.3g} GHz (first of {f.size}, to {f[-1] / 1e9:.3g} GHz)")
    fig.suptitle(f"{h.data.shape[-1]} x {h.data.shape[-2]} elements, {band}"
                 + (", scanned transceiver" if h.monostatic else ""))
    return fig


def plot_image(images: Sequence[Image], titles: Sequence[str], *,
               outline: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
               marks: dict[str, np.ndarray | None] | None = None,
               aperture: tuple[np.ndarray, np.ndarray] | None = None,
               db_range: float | None = None, suptitle: str = "") -> Figure:
    """|image| of one plane per panel, normalised to each panel's maximum.

    ``outline = (x, y, mask)`` draws the true object's contour in white;
    ``marks`` labels points ``(x, y)`` in metres (``None`` values are skipped);
    ``aperture = (x, y)`` draws the array's footprint. ``db_range`` switches to
    ``20*log10(|E|)`` on one scale for all panels, relative to the first panel's
    maximum, over that many dB (to show how much a processing step removed).
    """
    fig = Figure(figsize=(max(6.0, 5 * len(images)), 5.0), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(images)))
    ref = float(np.abs(images[0].data).max()) or 1.0
    for ax, img, title in zip(axes, images, titles, strict=True):
        a = np.abs(img.data.reshape((-1, *img.data.shape[-2:]))[0])
        if db_range is None:
            a = a / a.max() if a.max() > 0 else a
            vmin, vmax, label = 0.0, 1.0, f"{_quantity(img)} / max"
        else:
            a = 20 * np.log10(np.maximum(a / ref, 10 ** (-db_range / 20)))
            vmin, vmax, label = -db_range, 0.0, f"{_quantity(img)} (dB re first panel's max)"
        m = ax.pcolormesh(_edges(img.x) * CM, _edges(img.y) * CM, a, cmap="inferno",
                          vmin=vmin, vmax=vmax, shading="flat")
        if outline is not None:
            ox, oy, mask = outline
            ax.contour(ox * CM, oy * CM, mask.astype(float), levels=[0.5], colors="w",
                       linewidths=1.0)
        if aperture is not None:
            ex, ey = _edges(aperture[0]), _edges(aperture[1])
            ax.add_patch(Rectangle((ex[0] * CM, ey[0] * CM), (ex[-1] - ex[0]) * CM,
                                   (ey[-1] - ey[0]) * CM, fill=False, ec="c", ls="--",
                                   label="array footprint"))
        for name, xy in (marks or {}).items():
            if xy is not None:
                ax.plot(xy[0] * CM, xy[1] * CM, "c+", ms=14, mew=2, label=name)
        if marks or aperture is not None:
            ax.legend(loc="upper right", fontsize=8)
        ax.set_aspect("equal")
        ax.set_xlabel("x (cm)")
        ax.set_ylabel("y (cm)")
        ax.set_title(f"{title}\nz = {img.z[0] * CM:.1f} cm")
        fig.colorbar(m, ax=ax, label=label)
    if suptitle:
        fig.suptitle(suptitle)
    return fig


def plot_depth_sweep(img: Image, *, y: float = 0.0, marks: dict[str, float] | None = None,
                     title: str = "Depth sweep") -> Figure:
    """An x-z slice of |image| at ``y`` and the peak |image| of each plane against z."""
    iy = int(np.argmin(np.abs(img.y - y)))
    a = np.abs(img.data[..., iy, :])
    a = a.reshape((-1, *a.shape[-2:]))[0]
    fig = Figure(figsize=(11, 4.5), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    m = ax1.pcolormesh(_edges(img.x) * CM, _edges(img.z) * CM, a / a.max(), cmap="inferno",
                       shading="flat")
    ax1.invert_yaxis()
    ax1.set_xlabel("x (cm)")
    ax1.set_ylabel("range z from aperture (cm)")
    ax1.set_title(f"|image| in the plane y = {img.y[iy] * CM:.1f} cm")
    fig.colorbar(m, ax=ax1, label="|E| / max")
    peak = np.abs(img.data).reshape((-1, img.z.size, img.y.size * img.x.size)).max(axis=(0, 2))
    ax2.plot(img.z * CM, peak / peak.max(), "k-")
    for (label, zv), style in zip((marks or {}).items(), ("--", ":", "-."), strict=False):
        ax2.axvline(zv * CM, ls=style, color="C3" if style == "--" else "C0", label=label)
        ax1.axhline(zv * CM, ls=style, color="w", lw=0.8)
    ax2.set_xlabel("range z from aperture (cm)")
    ax2.set_ylabel("max |E| in plane / max")
    ax2.set_title("Focus against range")
    if marks:
        ax2.legend()
    fig.suptitle(title)
    return fig


def plot_spectrum(p: np.ndarray, q: np.ndarray, spectrum: np.ndarray,
                  windows: Sequence[SpectralWindow], *, nyquist: float | None = None,
                  union: bool = False,
                  title: str = "Object spectrum and spectral window") -> Figure:
    """|F(p, q)| (dB) with each view's spectral window drawn as a rectangle (rad/m).

    ``union=True`` (several views) shades the union of the windows: the object
    frequencies that a coherent synthesis of the views records (paper Fig. 11).
    """
    fig = Figure(figsize=(6.2, 5.2), layout="constrained")
    ax = fig.subplots()
    s = np.abs(spectrum)
    db = 20 * np.log10(np.maximum(s / s.max(), 1e-4))
    m = ax.pcolormesh(_edges(p), _edges(q), db, cmap="magma", vmin=-40, vmax=0, shading="flat")
    multi = len(windows) > 1
    for i, w in enumerate(windows):
        (p1, p2), (q1, q2) = w.p_range, w.q_range
        ax.add_patch(Rectangle((p1, q1), p2 - p1, q2 - q1, fill=False,
                               ec=f"C{i % 10}" if multi else "c", lw=1.8,
                               label=f"view {i + 1}" if multi else "spectral window"))
    if union and multi:
        P, Q = np.meshgrid(p, q)
        covered = np.zeros(P.shape, bool)
        for w in windows:
            covered |= w.contains(P, Q)
        ax.contourf(p, q, covered.astype(float), levels=[0.5, 1.5], colors=["w"], alpha=0.18)
        ax.contour(p, q, covered.astype(float), levels=[0.5], colors="w", linewidths=2.2)
        ax.plot([], [], "w-", lw=2.2, label="union (coherent synthesis)")
    for i, w in enumerate(windows if nyquist is not None else []):
        # The array samples |p|, |q| <= pi/s in its own frame: |p + p0| <= pi/s here.
        cx, cy = w.center
        ax.add_patch(Rectangle((cx - nyquist, cy - nyquist), 2 * nyquist, 2 * nyquist,
                               fill=False, ec="w", ls="--", lw=1,
                               label=r"sampling limit $\pm\pi/s$" if i == 0 else None))
    ax.set_xlabel("p (rad/m)")
    ax.set_ylabel("q (rad/m)")
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title)
    fig.colorbar(m, ax=ax, label="|F(p, q)| (dB re max)")
    return fig


def plot_oblique_plan(plan: Any, aperture: Any, source: Any, medium: Any,
                      target: Any) -> Figure:
    """Side view of an oblique layout with its rays (paper Fig. 17): the array, the
    horn's boresight to the specular point and its reflection, and the refracted
    ray from the array's centre to the target.

    The view is the vertical plane through the array's centre along its azimuth
    (horizontal axis: distance along that direction, metres; vertical: range z).
    """
    pose = aperture.pose
    c = np.asarray(pose.center)
    along = np.array([np.cos(pose.azimuth), np.sin(pose.azimuth), 0.0])

    def h(p: np.ndarray) -> float:
        return float((np.asarray(p) - c) @ along)

    fig = Figure(figsize=(8, 4.6), layout="constrained")
    ax = fig.subplots()
    zs = medium.z_interfaces[0]
    pts = aperture.points
    horn = np.asarray(getattr(source, "position", getattr(source, "center", c)), float)
    tgt = np.asarray(target, float)
    xs = [h(p) for p in pts] + [h(horn), h(tgt)]
    lo, hi = min(xs) - 0.15, max(xs) + 0.15
    ax.axhspan(zs, max(tgt[2], zs) + 0.15, color="tan", alpha=0.5,
               label=f"ground, eps {medium.eps[1]}")
    ax.plot([h(p) for p in pts], pts[:, 2], ".", ms=2, color="C0", label="array elements")
    ax.plot(h(horn), horn[2], "s", color="C1", ms=8, label="horn")
    ax.plot(h(tgt), tgt[2], "kx", ms=9, label="target")
    if np.all(np.isfinite(plan.specular_point)):
        sp = plan.specular_point
        ax.plot([h(horn), h(sp)], [horn[2], sp[2]], "-", color="C1", lw=1.5,
                label="boresight")
        far = sp + 0.8 * plan.reflected_direction
        ax.plot([h(sp), h(far)], [sp[2], far[2]], "--", color="C3", lw=1.5,
                label=f"specular reflection (misses by {plan.miss_distance * 100:.0f} cm)"
                if plan.miss_distance > 0 else "specular reflection (hits the array)")
    rp = plan.refraction_point
    ax.plot([h(c), h(rp), h(tgt)], [c[2], rp[2], tgt[2]], "-", color="C2", lw=1,
            label=f"refracted ray, effective distance {plan.effective_distance:.2f} m")
    ax.set(xlim=(lo, hi), ylim=(max(tgt[2], zs) + 0.15, min(pts[:, 2].min(), horn[2]) - 0.1),
           xlabel="distance along the array's azimuth (m)", ylabel="range z below the "
           "reference plane (m)",
           title=f"oblique layout: tilt {np.degrees(pose.tilt):.0f} deg, glare fraction "
                 f"{plan.glare_fraction:.2%}")
    ax.set_aspect("equal")
    ax.legend(loc="lower left", fontsize=7)
    return fig


def _quantity(img: Image) -> str:
    """What an image's magnitude is, for its colour bar: an inverted reflectivity (the
    Born amplitude per voxel), a mosaic's blended magnitude, or a migrated field."""
    method = str(getattr(img, "method", "") or "")
    return "|reflectivity|" if method.startswith("invert") else "|E|"


def _scaled(a: np.ndarray, ref: float, db_range: float | None, quantity: str = "|E|"
            ) -> tuple[np.ndarray, float, float, str]:
    if db_range is None:
        return scaled(a, ref, "linear", 0.0), 0.0, 1.0, f"{quantity} / max"
    return scaled(a, ref, "db", db_range), -db_range, 0.0, f"{quantity} (dB re max)"


def plot_planes(img: Image, zs: Sequence[float], *, db_range: float | None = None,
                shared: bool = True, z_surface: float | None = None,
                title: str = "") -> Figure:
    """|image| in the planes nearest ``zs``, one panel each.

    ``shared`` puts every panel on one colour scale (the maximum over the
    panels), so their brightness compares; otherwise each is normalised to its
    own maximum. ``db_range`` draws ``20 log10 |E|`` over that many dB.
    ``z_surface`` labels each plane with its depth below the ground surface
    ``z - z_surface`` as well as its range.
    """
    idx = [int(np.argmin(np.abs(img.z - z))) for z in zs]
    vol = np.abs(img.data).reshape((-1, img.z.size, img.y.size, img.x.size))[0] \
        if img.has_z_axis else np.abs(img.data).reshape((-1, 1, img.y.size, img.x.size))[0]
    panels = [vol[i] for i in idx]
    gmax = max(float(p.max()) for p in panels) or 1.0
    aspect = float(np.ptp(img.y) / np.ptp(img.x)) if np.ptp(img.x) > 0 else 1.0
    width = 4.6 if aspect >= 0.8 else 9.0  # a long strip (a survey map) gets room
    height = min(4.8, max(2.8, (width - 1.8) * aspect + 1.5))
    fig = Figure(figsize=(max(6.0, width * len(panels)), height), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(panels)))
    for ax, p, i in zip(axes, panels, idx, strict=True):
        ref = gmax if shared else (float(p.max()) or 1.0)
        a, vmin, vmax, label = _scaled(p, ref, db_range, _quantity(img))
        m = ax.pcolormesh(_edges(img.x) * CM, _edges(img.y) * CM, a, cmap="inferno",
                          vmin=vmin, vmax=vmax, shading="flat")
        ax.set_aspect("equal")
        ax.set_xlabel("x (cm)")
        ax.set_ylabel("y (cm)")
        z = float(img.z[i])
        depth = "" if z_surface is None else f", depth {(z - z_surface) * CM:.1f} cm below " \
                                               "the surface"
        ax.set_title(f"range z = {z * CM:.1f} cm{depth}", fontsize=9)
        if not shared or ax is axes[-1]:
            fig.colorbar(m, ax=ax, label=label + (" (all panels)" if shared and len(panels) > 1
                                                  else ""))
    if title:
        fig.suptitle(title)
    return fig


def plot_section(img: Image, *, along: str = "x", at: float = 0.0,
                 db_range: float | None = None, z_surface: float | None = None,
                 title: str = "") -> Figure:
    """A vertical section of |image| (x-z at ``y = at``, or y-z at ``x = at``); the
    vertical axis is the range, with the depth below the surface on the right."""
    vol = np.abs(img.data).reshape((-1, img.z.size, img.y.size, img.x.size))[0]
    if along == "x":
        j = int(np.argmin(np.abs(img.y - at)))
        sec, h, where = vol[:, j, :], img.x, f"y = {img.y[j] * CM:.1f} cm"
    else:
        j = int(np.argmin(np.abs(img.x - at)))
        sec, h, where = vol[:, :, j], img.y, f"x = {img.x[j] * CM:.1f} cm"
    a, vmin, vmax, label = _scaled(sec, float(sec.max()) or 1.0, db_range, _quantity(img))
    fig = Figure(figsize=(8.0, 5.0), layout="constrained")
    ax = fig.subplots()
    m = ax.pcolormesh(_edges(h) * CM, _edges(img.z) * CM, a, cmap="inferno", vmin=vmin,
                      vmax=vmax, shading="flat")
    ax.invert_yaxis()
    ax.set_xlabel(f"{along} (cm)")
    ax.set_ylabel("range z from the array (cm)")
    if z_surface is not None:
        ax.axhline(z_surface * CM, color="c", lw=1, ls="--", label="ground surface")
        ax.legend(loc="lower right", fontsize=8)
        sec_ax = ax.secondary_yaxis("right", functions=(lambda v: v - z_surface * CM,
                                                        lambda v: v + z_surface * CM))
        sec_ax.set_ylabel("depth below the surface (cm)")
    ax.set_title(f"|image| in the section {where}")
    fig.colorbar(m, ax=ax, label=label)
    if title:
        fig.suptitle(title)
    return fig
