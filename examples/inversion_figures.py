"""Reflectivity by inversion against the migrated (adjoint) image: the figures of
docs/inversion.md, and the numbers quoted there.

Scenes simulated with the vector model (dipoles induced in each target by a polarised
source, the elements recording E_y), which the inversion's operator did not make:

1. two points 0.6 of the Rayleigh spacing apart, 32 x 32 array at 1.25 cm, 40 cm, 30 dB;
2. one point: its reflectivity's level outside its resolution cell (the sidelobes);
3. three equal bars 6 cm under concrete, lit by a dipole 25 cm beside a 41 x 41 array,
   8-12 GHz: each bar's level in the adjoint image and in the reflectivity, and what
   ``detect`` finds with the hologram.

Run: ``python examples/inversion_figures.py [OUTDIR]`` (default docs/figures).
"""

import sys
import time
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import holoradar as hr

warnings.simplefilter("ignore", hr.AliasingWarning)
OUT = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/figures")
F0, Y = 9.9e9, (0, 1, 0)
LAM = hr.C0 / F0


def db(a: np.ndarray) -> np.ndarray:
    a = np.abs(a)
    return 20 * np.log10(np.maximum(a / a.max(), 1e-6))


def show(ax, img: hr.Image, title: str, floor: float = -40.0) -> None:
    data = img.data if img.data.ndim == 2 else np.abs(img.data).max(axis=0)
    m = ax.imshow(db(data), origin="lower", cmap="magma", vmin=floor, vmax=0,
                  extent=[100 * img.x[0], 100 * img.x[-1], 100 * img.y[0], 100 * img.y[-1]])
    ax.set(title=title, xlabel="x (cm)", ylabel="y (cm)")
    return m


# 1-2: two points closer than the Rayleigh spacing; one point's sidelobes.
z, size = 0.4, 32 * 0.0125
cell = LAM * z / size
sep = 0.6 * cell
array = hr.Aperture.grid(32, 0.0125, polarization=Y)
pts = [hr.PointTarget((-sep / 2, 0.0, z)), hr.PointTarget((sep / 2, 0.0, z))]
two = hr.simulate(hr.Scene(hr.Medium.free_space(), hr.PlaneWave(polarization=Y), pts),
                  array, F0, snr_db=30, seed=1)
t0 = time.perf_counter()
r_two = hr.invert(two, z, method="sparse", upsample=2, progress=False)
t_two = time.perf_counter() - t0
a_two = hr.migrate(two, z, upsample=2)
row = np.abs(r_two.data[np.argmin(np.abs(r_two.y)), :])
peaks = [float(r_two.x[i]) for i in range(1, row.size - 1)
         if row[i] >= row[i - 1] and row[i] >= row[i + 1] and row[i] > 0.3 * row.max()]
print(f"two points at +-{100 * sep / 2:.2f} cm (cell {100 * cell:.2f} cm): sparse peaks at "
      f"{[round(100 * p, 2) for p in peaks]} cm, {r_two.history[0]['iterations']} steps, "
      f"{t_two:.1f} s")

one = hr.simulate(hr.Scene(hr.Medium.free_space(), hr.PlaneWave(polarization=Y),
                           [hr.PointTarget((0.003, -0.002, z))]), array, F0, snr_db=30,
                  seed=2)
for how in ("adjoint", "lsqr", "sparse"):
    img = hr.migrate(one, z, upsample=2) if how == "adjoint" else \
        hr.invert(one, z, method=how, upsample=2, progress=False)
    a = np.abs(img.data)
    X, Y_ = np.meshgrid(img.x, img.y)
    outside = np.hypot(X - 0.003, Y_ + 0.002) > cell
    extra = "" if how == "adjoint" else \
        f", {img.history[0]['iterations']} steps ({img.history[0]['stop']})"
    print(f"one point, {how}: highest level outside its cell "
          f"{20 * np.log10(a[outside].max() / a.max()):.1f} dB{extra}")

# 3: three equal bars lit from beside the array.
concrete = hr.Medium.half_space(0.20, 6.0 + 0.3j)
dipole = hr.Dipole((-0.25, 0.0, 0.05), Y)
xs = (-0.12, 0.0, 0.12)
bars = [hr.LineTarget((xb, -0.15, 0.25), (xb, 0.15, 0.25), radius=0.006) for xb in xs]
h = hr.simulate(hr.Scene(concrete, dipole, bars), hr.Aperture.grid(41, 0.01, polarization=Y),
                np.linspace(8e9, 12e9, 5), include_surface=False, snr_db=30, seed=3)
zs = np.arange(0.22, 0.29, 0.01)


def levels(img: hr.Image) -> list[float]:
    a = np.abs(img.data)
    v = [a[:, np.abs(img.y) < 0.1][:, :, np.abs(img.x - xb) < 0.02].max() for xb in xs]
    return [round(float(d), 1) for d in 20 * np.log10(np.array(v) / max(v))]


adj = hr.migrate(h, zs, medium=concrete)
t0 = time.perf_counter()
refl = hr.invert(h, zs, medium=concrete, progress=False)
t_bars = time.perf_counter() - t0
print(f"three bars: adjoint {levels(adj)} dB, reflectivity (lsqr) {levels(refl)} dB, "
      f"{refl.history[0]['iterations']} steps ({refl.history[0]['stop']}), {t_bars:.1f} s")
t0 = time.perf_counter()
df = hr.detect(adj, hologram=h, medium=concrete)
print(f"detect with the hologram ({time.perf_counter() - t0:.1f} s):")
print(df[["kind", "x", "y", "depth", "length", "azimuth_deg", "spacing", "amplitude_db"]]
      .round(3).to_string())

fig, axes = plt.subplots(2, 2, figsize=(10, 9), constrained_layout=True)
show(axes[0, 0], a_two, f"two points {100 * sep:.1f} cm apart: adjoint image")
show(axes[0, 1], r_two, "the same: reflectivity (sparse)")
show(axes[1, 0], adj, "three equal bars, dipole at x = -25 cm: adjoint")
m = show(axes[1, 1], refl, "the same: reflectivity (least squares)")
for ax in axes[0]:
    for x0 in (-sep / 2, sep / 2):
        ax.plot(100 * x0, 0, "c+", ms=12)
fig.colorbar(m, ax=axes, shrink=0.6, label="dB of the image's maximum")
OUT.mkdir(parents=True, exist_ok=True)
fig.savefig(OUT / "inversion.png", dpi=90)
print("wrote", OUT / "inversion.png")
