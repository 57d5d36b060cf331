"""StreamImager: the per-frame pipeline equals the general functions it speeds up."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from conftest import F0

SAND = hr.Medium.half_space(0.30, 2.5 * (1 + 0.005j))
HORNS = [hr.PointSource((0.0, y0, -0.05), pattern_exponent=2.0)
         for y0 in np.linspace(-0.15, 0.15, 4)]
TARGETS = [hr.PointTarget((0.04, -0.02, 0.42), amplitude=0.02)]


@pytest.fixture(scope="module")
def views():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        return [hr.simulate(hr.Scene(SAND, s, TARGETS), hr.Aperture.paper(), F0,
                            include_direct=True) for s in HORNS]


def test_without_suppression_equals_synthesize(views):
    # Same operators, cached: identical to machine precision.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        imager = hr.StreamImager(views, 0.42, SAND, suppress=False)
        ref = hr.synthesize(views, 0.42, medium=SAND, upsample=4, fov="full",
                              dtype=np.complex128)
    out = imager(np.stack([v.data for v in views]))
    np.testing.assert_allclose(out.x, ref.x)
    np.testing.assert_allclose(out.y, ref.y)
    assert np.linalg.norm(out.data - ref.data) <= 1e-12 * np.linalg.norm(ref.data)


def test_tracked_suppression_equals_per_view_fits(views):
    # One warm-started Gauss-Newton step per frame reaches the full least-squares fit
    # of suppress_surface (same model): the images agree to 1e-3, and the glare left is
    # tens of dB below what it was.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        imager = hr.StreamImager(views, 0.42, SAND)
        cleaned = [hr.suppress_surface(v, SAND, s, "gaussian")[0]
                   for v, s in zip(views, HORNS, strict=True)]
        ref = hr.synthesize(cleaned, 0.42, medium=SAND, upsample=4, fov="full")
        raw = hr.synthesize(views, 0.42, medium=SAND, upsample=4, fov="full")
        clean = [hr.simulate(hr.Scene(SAND, s, TARGETS), hr.Aperture.paper(), F0,
                             include_surface=False) for s in HORNS]
        ideal = hr.synthesize(clean, 0.42, medium=SAND, upsample=4, fov="full")
    data = np.stack([v.data for v in views])
    for _ in range(3):
        out = imager(data)
    assert np.linalg.norm(out.data - ref.data) <= 1e-3 * np.linalg.norm(ref.data)
    before = np.linalg.norm(raw.data - ideal.data)
    after = np.linalg.norm(out.data - ideal.data)
    assert 20 * np.log10(before / after) > 20


def test_frame_shape_is_checked(views):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        imager = hr.StreamImager(views, 0.42, SAND, suppress=False)
    with pytest.raises(ValueError, match="data must have shape"):
        imager(np.zeros((3, 16, 16)))


def test_tracking_follows_a_changing_ground():
    # Start on one ground, then image frames of a wetter one (eps' 2.5 -> 3.2: the glare
    # grows by 2.5 dB and changes shape). After a few warm-started steps the glare left
    # in the image must be as low as with a full least-squares fit of every view (within
    # 1 dB; the waist is weakly determined, so the two may settle on different waists).
    wet = hr.Medium.half_space(0.30, 3.2 * (1 + 0.005j))
    ap = hr.Aperture.paper()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        first = [hr.simulate(hr.Scene(SAND, s, TARGETS), ap, F0, include_direct=True)
                 for s in HORNS]
        later = [hr.simulate(hr.Scene(wet, s, TARGETS), ap, F0, include_direct=True)
                 for s in HORNS]
        clean = [hr.simulate(hr.Scene(wet, s, TARGETS), ap, F0, include_surface=False)
                 for s in HORNS]
        imager = hr.StreamImager(first, 0.42, SAND)
        cleaned = [hr.suppress_surface(v, SAND, s, "gaussian")[0]
                   for v, s in zip(later, HORNS, strict=True)]

        def image(hs):
            return hr.synthesize(hs, 0.42, medium=SAND, upsample=4, fov="full").data

        ideal, full_fit, raw = image(clean), image(cleaned), image(later)
    data = np.stack([v.data for v in later])
    for _ in range(4):
        out = imager(data).data
    glare = np.linalg.norm(raw - ideal)
    tracked_db = 20 * np.log10(glare / np.linalg.norm(out - ideal))
    full_db = 20 * np.log10(glare / np.linalg.norm(full_fit - ideal))
    assert tracked_db > full_db - 1.0
    assert tracked_db > 20


def test_bad_frames_are_refused(views):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        imager = hr.StreamImager(views, 0.42, SAND)
        with pytest.raises(ValueError, match="z must be one range"):
            hr.StreamImager(views, [0.4, 0.42], SAND)
    bad = np.stack([v.data for v in views])
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="data must be finite"):
        imager(bad)
    assert np.all(np.isfinite(imager(np.zeros_like(bad)).data))  # an empty frame is fine
