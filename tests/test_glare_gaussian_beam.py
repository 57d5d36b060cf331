"""Glare of a Gaussian-beam horn (the paper's own model of the radiator): every method of
suppress_surface takes a GaussianBeam; its glare is the beam reflected by the ground, its
incoming beam crossing the array is the direct wave, and both are removed."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr

F = 9.9e9
SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
TARGET = (0.03, 0.02, 0.42)
AP = hr.Aperture.grid(32, 0.0125)


def _scene(alpha_deg: float, waist_z: float = 0.0):
    a = np.radians(alpha_deg)
    # The beam's waist on the array plane (or above the sand), aimed so that its axis
    # meets the surface under the array's centre: incoming and reflected beams both
    # cross the array.
    beam = hr.GaussianBeam(0.06, center=(-(0.30 - waist_z) * np.tan(a), 0.0, waist_z), alpha=a)
    scene = hr.Scene(SAND, beam, [hr.PointTarget(TARGET, 0.02)])
    full = hr.simulate(scene, AP, F, include_direct=True)
    objects = hr.simulate(scene, AP, F, include_surface=False)
    return beam, full, objects


def _kept(clean: hr.Hologram, objects: hr.Hologram) -> float:
    """The object's share left in the cleaned data: its projection on the object alone."""
    t = objects.data.ravel()
    return float(abs(np.vdot(t, clean.data.ravel())) / np.vdot(t, t).real)


@pytest.mark.parametrize("method, alpha", [
    ("gaussian", 0.0), ("gaussian", 30.0), ("image_source", 0.0),
    pytest.param("image_source", 20.0, marks=pytest.mark.slow)])  # 11 s: make test-slow
def test_beam_glare_and_direct_wave_removed_object_kept(method, alpha):
    """Glare and direct beam 20-23 dB above the object. Required: the glare's spot down
    by >= 20 dB, >= 80% of the object kept, and the object the brightest thing of the
    image through the sand at its lateral position (within one pixel, 6.25 mm)."""
    beam, full, objects = _scene(alpha, waist_z=0.15 if alpha == 30.0 else 0.0)
    clean, rep = hr.suppress_surface(full, SAND, beam, method=method)
    assert rep.glare_suppression_db >= 20
    assert 0.8 <= _kept(clean, objects) <= 1.2
    img = hr.migrate(clean, np.arange(0.36, 0.48, 0.005), medium=SAND, upsample=2)
    x, y, _ = img.peak()
    assert abs(x - TARGET[0]) <= 0.00625 and abs(y - TARGET[1]) <= 0.00625
    if method == "image_source":
        # The reflected beam's strength against the incoming one (the direct wave in
        # the data) gives eps, biased by the object by at most 4 n |V| e / (1 + V)^2
        # (relative), e the object's amplitude relative to the glare's.
        glare = hr.simulate(hr.Scene(SAND, beam, []), AP, F)
        e = np.linalg.norm(objects.data) / np.linalg.norm(glare.data)
        n = np.sqrt(2.5)
        v = (1 - n) / (1 + n)
        assert abs(rep.eps.real - 2.5) / 2.5 <= 4 * n * abs(v) * e / (1 + v) ** 2


def test_cut_and_background_take_a_beam_too():
    beam, full, objects = _scene(0.0)
    clean, rep = hr.suppress_surface(full, SAND, beam, method="cut")
    # The cut disk covers two waists of the mirror spot (-35 dB of the beam's amplitude):
    # the spot goes down by more than 20 dB; objects under the spot are bitten with it
    # (the cut's known weakness, paper Fig. 14), so nothing is claimed for them.
    assert rep.glare_suppression_db >= 20
    empty = hr.simulate(hr.Scene(SAND, beam, []), AP, F, include_direct=True)
    clean, rep = hr.suppress_surface(full, SAND, beam, method="background", background=empty)
    assert np.allclose(clean.data, objects.data, rtol=0, atol=1e-12 * np.abs(full.data).max())


def test_beam_waist_below_the_surface_is_refused():
    beam = hr.GaussianBeam(0.05, center=(0.0, 0.0, 0.35))
    h = hr.simulate(hr.Scene(SAND, hr.GaussianBeam(0.05), []), AP, F)
    with pytest.raises(ValueError, match="waist"):
        hr.suppress_surface(h, SAND, beam, method="gaussian")


def test_image_source_refuses_a_direct_wave_reference_the_data_lack():
    # The image-source fit takes the glare's strength relative to the direct wave; with no
    # direct wave in the data its fitted amplitude is noise and eps runs off (1e6 was
    # seen). Both entry points refuse alike, naming the way out.
    m = hr.Medium.half_space(0.30, 2.5)
    h = hr.simulate(hr.Scene(m, hr.PointSource((0.0, -0.05, 0.0))), hr.Aperture.grid(16, 0.02),
                    9.9e9, include_direct=False, snr_db=40, seed=0)
    with pytest.raises(ValueError, match="direct=False"):
        hr.suppress_surface(h, m, method="image_source", direct=True)
    with pytest.raises(ValueError, match="direct=False"):
        hr.estimate_permittivity(h, m, direct=True)
    _, rep = hr.suppress_surface(h, hr.Medium.half_space(0.30, 3.0), method="image_source",
                                 direct=False)
    assert abs(rep.eps.real - 2.5) < 2.5 * rep.eps_std[0]
