"""Command line and demo: what a new user runs first."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import holoradar as hr
from conftest import F0
from holoradar.app.cli import main


def test_demo_writes_labelled_figures_and_summary(tmp_path):
    out = tmp_path / "demo"
    res = CliRunner().invoke(main, ["demo", "--out", str(out), "--upsample", "2"])
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    for name in s["files"]:
        assert (out / name).stat().st_size > 0
    assert {"hologram.png", "image_object_range.png", "depth_sweep.png",
            "spectrum_window.png"} <= set(s["files"])
    # Theory in the summary is the paper's: L = z0 + d/n, delta = lambda L / A.
    n = np.sqrt(2.5 * (1 + 0.005j)).real
    assert abs(s["theory"]["apparent_distance_m"] - (0.30 + 0.12 / n)) < 1e-9
    lam = hr.C0 / F0
    assert abs(s["theory"]["lateral_resolution_m"]
               - lam * s["theory"]["apparent_distance_m"] / 0.40) < 1e-12
    # The letter's image (targets only, migrated through the sand) lies on the letter's
    # 10 x 15 cm box, and the focus lies at or short of the true range (focal shift).
    x, y, z = s["image_peak_m"]["targets_only"]
    assert abs(x) <= 0.05 + 0.02 and abs(y) <= 0.075 + 0.02
    assert z <= s["object"]["range_m"] + 0.01
    assert "apparent distance" in res.output
    # The glare focuses at the horn's mirror image, beside the array: found within a
    # quarter of the resolution cell lambda*z_m/A (4.5 cm) of where geometry puts it.
    found, expected = (np.array(s["glare"][k]) for k in ("mirror_image_found_m",
                                                          "mirror_image_expected_m"))
    assert np.hypot(*(found[:2] - expected[:2])) < lam * expected[2] / 0.40 / 4
    assert not list(out.glob(".*tmp"))
    # The README's next command images the demo's own hologram.
    res = CliRunner().invoke(main, ["image", str(out / "hologram.nc"), "--z",
                                    "0.30:0.60:0.005", "--eps", "2.5+0.0125j", "--z-surface",
                                    "0.30", "--out", str(tmp_path / "img.nc")])
    assert res.exit_code == 0, res.output
    assert isinstance(hr.load(tmp_path / "img.nc"), hr.Image)


def test_image_command_roundtrip(tmp_path):
    scene = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))])
    h = hr.simulate(scene, hr.Aperture.grid(64, 0.01), F0)  # Fresnel number 11
    src = tmp_path / "holo.npz"
    np.savez(src, data=h.data, x=h.x, y=h.y, frequency=F0)
    out = tmp_path / "img.npz"
    res = CliRunner().invoke(main, ["image", str(src), "--z", "0.25:0.35:0.01",
                                    "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    # Focal shift at this Fresnel number: theory.focal_shift = -1.3 mm; a 1 cm plane step.
    assert abs(json.loads(res.stdout)["peak_m"][2] - 0.3) < 0.01
    assert out.exists() and out.with_suffix(".png").exists()


def test_image_command_bad_input_writes_nothing(tmp_path):
    src = tmp_path / "bad.npz"
    np.savez(src, data=np.full((4, 4), np.nan + 0j), x=np.arange(4.0) * 0.01,
             y=np.arange(4.0) * 0.01,
             frequency=F0)
    out = tmp_path / "img.npz"
    res = CliRunner().invoke(main, ["image", str(src), "--z", "0.3", "--out", str(out)])
    assert res.exit_code == 2
    assert "data must be finite" in res.output
    assert not out.exists()


def test_theory_command():
    res = CliRunner().invoke(main, ["theory", "--distance", "0.6", "--aperture", "0.4",
                                    "--frequency", str(hr.C0 / 0.03), "--json"])
    assert res.exit_code == 0
    assert abs(json.loads(res.stdout)["lateral_resolution_m"] - 0.045) < 1e-12


def test_plan_oblique_command(tmp_path):
    """The planner from the command line: JSON numbers, a layout figure, and no
    overwrite without --force; a horn in the ground is refused and writes nothing."""
    out = tmp_path / "plan.png"
    res = CliRunner().invoke(main, ["plan-oblique", "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.stdout)
    assert d["miss_distance_m"] > 0 and 0 <= d["glare_fraction"] < 0.01
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    again = CliRunner().invoke(main, ["plan-oblique", "--out", str(out)])
    assert again.exit_code != 0 and "--force" in again.output
    bad = tmp_path / "bad.png"
    res = CliRunner().invoke(main, ["plan-oblique", "--horn", "0,0,0.35", "--out", str(bad)])
    assert res.exit_code == 2 and "source" in res.output and not bad.exists()


def test_image_command_reads_and_writes_netcdf_and_never_destroys_data(tmp_path):
    """A hologram saved by holoradar.save is imaged from the command line into an
    image file that holoradar.load reads; the output may not be the input, an
    existing output needs --force, a missing folder or a bad --z fails before any
    work (exit code 2, one line, nothing written)."""
    scene = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))])
    src = hr.save(hr.simulate(scene, hr.Aperture.grid(64, 0.01), F0), tmp_path / "holo.nc")
    before = src.read_bytes()
    out = tmp_path / "img.nc"
    run = CliRunner().invoke
    res = run(main, ["image", str(src), "--z", "0.25:0.35:0.01", "--out", str(out)])
    assert res.exit_code == 0, res.output
    img = hr.load(out)
    assert isinstance(img, hr.Image) and abs(img.peak()[2] - 0.3) < 0.01
    steps = [s["step"] for s in hr.io.read_history(out)]
    assert steps == ["save", "migrate", "save"]  # the input's history, then this run's
    res = run(main, ["image", str(src), "--z", "0.3", "--out", str(src)])
    assert res.exit_code == 2 and "one of the inputs" in res.output
    res = run(main, ["image", str(src), "--z", "0.3", "--out", str(out)])
    assert res.exit_code == 2 and "--force" in res.output
    assert run(main, ["image", str(src), "--z", "0.3", "--out", str(out), "--force"]
               ).exit_code == 0
    res = run(main, ["image", str(src), "--z", "0.3", "--out", str(tmp_path / "no" / "i.nc")])
    assert res.exit_code == 2 and "does not exist" in res.output
    res = run(main, ["image", str(src), "--z", "0.3:0.6:0", "--out", str(tmp_path / "j.nc")])
    assert res.exit_code == 2 and "step > 0" in res.output
    res = run(main, ["image", str(src), "--z", "0.3", "--out", str(tmp_path / "k.png")])
    assert res.exit_code == 2 and ".nc or .nc4 or .npz" in res.output
    assert src.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["holo.nc", "img.nc", "img.png"]


def _kept_figures(monkeypatch) -> list:
    """The figures the demo draws, kept as it turns them into PNGs."""
    from holoradar.app import plotting

    figs = []
    real = plotting.to_png

    def keep(fig, *args, **kwargs):
        figs.append(fig)
        return real(fig, *args, **kwargs)

    monkeypatch.setattr(plotting, "to_png", keep)
    return figs


def test_demo_titles_fit_their_figures_and_define_their_symbols(monkeypatch, tmp_path):
    """The third panel's title ran off the figure ('... to L = 37.6 c'); the glare figure
    wrote z_m = 2 z0 - z_s without saying what z0 and z_s are."""
    from holoradar.app import demo

    figs = _kept_figures(monkeypatch)
    demo.run_demo(tmp_path / "demo", upsample=1)
    assert len(figs) == 5
    for fig in figs:
        renderer = fig.canvas.get_renderer()
        for ax in fig.axes:
            if not ax.get_title():
                continue
            box = ax.title.get_window_extent(renderer)
            # inside the figure, and clear of every other axes (a colorbar drew over it)
            assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1, ax.get_title()
            for other in fig.axes:
                if other is not ax:
                    assert not box.overlaps(other.get_window_extent(renderer)), ax.get_title()
    glare = next(f.get_suptitle() for f in figs if "mirror image" in f.get_suptitle())
    assert "2 z0 - z_s" in glare and "surface z0 = 30 cm" in glare and "horn z_s = 0 cm" in glare


def test_demo_spectrum_window_is_where_the_summary_says(monkeypatch, tmp_path):
    """The horn at y = -0.25 m lights the letter from -y: its wave runs towards +y across
    the array (q0 > 0, exp(i q0 y) under exp(-i omega t)). The recorded field is the
    object times exp(i q0 y), whose spectrum is F(q - q0): the array's |q| <= nu records
    the object's frequencies around -q0. The figure's rectangle is centred there, and
    the summary says both numbers."""
    from matplotlib.patches import Rectangle

    from holoradar.app import demo

    figs = _kept_figures(monkeypatch)
    s = demo.run_demo(tmp_path / "demo", upsample=1)
    p0, q0 = s["theory"]["illumination_p0_q0_rad_per_m"]
    assert q0 > 0 and abs(p0) < 1e-9
    assert s["theory"]["window_center_in_object_spectrum_rad_per_m"] == [-p0, -q0]
    fig = next(f for f in figs if "spectrum" in f.axes[0].get_title())
    rect = next(a for a in fig.axes[0].patches if isinstance(a, Rectangle)
                and a.get_label() == "spectral window")
    cx = rect.get_x() + rect.get_width() / 2
    cy = rect.get_y() + rect.get_height() / 2
    assert (cx, cy) == pytest.approx((-p0, -q0), abs=1e-9)
