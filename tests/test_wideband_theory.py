"""Range resolution, unambiguous range and the monostatic sampling limit (holoradar.theory).

Checked against the range response computed here directly: a point at range z
seen at frequencies f_m returns phases exp(i f2 k_m Re(n) z) (f2 = 2 monostatic,
1 + cos(theta_i) for an array lit at theta_i); the coherent sum over the band
is the range response.
"""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from holoradar import theory
from holoradar.analysis.metrics import main_lobe_width


def _response(freqs, n, f2, z):
    k = 2 * np.pi * freqs / hr.C0
    return np.abs(np.exp(1j * f2 * n * np.outer(z, k)).sum(axis=1))


@pytest.mark.parametrize(("eps", "monostatic", "incidence"), [
    (1.0, True, 0.0), (6.0, True, 0.0), (2.5, False, 0.0), (4.0, False, np.radians(30))])
def test_range_resolution_is_the_first_null_of_the_range_response(eps, monostatic, incidence):
    # 401 frequencies over 8-12 GHz: the discrete band's first null,
    # c/(f2 n N df), differs from the continuous c/(f2 n B) by 1/N = 0.25%: allow 1%.
    freqs = np.linspace(8e9, 12e9, 401)
    n = np.sqrt(eps)
    f2 = 2.0 if monostatic else 1 + np.cos(incidence)
    z = np.linspace(-0.1, 0.1, 20001)
    half = main_lobe_width(_response(freqs, n, f2, z), z) / 2
    got = theory.range_resolution(4e9, eps, monostatic=monostatic, incidence=incidence)
    assert got == pytest.approx(half, rel=0.01)


def test_unambiguous_range_is_the_period_of_the_range_response():
    freqs = 9e9 + 400e6 * np.arange(11)
    period = theory.unambiguous_range(400e6, 2.5)
    z = np.array([0.013, 0.013 + period, 0.013 + 2 * period])
    r = _response(freqs, np.sqrt(2.5), 2.0, z)
    np.testing.assert_allclose(r, r[0], rtol=1e-9)


def test_monostatic_pitch_samples_the_round_trip():
    # A wave returning from 89.9 degrees carries 2 k sin(theta) ~ 2k: at the limit pitch
    # s = lambda/4 that is just below the Nyquist wavenumber pi/s.
    f = 11e9
    s = theory.max_monostatic_pitch(f)
    k = 2 * np.pi * f / hr.C0
    assert 2 * k * np.sin(np.radians(89.9)) < np.pi / s
    assert 2 * k > np.pi / (1.01 * s)


def test_wideband_theory_bad_input():
    with pytest.raises(ValueError, match="bandwidth"):
        theory.range_resolution(0.0)
    with pytest.raises(ValueError, match="incidence"):
        theory.range_resolution(1e9, monostatic=False, incidence=2.0)
    with pytest.raises(ValueError, match="frequency_step"):
        theory.unambiguous_range(-1.0)
