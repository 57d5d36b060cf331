"""A tilted array over sand: a buried point imaged on horizontal ground planes.

A 32 x 32 receiver array (pitch 12 mm) tilted 35 degrees, centre 5 cm below the
reference plane and 15 cm to the side, looks into sand (eps 2.5, surface at
0.30 m) at a point 12 cm deep; 9 frequencies over 8-12 GHz, normal plane-wave
illumination. ``migrate(..., frame="ground")`` images it on horizontal world
planes through the surface; the same data migrated as if there were no ground
lands shallower and to the side.

Run: ``.venv/bin/python examples/oblique_point.py [out_dir]``; writes
``oblique_layout.png`` (the layout, side view, and the pose's axes),
``oblique_point.png`` (x-y plane at the target depth and y-z section, dB) and
``oblique_point.json`` (positions and errors).
"""

from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import holoradar as hr


def main(out: Path) -> dict:
    sand = hr.Medium.half_space(0.30, 2.5)
    target = np.array([0.02, -0.01, 0.42])
    pose = hr.Pose((0.0, -0.15, 0.05), tilt=np.radians(35), azimuth=np.radians(90))
    aperture = hr.Aperture.grid(32, 0.012, pose=pose)
    scene = hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget(tuple(target))])
    freqs = np.linspace(8e9, 12e9, 9)
    h = hr.simulate(scene, aperture, freqs, include_surface=False)
    x = np.arange(-0.06, 0.10, 0.003)
    y = np.arange(-0.10, 0.08, 0.003)
    zs = np.arange(0.34, 0.50, 0.003)
    img = hr.migrate(h, zs, medium=sand, frame="ground", x=x, y=y)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        free = hr.migrate(h, np.arange(0.2, 0.6, 0.005), frame="ground", x=x, y=y)
    peak, peak_free = np.array(img.peak()), np.array(free.peak())
    _layout(out / "oblique_layout.png", h, sand, target)
    _images(out / "oblique_point.png", img, target)
    metrics = {"target_m": target.tolist(), "peak_m": peak.tolist(),
               "error_mm": float(1e3 * np.linalg.norm(peak - target)),
               "peak_without_medium_m": peak_free.tolist(),
               "error_without_medium_mm": float(1e3 * np.linalg.norm(peak_free - target))}
    (out / "oblique_point.json").write_text(json.dumps(metrics, indent=1))
    return metrics


def _layout(path: Path, h: hr.Hologram, medium: hr.Medium, target: np.ndarray) -> None:
    """Side view (y-z) of the layout, and the pose's axes."""
    fig = Figure(figsize=(9, 4.2), layout="constrained")
    ax, ax2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.6, 1]})
    pts = h.points
    surf = medium.z_interfaces[0]
    ax.axhspan(surf, 0.6, color="tan", alpha=0.5, label="sand, eps 2.5")
    ax.plot(pts[:, 1], pts[:, 2], ".", ms=2, color="C0", label="elements (side view)")
    c, n = np.array(h.pose.center), h.pose.normal
    ax.annotate("", (c + 0.12 * n)[1:], c[1:], arrowprops={"arrowstyle": "->", "color": "C3"})
    ax.text(*(c + 0.13 * n)[1:], "normal", color="C3")
    # The ray from the array's centre to the target: straight to the surface,
    # refracted below it (Snell).
    ax.plot(target[1], target[2], "kx", ms=9, label="point target")
    ax.plot([c[1], target[1]], [c[2], target[2]], ":", color="0.5", lw=1,
            label="straight line (no ground)")
    ax.set(xlabel="y (m)", ylabel="z, range below the reference plane (m)",
           title="oblique layout: tilt 35 deg, azimuth 90 deg", xlim=(-0.35, 0.15),
           ylim=(0.55, -0.1))
    ax.legend(loc="lower left", fontsize=8)
    # The pose convention: R = Rz(az) Ry(tilt) Rz(-az).
    for vec, name, col in ((h.pose.u, "x'", "C0"), (h.pose.v, "y'", "C2"),
                           (h.pose.normal, "n", "C3")):
        ax2.annotate("", (vec[1], vec[2]), (0, 0),
                     arrowprops={"arrowstyle": "->", "color": col, "lw": 2})
        ax2.text(vec[1] * 1.1, vec[2] * 1.1, f"{name} = ({vec[0]:.2f}, {vec[1]:.2f}, "
                 f"{vec[2]:.2f})", color=col, fontsize=8)
    ax2.set(xlim=(-1.2, 1.6), ylim=(1.2, -1.2), xlabel="world y", ylabel="world z (down)",
            title="aperture axes in the world\n(x' = +x, out of the page)")
    ax2.set_aspect("equal")
    fig.savefig(path, dpi=110)


def _images(path: Path, img: hr.Image, target: np.ndarray) -> None:
    a = np.abs(img.data)
    a = 20 * np.log10(np.maximum(a / a.max(), 1e-3))
    iz = int(np.argmin(np.abs(img.z - target[2])))
    ix = int(np.argmin(np.abs(img.x - target[0])))
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    ext = [img.x[0], img.x[-1], img.y[0], img.y[-1]]
    im = ax1.imshow(a[iz], origin="lower", extent=ext, vmin=-30, vmax=0, cmap="magma")
    ax1.plot(target[0], target[1], "c+", ms=12)
    ax1.set(xlabel="x (m)", ylabel="y (m)", title=f"ground plane z = {img.z[iz]:.3f} m")
    ax2.imshow(a[:, :, ix], origin="upper", aspect="auto", vmin=-30, vmax=0, cmap="magma",
               extent=[img.y[0], img.y[-1], img.z[-1], img.z[0]])
    ax2.plot(target[1], target[2], "c+", ms=12)
    ax2.set(xlabel="y (m)", ylabel="z (m)", title=f"section x = {img.x[ix]:.3f} m")
    fig.colorbar(im, ax=(ax1, ax2), label="|image| (dB)")
    fig.suptitle("tilted array, 9 frequencies 8-12 GHz, through sand (+: true position)")
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("docs/figures")
    out_dir.mkdir(parents=True, exist_ok=True)
    print(json.dumps(main(out_dir), indent=1))
