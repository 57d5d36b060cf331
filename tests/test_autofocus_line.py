"""autofocus(target="line"): the asymptotic line model, its exact finish, rods and mats.

The search runs on the line's asymptotic field (rays through the layers, stationary
phase along the line: holoradar.physics.line_green) and finishes with the exact finite
line (LineResponse). The tests check the asymptotic model against the exact one, its
smoothness (the fits' finite differences), the exact finish, the recovery of eps' on
simulated bars, the radius check; the FDTD rod and a rebar mat are slow.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest

import holoradar as hr
from conftest import DATA
from holoradar.imaging.line_response import LineRayResponse, LineResponse

SAND = 2.5
F_BAND = np.linspace(9e9, 11e9, 3)


def _sand(eps: float) -> hr.Medium:
    return hr.Medium.half_space(0.30, eps * (1 + 0.005j))


def _rod_hologram(freqs=F_BAND, n=16, pitch=0.02, snr_db=None, seed=0):
    """A 20 cm bar (7.5 mm radius) 10 cm deep in sand along y, lit by a y-dipole held
    low beside the array (the FDTD fixture's geometry), E_y recorded."""
    rod = hr.LineTarget((0.01, -0.1, 0.40), (0.01, 0.1, 0.40), 0.0075)
    dip = hr.Dipole((-0.2, 0.0, 0.2), moment=(0, 1, 0))
    return hr.simulate(hr.Scene(_sand(SAND), dip, [rod]),
                       hr.Aperture.grid(n, pitch, polarization=(0, 1, 0)), freqs,
                       include_surface=False, snr_db=snr_db, seed=seed)


def _coherence(a: np.ndarray, b: np.ndarray) -> float:
    return float(abs(np.vdot(a, b)) / (np.linalg.norm(a) * np.linalg.norm(b)))


# ----------------------------------------------------------------- the ray model
@pytest.mark.parametrize(("source", "pol"), [
    (hr.Dipole((-0.2, 0.0, 0.2), moment=(0, 1, 0)), (0, 1, 0)),
    (hr.PlaneWave(polarization=(0, 1, 0)), (0, 1, 0)),
    # TM waves (vertical fields in the ground both ways): an x-dipole, E_x recorded.
    (hr.Dipole((-0.2, 0.05, 0.2), moment=(1, 0, 0)), (1, 0, 0))])
def test_ray_model_is_the_exact_line(source, pol):
    """The asymptotic hologram of a line against the exact one (Gauss-Legendre nodes,
    Sommerfeld tables), both for the same line. The rays' leading order leaves relative
    errors of order 1/(k_m d) on the ground leg (d the depth, 10 cm: 1/33) and 1/(k R)
    on the air legs (R >= 0.3 m: 1/60); the ends' diffraction (10-20% of a 15-20 cm
    line's field at the elements beyond it) takes the amplitude of the stationary point,
    which the spreading changes by 10-20% over that distance: 2-4% of the field. An
    error e of the field, not common to all elements (a common amplitude and phase
    cancel), costs 1 - coherence of about e^2/2: with e = 0.05, 1.5e-3 (measured 1e-4 to
    9e-4). A line 1 cm away is far below it. (Cross-polar set-ups, where the recorded
    component is one the leading order nearly cancels, and lines lit end-on, whose
    echo is their ends' diffraction, reach 1e-2: the exact finish corrects them.)"""
    h = hr.simulate(hr.Scene(_sand(SAND), source, [hr.PointTarget((0, 0, 0.4))]),
                    hr.Aperture.grid(16, 0.02, polarization=pol), F_BAND,
                    include_surface=False)
    exact = LineResponse(h, _sand, coherent=True, radius=0.0075)
    fast = LineRayResponse(h, _sand, coherent=True, radius=0.0075)
    for xy, z in [((0.01, 0.0, np.pi / 2, 0.2), 0.40), ((0.02, 0.03, 1.2, 0.15), 0.42)]:
        ge, gf = exact.response_once(SAND, z, xy), fast.response(SAND, z, xy)
        assert 1 - _coherence(ge, gf) < 1.5e-3, (xy, z)
        for f in range(len(F_BAND)):      # each frequency too
            assert 1 - _coherence(ge[f], gf[f]) < 1.5e-3, (xy, f)
        # Same normalisation: the common complex factor is near 1 (the leading order's
        # amplitude; measured within 4% and 2 degrees).
        ratio = np.vdot(ge, gf) / np.vdot(ge, ge)
        assert abs(abs(ratio) - 1) < 0.1 and abs(np.angle(ratio)) < 0.1
    assert _coherence(exact.response_once(SAND, 0.40, (0.01, 0.0, np.pi / 2, 0.2)),
                      fast.response(SAND, 0.40, (0.02, 0.0, np.pi / 2, 0.2))) < 0.9


def test_ray_model_is_smooth_in_its_parameters():
    """The fits' Jacobians are finite differences of steps ~1e-8 m: the model must be
    smooth at that scale (the stationary point solved to rounding, no switch between
    iterations): forward differences of 1e-8 and 1e-7 m agree to the second order's
    1e-6 (a model with a jump of 1e-9 of its value would differ by 0.1 and more)."""
    h = _rod_hologram()
    fast = LineRayResponse(h, _sand, coherent=True, radius=0.0075)
    xy = np.array([0.004, 0.003, np.pi / 2 + 0.05, 0.2])
    g0 = fast.response(SAND, 0.401, xy)
    for axis in range(4):
        d = []
        for step in (1e-8, 1e-7):
            dv = np.zeros(5)
            dv[axis if axis < 2 else axis + 1] = step
            d.append((fast.response(SAND, 0.401 + dv[2], xy + np.r_[dv[:2], dv[3:]]) - g0)
                     / step)
        assert np.linalg.norm(d[0] - d[1]) < 1e-4 * np.linalg.norm(d[1]), axis
    d = [(fast.response(SAND, 0.401 + s, xy) - g0) / s for s in (1e-8, 1e-7)]
    assert np.linalg.norm(d[0] - d[1]) < 1e-4 * np.linalg.norm(d[1])


def test_corrected_model_is_the_exact_one_where_corrected():
    """correct_to: the asymptotic model times the exact/asymptotic ratio at one line is
    the exact model there (to rounding, the regularisation aside: it damps samples
    weaker than a hundredth of the rms, and the others by 1e-4), and close to it
    nearby (2 mm, 4% in eps': the correction's change over the step, 6e-7 measured)."""
    h = _rod_hologram()
    exact = LineResponse(h, _sand, coherent=True, radius=0.0075)
    fast = LineRayResponse(h, _sand, coherent=True, radius=0.0075)
    xy = (0.01, 0.0, np.pi / 2, 0.2)
    fast.correct_to(exact, SAND, 0.40, xy)
    assert 1 - _coherence(exact.response_once(SAND, 0.40, xy),
                          fast.response(SAND, 0.40, xy)) < 1e-6
    near = (0.012, 0.0, np.pi / 2, 0.2)
    assert 1 - _coherence(exact.response_once(2.6, 0.398, near),
                          fast.response(2.6, 0.398, near)) < 1e-4


# ---------------------------------------------------------------- autofocus
def test_autofocus_recovers_a_simulated_bar():
    """A bar in sand lit by a dipole beside the array (16 x 16 at 2 cm, 9-11 GHz in 11
    steps, 40 dB): eps' within its 95% interval, the bar where it lies, its azimuth and
    length found (the ends' diffraction is in the data)."""
    h = _rod_hologram(np.linspace(9e9, 11e9, 11), snr_db=40, seed=3)
    res = hr.autofocus(h, medium_model=_sand(3.0), target="line", line_radius=0.0075)
    assert res.determinable, res.reason
    assert res.eps_interval[0] < SAND < res.eps_interval[1]
    assert np.ptp(res.eps_interval) / res.eps < 0.1
    assert abs(res.position[0] - 0.01) < 0.003 and abs(res.position[2] - 0.40) < 0.003
    assert abs(res.line_azimuth_deg - 90) < 2 and abs(res.line_length - 0.2) < 0.02


@pytest.mark.parametrize("radius", [0.0, -0.006, np.nan, np.inf, "thick"])
def test_line_radius_must_be_a_positive_finite_length(radius):
    h = _rod_hologram()
    with pytest.raises(ValueError, match="line_radius"):
        hr.autofocus(h, medium_model=_sand(3.0), target="line", line_radius=radius)


# ------------------------------------------------------------------- slow cases
def _fdtd_rod() -> hr.Hologram:
    """gprMax run C - run B (tests/data/README.md): a PEC rod 15 mm across, 30 cm long
    along y, axis 10 cm deep in sand (range 0.40 m), lit by a y-directed Hertzian
    dipole 10 cm above the sand, 20 cm aside; E_y on 41 x 41 receivers, 21 frequencies.
    The fixture's transfer functions are E/I; the dipole's moment is i I dl/omega and
    holoradar's Dipole field is 4 pi eps0/k^2 times the physical one, so E/I is f times
    the field of a fixed moment (up to one constant): divided by f, the data are what
    the model with one amplitude for all frequencies describes."""
    with np.load(DATA / "run_B_background.npz") as b, np.load(DATA / "run_C_rod.npz") as c:
        f = b["freqs_hz"].copy()
        scat = c["Ey"].astype(complex) - b["Ey"].astype(complex)
        x, y = b["x_m"].copy(), b["y_m"].copy()
    return hr.Hologram(scat / (f[:, None, None] / 1e10), x, y, f,
                       source=hr.Dipole((-0.20, 0.0, 0.20), moment=(0, 1, 0)),
                       polarization=(0, 1, 0))


@pytest.mark.slow
def test_fdtd_rod_eps_from_the_line_fit():
    """The FDTD rod: eps' within an interval that holds the sand's 2.5 (the FDTD's
    dispersion moves the apparent eps' by about +3%) and is at most 20% wide; the rod
    along y at x = 0, its length 0.30 m (measured: 2.42 in [2.28, 2.58], 12% wide,
    length 0.300 m, F = 0.998; 8-10 s on two cores)."""
    sand = hr.Medium.half_space(0.30, hr.permittivity(2.5, sigma=0.0069, frequency=10e9))
    t0 = time.perf_counter()
    res = hr.autofocus(_fdtd_rod(), medium_model=sand, target="line", line_radius=0.0075)
    seconds = time.perf_counter() - t0
    assert res.determinable, res.reason
    lo, hi = res.eps_interval
    assert lo <= 2.5 <= hi, (res.eps, res.eps_interval)
    assert (hi - lo) / res.eps <= 0.20, (res.eps, res.eps_interval)
    assert abs(res.position[0]) < 0.0075 and abs(res.line_azimuth_deg - 90) < 1
    assert abs(res.line_length - 0.30) < 0.02
    print(f"FDTD rod: eps' {res.eps:.3f} in {lo:.3f}..{hi:.3f}, {seconds:.1f} s")


@pytest.mark.slow
def test_rebar_mat_eps_from_its_bars():
    """A rebar mat in concrete (6 + 0.3j): bars along x under 4 cm of cover and bars
    along y under 6 cm, 15 cm apart, 12 mm, a y-polarised plane wave, E_y on the paper's
    16 x 16 array, 8-12 GHz in 21 steps, 30 dB. One line explains a third of the data;
    the four fitted together explain it all: eps' within an interval that holds 6 and
    is at most 20% wide (measured 5.99 in [5.66, 6.35], 12% wide; 12 s on two cores)."""
    z0, r = 0.20, 0.006
    concrete = hr.Medium.half_space(z0, 6 + 0.3j)
    top = [hr.LineTarget((-0.3, y, z0 + 0.04 + r), (0.3, y, z0 + 0.04 + r), r)
           for y in (-0.075, 0.075)]
    bottom = [hr.LineTarget((x, -0.3, z0 + 0.06 + r), (x, 0.3, z0 + 0.06 + r), r)
              for x in (-0.075, 0.075)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        h = hr.simulate(hr.Scene(concrete, hr.PlaneWave(polarization=(0, 1, 0)),
                                 top + bottom),
                        hr.Aperture.grid(16, 0.025, polarization=(0, 1, 0)),
                        np.linspace(8e9, 12e9, 21), include_surface=False, snr_db=30, seed=1)
        t0 = time.perf_counter()
        res = hr.autofocus(h, medium_model=hr.Medium.half_space(z0, 5.0 * (1 + 0.05j)),
                           target="line", line_radius=r)
    seconds = time.perf_counter() - t0
    assert res.determinable, res.reason
    lo, hi = res.eps_interval
    assert lo <= 6 <= hi and (hi - lo) / res.eps <= 0.20, (res.eps, res.eps_interval)
    assert res.focus_fraction > 0.99
    print(f"rebar mat: eps' {res.eps:.3f} in {lo:.3f}..{hi:.3f}, {seconds:.1f} s")


def test_the_parabolas_find_the_vertex_of_an_exact_parabola():
    # A focus that is exactly a parabola in log eps' with its top at eps' = 5.3: the
    # successive parabolas through the best three trials land on its vertex (one step
    # from three exact samples), to 1e-3 relative. A vertex taken with the wrong sign
    # walks away from the top (each move is bounded, so it never reaches it).
    from holoradar.imaging.autofocus.line_search import _parabolas

    class Search:
        lo, hi = 1.5, 16.0

        def __init__(self) -> None:
            self.best: dict[float, tuple[float]] = {}

        def evaluate(self, e: float) -> None:
            self.best[e] = (-(np.log(e) - np.log(5.3)) ** 2,)

    found = _parabolas(Search(), 5.0, 0.02)
    assert abs(found / 5.3 - 1) < 1e-3
