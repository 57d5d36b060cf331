"""Images of the independent full-wave fixtures (tests/data) migrated through the sand.

* S2 (SMUTHI): metal sphere 10 cm deep, plane waves at 0, +-20, +-40 degrees;
  x-z slices through the sphere with its true outline.
* gprMax: PEC rod 10 cm deep, dipole lit from the side; scattered field =
  run C - run B at 9.9 GHz; the plane of sharpest focus and an x-z slice.

Run: ``.venv/bin/python examples/fixture_images.py [OUT_DIR]`` (default ``out/``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

import holoradar as hr
from holoradar.analysis.metrics import peak_position
from holoradar.app.atomic import write_atomic
from holoradar.app.plotting import _edges, to_png

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"
CM = 100


def sphere_figure() -> Figure:
    fig = Figure(figsize=(16, 3.8), layout="constrained")
    axes = fig.subplots(1, 5)
    for ax, inc in zip(axes, ["-40", "-20", "+00", "+20", "+40"], strict=True):
        with np.load(DATA / f"S2_buried_sphere_metal_inc{inc}.npz") as d:
            h = hr.Hologram(d["E_scat"][1], d["x_m"], d["y_m"], float(d["f_hz"][0]))
            medium = hr.Medium.half_space(0.30, complex(d["sand_eps"][0]))
        zs = np.linspace(0.30, 0.48, 91)
        img = hr.migrate(h, zs, medium=medium, upsample=2)
        x, _, z = peak_position(img)
        iy = int(np.argmin(np.abs(img.y)))
        a = np.abs(img.data[:, iy, :])
        sel = np.abs(img.x) <= 0.12
        m = ax.pcolormesh(_edges(img.x[sel]) * CM, _edges(zs) * CM, a[:, sel] / a.max(),
                          cmap="inferno", shading="flat")
        ax.add_patch(Circle((0, 40), 1.5, fill=False, ec="c", lw=1))
        ax.axhline(30, color="w", lw=0.8, ls="--")
        ax.plot(x * CM, z * CM, "c+", ms=10)
        ax.invert_yaxis()
        ax.set_aspect("equal")
        ax.set_xlabel("x (cm)")
        ax.set_ylabel("range z (cm)")
        ax.set_title(f"incidence {inc} deg\npeak x={x * CM:.2f}, z={z * CM:.2f} cm")
    fig.colorbar(m, ax=axes, label="|E| / max")
    fig.suptitle("SMUTHI metal sphere (r = 1.5 cm, centre 10 cm deep; cyan circle) migrated "
                 "through sand; dashed: surface")
    return fig


def rod_figure() -> Figure:
    with np.load(DATA / "run_B_background.npz") as b, np.load(DATA / "run_C_rod.npz") as c:
        fi = int(np.argmin(np.abs(b["freqs_hz"] - 9.9e9)))
        f = float(b["freqs_hz"][fi])
        scat = c["Ey"][fi].astype(complex) - b["Ey"][fi].astype(complex)
        h = hr.Hologram(scat, b["x_m"], b["y_m"], f)
    medium = hr.Medium.half_space(0.30, hr.permittivity(2.5, sigma=0.0069, frequency=f))
    zs = np.linspace(0.30, 0.50, 101)
    img = hr.migrate(h, zs, medium=medium, upsample=4)
    e = np.sum(np.abs(img.data) ** 2, axis=1)
    iz = int(np.unravel_index(np.argmax(e), e.shape)[0])
    fig = Figure(figsize=(12, 4.5), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    a = np.abs(img.data[iz])
    m = ax1.pcolormesh(_edges(img.x) * CM, _edges(img.y) * CM, a / a.max(), cmap="inferno",
                       shading="flat")
    ax1.plot([0, 0], [-15, 15], "c--", lw=1, label="rod axis")
    ax1.plot(-20, 0, "w*", ms=12, label="dipole (10 cm above sand)")
    ax1.set_aspect("equal")
    ax1.set_xlabel("x (cm)")
    ax1.set_ylabel("y (cm)")
    ax1.set_title(f"plane of sharpest x-focus, z = {zs[iz] * CM:.1f} cm")
    ax1.legend(fontsize=8, loc="lower right")
    fig.colorbar(m, ax=ax1, label="|E| / max")
    iy = int(np.argmin(np.abs(img.y)))
    b2 = np.abs(img.data[:, iy, :])
    m2 = ax2.pcolormesh(_edges(img.x) * CM, _edges(zs) * CM, b2 / b2.max(), cmap="inferno",
                        shading="flat")
    ax2.add_patch(Circle((0, 40), 0.75, fill=False, ec="c"))
    ax2.axhline(30, color="w", lw=0.8, ls="--")
    ax2.invert_yaxis()
    ax2.set_aspect("equal")
    ax2.set_xlabel("x (cm)")
    ax2.set_ylabel("range z (cm)")
    ax2.set_title("x-z slice at y = 0 (cyan: rod cross-section)")
    fig.colorbar(m2, ax=ax2, label="|E| / max")
    fig.suptitle("gprMax PEC rod (15 mm, 10 cm deep), run C - run B, 9.9 GHz, E_y")
    return fig


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / "fixture_sphere.png", to_png(sphere_figure()))
    write_atomic(out / "fixture_rod.png", to_png(rod_figure()))


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "out"))
