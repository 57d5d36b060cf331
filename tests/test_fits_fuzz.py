"""Fits that never crash: the default fits over random scenes, noise levels, grids and
bands answer (or refuse in one line, a ValueError naming what is wrong); no other
exception reaches the user (hypothesis draws the scenes)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import holoradar as hr

_QUIET = settings(deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)


@pytest.mark.slow   # several seconds an example where the exact image-source fit runs
@settings(_QUIET, max_examples=40)
@given(n=st.integers(6, 20), pitch=st.floats(0.005, 0.03), z0=st.floats(0.05, 0.5),
       eps=st.floats(1.5, 20), depth=st.floats(0.0, 0.3), amp=st.floats(1e-4, 1.0),
       snr=st.floats(0, 60), zs=st.floats(-0.3, -0.01), f=st.floats(2e9, 20e9))
def test_the_glare_fits_answer_or_refuse(n, pitch, z0, eps, depth, amp, snr, zs, f):
    g = hr.Medium.half_space(z0, eps)
    scene = hr.Scene(g, hr.PointSource((0.0, 0.0, zs)),
                     [hr.PointTarget((0.01, 0.0, z0 + depth + 0.01), amp)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            h = hr.simulate(scene, hr.Aperture.grid(n, pitch), f, snr_db=snr, seed=1)
        except ValueError:
            return
        for method in ("gaussian", "cut", "image_source"):
            try:
                hr.suppress_surface(h, g, method=method, direct=method != "image_source")
            except ValueError:
                pass
        try:
            hr.estimate_permittivity(h, g)
        except ValueError:
            pass


@pytest.mark.slow
@settings(_QUIET, max_examples=12)
@given(n=st.integers(8, 20), pitch=st.floats(0.008, 0.03), z0=st.floats(0.05, 0.4),
       eps=st.floats(1.5, 12), depth=st.floats(0.02, 0.3), snr=st.floats(0, 50),
       nf=st.sampled_from([1, 3, 7]), target=st.sampled_from(["point", "line", "sphere"]))
def test_autofocus_answers_or_refuses(n, pitch, z0, eps, depth, snr, nf, target):
    g = hr.Medium.half_space(z0, eps)
    f = np.linspace(8e9, 12e9, nf) if nf > 1 else 10e9
    tg = hr.LineTarget((-0.3, 0.0, z0 + depth), (0.3, 0.0, z0 + depth), 0.006) \
        if target == "line" else hr.PointTarget((0.0, 0.01, z0 + depth))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            h = hr.simulate(hr.Scene(g, hr.PlaneWave(), [tg]), hr.Aperture.grid(n, pitch), f,
                            include_surface=False, snr_db=snr, seed=2)
        except ValueError:
            return
        kw = {"sphere_radius": 0.01} if target == "sphere" else {}
        try:
            res = hr.autofocus(h, medium_model=lambda e: hr.Medium.half_space(z0, e),
                               target=target, **kw)
        except ValueError:
            return
    assert res.determinable or res.reason   # an answer, or not determinable with why

