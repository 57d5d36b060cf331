"""hr.detect on a plane without its hologram: the aperture's point response, sidelobes."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from holoradar.analysis.detect import detect
from holoradar.analysis.detect.grid import as_volume
from holoradar.analysis.detect.psf import ApertureModel, pad_variants, pitch_candidates

warnings.filterwarnings("ignore", category=hr.AliasingWarning)

SAND = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
# A noise maximum passes with probability false_alarm per resolution cell: the paper's
# array images about 100 cells at 42 cm, so at 1e-5 a false object from the noise has
# probability 1e-3 and any extra object is a sidelobe or a model's residue.
FA = 1e-5


def _plane(targets, seed=3, z=0.42, snr_db=40):
    scene = hr.Scene(SAND, hr.PlaneWave(), targets)
    h = hr.simulate(scene, hr.Aperture.paper(), 9.9e9, include_surface=False, snr_db=snr_db,
                    seed=seed)
    return h, hr.migrate(h, z, medium=SAND, upsample=4)


def _cell(h):
    # Lateral resolution lambda L / A at the apparent distance of 42 cm in the sand.
    return hr.theory.lateral_resolution(h.wavelength, SAND.apparent_distance(0.42), 0.40)


def test_strong_and_weak_point_20_db_apart_on_a_plane_without_the_hologram():
    # The image's first sidelobes are 13 dB down and its far ones stand 30-50 dB above
    # the noise of a 40 dB hologram (64 dB in the image): each must be explained by the
    # strong point's response. Before, the analytic sinc reported 25 objects here.
    h, img = _plane([hr.PointTarget((-0.06, 0.03, 0.42), 1.0),
                     hr.PointTarget((0.08, -0.05, 0.42), 0.1)])
    df = detect(img, medium=SAND, false_alarm=FA)
    assert len(df) == 2, df[["x", "y", "snr_db"]]
    cell = _cell(h)
    strong, weak = df.iloc[0], df.iloc[1]
    assert abs(strong.x + 0.06) < cell / 4 and abs(strong.y - 0.03) < cell / 4
    assert abs(weak.x - 0.08) < cell / 4 and abs(weak.y + 0.05) < cell / 4
    # 20 dB apart (equal ranges; the paths differ by a fraction of a dB).
    assert strong.amplitude_db - weak.amplitude_db == pytest.approx(20.0, abs=1.0)


def test_single_strong_point_is_one_object():
    h, img = _plane([hr.PointTarget((0.03, -0.02, 0.42))], seed=5)
    df = detect(img, medium=SAND, false_alarm=FA)
    assert len(df) == 1, df[["x", "y", "snr_db"]]
    assert df.snr_db.iloc[0] > 60          # 40 dB per element, 24 dB of array gain
    cell = _cell(h)
    assert abs(df.x.iloc[0] - 0.03) < cell / 4 and abs(df.y.iloc[0] + 0.02) < cell / 4
    # The response is the exact one: what it leaves on the main lobe and the first
    # sidelobes is below the noise (the error measure's floor).
    assert df.model_error_db.iloc[0] < -30


def test_the_pitch_is_read_off_the_data():
    # The paper's 2.5 cm pitch aliases at 9.9 GHz (lambda/2 = 1.5 cm): a point near the
    # corner images through aliased components, and only the true pitch (4 pixels at
    # upsample=4) explains its sidelobes; a finer pitch leaves 2 % of the fit box.
    _, img = _plane([hr.PointTarget((0.12, 0.10, 0.42))])
    vol = as_volume(img)
    model = ApertureModel(vol, SAND)
    model.detection = (1e9, 10.0)          # bright: choose the pitch
    m, _, info = model.fit(vol.data.copy(), (0, 0, 0), (0.12, 0.10, 0.42))
    assert info["pitch_upsample"] == 4
    r = vol.data - m
    assert np.linalg.norm(r) / np.linalg.norm(vol.data) < 1e-2   # noise: -24 dB per pixel


def test_a_point_off_the_plane_is_fitted_in_range():
    # 3 cm beyond the imaged plane: defocused sidelobes (filled nulls, curved phase) that
    # the in-focus response would leave as objects. The fitted range is within a quarter
    # of the longitudinal resolution (7 lambda (L/A)^2 for one frequency).
    h, img = _plane([hr.PointTarget((0.02, -0.01, 0.45))], seed=1)
    df = detect(img, medium=SAND, false_alarm=FA)
    assert len(df) == 1
    L = SAND.apparent_distance(0.45)
    longitudinal = hr.theory.longitudinal_resolution(h.wavelength, L, 0.40)
    assert abs(df["range"].iloc[0] - 0.45) < longitudinal / 4


def test_pitch_candidates_and_pad_variants():
    # Pitches up to lambda/2 image alike: only the coarsest of them is a candidate.
    assert pitch_candidates(61, 61, 0.00625, 0.00625, 0.0303) == [2, 3, 4, 5, 6]
    # 2 z / d = 80 exactly: the FFT grid depends on the pitch's last bit; both tried.
    v = pad_variants((24, 24), (0.0125, 0.0125), 0.0303, 0.5)
    assert len(v) == 2 and all(isinstance(f, float) for f in v)
