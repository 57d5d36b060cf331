"""Calibration (holoradar.calibrate): every step recovers a known fault of simulated raw
data to the accuracy its noise allows, and calibration files round-trip exactly.

The device: the paper's 16 x 16 array at 2.5 cm, three frequencies, a horn beside it.
Its faults (the receiver model of holoradar.calibrate.faults): DC offsets per element
and channel, a Q channel with gain 1.15 and phase error 8 degrees, random complex
element gains (uniform phases), a complex response per frequency, I - iQ delivered,
two dead elements and a noisy one, complex receiver noise SIGMA per element.

Tolerances are derived, not tuned: a sum of K squared standard normal z-scores is
chi2(K) (mean K, sd sqrt(2K)); a sum of K values |CN(0, v)|^2/v is Gamma(K, 1) (mean
K, sd sqrt(K)); sums are asserted within 5 sd of their mean, single complex errors
within 5 standard deviations in modulus (P(|CN(0, 1)| > 5) = exp(-25)).
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

import holoradar as hr
from holoradar import calibrate as cb
from holoradar.io.netcdf import source_to_json
from holoradar.io.output import default_mode

X = (np.arange(16) - 7.5) * 0.025
F = np.array([9.5e9, 9.9e9, 10.3e9])
SHAPE = (F.size, X.size, X.size)
HORN = hr.PointSource((0.0, -0.25, -0.05), pattern_exponent=2, axis=(0.0, 0.5, 1.0))
DEVICE = "HSR-0042"
SIGMA = 0.01          # receiver noise, device units (E|n|^2 = SIGMA^2); the plate's field ~1
NREP = 8              # repeats of each reference
NDARK = 32            # dark frames
PLATES = (0.300, 0.304)  # an eighth of a wavelength apart: the two-way phase moves ~90 deg
G_IQ, PHI_IQ = 1.15, np.radians(8.0)
DEAD = [(3, 4), (10, 12)]
NOISY = (7, 1)
RESPONSE = np.array([1.0, 0.7, 1.3]) * np.exp(1j * np.array([0.3, 2.0, -1.2]))


def _gains(seed: int) -> np.ndarray:
    """Random element gains: amplitude spread 20%, phases uniform over the circle."""
    rng = np.random.default_rng(seed)
    return (np.exp(0.2 * rng.standard_normal(SHAPE[1:]))
            * np.exp(2j * np.pi * rng.random(SHAPE[1:])))


def _field(kind: str, z: float | None = None, include_direct: bool | None = None
           ) -> hr.Hologram:
    m = cb.reference_field(kind, X, X, F, HORN, plate_range=z, include_direct=include_direct)
    return hr.Hologram(m, X, X, F, source=HORN)


def _dark_field() -> hr.Hologram:
    return hr.Hologram(np.zeros(SHAPE), X, X, F, source=HORN)


def _survey_truth() -> hr.Hologram:
    scene = hr.Scene(hr.Medium.free_space(), HORN,
                     [hr.PointTarget((0.03, 0.02, 0.40), 0.05),
                      hr.PointTarget((-0.08, 0.05, 0.45), 0.03)])
    return hr.simulate(scene, hr.Aperture.grid(16, 0.025), F)


def _faulty_device() -> tuple[cb.DeviceFaults, dict]:
    rng = np.random.default_rng(11)
    gain = _gains(12)
    for d in DEAD:
        gain[d] = 0.0
    sigma = np.full(SHAPE[1:], SIGMA)
    sigma[NOISY] = 10 * SIGMA
    truth = {"dc_i": 0.2 + 0.05 * rng.standard_normal(SHAPE),
             "dc_q": -0.1 + 0.05 * rng.standard_normal(SHAPE), "gain": gain, "sigma": sigma}
    dev = cb.DeviceFaults(dc_i=truth["dc_i"], dc_q=truth["dc_q"], iq_gain=G_IQ,
                          iq_phase=PHI_IQ, element_gain=gain, response=RESPONSE,
                          conjugate=True, noise=sigma)
    return dev, truth


@pytest.fixture(scope="module")
def fitted():
    """The faulty device, its references, dark frames, calibration and a survey."""
    dev, truth = _faulty_device()
    refs = [cb.Reference(dev.record(_field("plate", z), DEVICE, repeats=NREP, seed=20 + j),
                         "plate", plate_range=z) for j, z in enumerate(PLATES)]
    dark = dev.record(_dark_field(), DEVICE, repeats=NDARK, transmitter=False, seed=30)
    cal = cb.fit_calibration(refs, dark=dark, notes="test bench")
    survey = _survey_truth()
    raw = dev.record(survey, DEVICE, seed=40)
    return {"device": dev, "truth": truth, "refs": refs, "dark": dark, "cal": cal,
            "survey": survey, "raw": raw}


# --- DC offset ------------------------------------------------------------------------
def test_dc_offset_from_dark_frames_to_its_standard_error():
    rng = np.random.default_rng(1)
    dc_i, dc_q = 0.2 + 0.05 * rng.standard_normal(SHAPE), -0.1 + 0.05 * rng.standard_normal(SHAPE)
    dev = cb.DeviceFaults(dc_i=dc_i, dc_q=dc_q, iq_gain=G_IQ, iq_phase=PHI_IQ, noise=SIGMA)
    dark = dev.record(_dark_field(), DEVICE, repeats=NDARK, transmitter=False, seed=2)
    off = cb.dc_offset(*dark.stacked())
    # A dark frame reads dc + noise. The I channel's noise is Re(n), variance SIGMA^2/2;
    # the Q channel's g*(cos(phi) Im n + sin(phi) Re n), variance g^2 SIGMA^2/2. The mean
    # of NDARK frames has SE_I = SIGMA/sqrt(2 NDARK), SE_Q = g SIGMA/sqrt(2 NDARK); the
    # K = 2*768 z-scores squared sum to chi2(K).
    se_i, se_q = SIGMA / np.sqrt(2 * NDARK), G_IQ * SIGMA / np.sqrt(2 * NDARK)
    stat = np.sum(((off.i - dc_i) / se_i) ** 2) + np.sum(((off.q - dc_q) / se_q) ** 2)
    k = 2 * dc_i.size
    assert abs(stat - k) < 5 * np.sqrt(2 * k)
    # The reported standard errors estimate SE_I: each squared is SE_I^2 chi2(n-1)/(n-1);
    # the mean of 768 of them has relative sd sqrt(2/((n-1)*768)).
    tol = 5 * np.sqrt(2 / ((NDARK - 1) * dc_i.size))
    assert abs(np.mean(off.stderr_i**2) / se_i**2 - 1) < tol
    assert abs(np.mean(off.stderr_q**2) / se_q**2 - 1) < tol
    i0, q0 = cb.remove_dc(dark.i, dark.q, off.i, off.q)
    assert np.allclose(i0.mean(axis=0), 0, atol=1e-12)
    assert np.allclose(q0.mean(axis=0), 0, atol=1e-12)


# --- I/Q imbalance --------------------------------------------------------------------
@pytest.mark.parametrize("grouped", [False, True])
def test_iq_standard_error_matches_the_scatter_of_the_estimate(grouped):
    """The estimator's stated accuracy (iq.py's derivation) against 400 trials."""
    rng = np.random.default_rng(3)
    trials, n = 400, 512
    c = np.array([1.0, 1.2, 0.8 * np.exp(0.3j), 1.1 * np.exp(-0.2j)])  # 4 samples share a phase
    est, se_g, se_p = [], [], []
    for _ in range(trials):
        if grouped:
            s = ((rng.standard_normal(n // 4) + 1j * rng.standard_normal(n // 4))[:, None]
                 * c).ravel()
            groups = np.repeat(np.arange(n // 4), 4)
        else:
            s = rng.standard_normal(n) + 1j * rng.standard_normal(n)
            groups = None
        r = cb.iq_imbalance(s.real, G_IQ * (np.cos(PHI_IQ) * s.imag + np.sin(PHI_IQ) * s.real),
                            groups)
        est.append((r.gain, r.phase))
        se_g.append(r.stderr_gain)
        se_p.append(r.stderr_phase)
    est = np.array(est)
    sd_g, sd_p = est[:, 0].std(ddof=1), est[:, 1].std(ddof=1)
    # A standard deviation from T trials has relative sd 1/sqrt(2(T-1)).
    tol = 5 / np.sqrt(2 * (trials - 1))
    assert abs(np.mean(se_g) / sd_g - 1) < tol
    assert abs(np.mean(se_p) / sd_p - 1) < tol
    if not grouped:
        # Independent Gaussian samples: kappa = 2, SE(phi) = SE(g)/g = cos(phi)/sqrt(N).
        theory = np.cos(PHI_IQ) / np.sqrt(n)
        assert abs(sd_p / theory - 1) < tol
        assert abs(sd_g / (G_IQ * theory) - 1) < tol
    # Unbiased to first order: the mean within 5 standard errors of the mean.
    assert abs(est[:, 0].mean() - G_IQ) < 5 * sd_g / np.sqrt(trials)
    assert abs(est[:, 1].mean() - PHI_IQ) < 5 * sd_p / np.sqrt(trials)


@pytest.mark.parametrize("conjugate", [False, True])
def test_iq_imbalance_of_the_device_within_its_standard_error(conjugate):
    dev = cb.DeviceFaults(iq_gain=G_IQ, iq_phase=PHI_IQ, element_gain=_gains(4),
                          response=RESPONSE, conjugate=conjugate, noise=SIGMA)
    raw = dev.record(_field("plate", PLATES[0]), DEVICE, repeats=NREP, seed=5)
    i, q = raw.stacked()
    groups = np.broadcast_to(np.arange(256).reshape(16, 16), SHAPE)
    est = cb.iq_imbalance(i.mean(axis=0), q.mean(axis=0), groups)
    # phi is the Q channel's error as delivered: the sign of the device does not change it
    # (the I/Q sign is found separately).
    assert abs(est.gain - G_IQ) < 5 * est.stderr_gain
    assert abs(est.phase - PHI_IQ) < 5 * est.stderr_phase
    z = cb.correct_iq(i.mean(axis=0), q.mean(axis=0), est.gain, est.phase)
    a, b = cb.iq_residual(G_IQ, PHI_IQ, est.gain, est.phase)
    s = RESPONSE[:, None, None] * _gains(4) * _field("plate", PLATES[0]).data
    s = np.conj(s) if conjugate else s
    # Exact to the noise: z = a s + b conj(s) + (a n + b conj(n)), n the mean noise.
    noise = np.abs(z - (a * s + b * np.conj(s))) / (abs(a) + abs(b))
    assert noise.max() < 5 * SIGMA / np.sqrt(NREP)


def test_iq_standard_error_holds_when_a_few_groups_hold_most_of_the_power():
    """The exact correction's leverage (iq.py): one group of ten holding 45% of the power,
    as the elements nearest the horn do in an empty scene; 1000 trials."""
    rng = np.random.default_rng(21)
    trials, m = 1000, 64                                   # 10 groups of m samples
    share = np.r_[0.45, np.full(9, 0.55 / 9)]
    amp = np.repeat(np.sqrt(share / m), m)                 # constant amplitude in a group
    groups = np.repeat(np.arange(10), m)
    est, var_g, var_p = [], [], []
    for _ in range(trials):
        s = amp * np.exp(2j * np.pi * rng.random(amp.size))
        r = cb.iq_imbalance(s.real, G_IQ * (np.cos(PHI_IQ) * s.imag + np.sin(PHI_IQ) * s.real),
                            groups)
        est.append((r.gain, r.phase))
        var_g.append(r.stderr_gain**2)
        var_p.append(r.stderr_phase**2)
    est = np.array(est)
    for k, v in enumerate((np.array(var_g), np.array(var_p))):
        # The mean squared standard error estimates the estimate's variance: a sample
        # variance of T trials has relative sd sqrt(2/(T-1)), the mean of T squared
        # errors its own sd/sqrt(T) (measured); 5 of their combined sd. The plain sandwich
        # (n/(n-1) times the sum) gives about half the variance here.
        ratio = v.mean() / est[:, k].var(ddof=1)
        tol = 5 * np.sqrt(2 / (trials - 1) + v.var() / (trials * v.mean() ** 2))
        assert abs(ratio - 1) < tol, (k, ratio, tol)


# --- element gains and equalisation ---------------------------------------------------
@pytest.mark.parametrize("kind", ["plate", "empty"])
def test_element_gains_from_a_reference_to_the_noise(kind):
    gain = _gains(6)
    dev = cb.DeviceFaults(element_gain=gain, response=RESPONSE, noise=SIGMA)
    field = _field(kind, PLATES[0] if kind == "plate" else None)
    raw = dev.record(field, DEVICE, repeats=NREP, seed=7)
    i, q = raw.stacked()
    mean = cb.correct_iq(i.mean(axis=0), q.mean(axis=0), 1.0, 0.0)
    est = cb.element_gains(mean, field.data)
    # mean = G M + nbar, nbar ~ CN(0, SIGMA^2/NREP): est - G = nbar/M, so
    # |est - G|^2 NREP |M|^2 / SIGMA^2 ~ Exp(1) each, their sum over K values Gamma(K, 1).
    z2 = np.abs(est - RESPONSE[:, None, None] * gain) ** 2 * NREP * np.abs(field.data) ** 2
    k = z2.size
    assert abs(z2.sum() / SIGMA**2 - k) < 5 * np.sqrt(k)


def test_equalize_frequencies_recovers_each_frequency_response():
    gain = _gains(8)
    dev = cb.DeviceFaults(element_gain=gain, response=RESPONSE, noise=SIGMA)
    field = _field("plate", PLATES[0])
    raw = dev.record(field, DEVICE, repeats=NREP, seed=9)
    i, q = raw.stacked()
    mean = cb.correct_iq(i.mean(axis=0), q.mean(axis=0), 1.0, 0.0)
    mask = np.zeros((16, 16), bool)
    mask[DEAD[0]] = mask[DEAD[1]] = True
    h = cb.equalize_frequencies(mean, field.data, mask)
    # The least-squares response over the good elements is the power-weighted mean gain,
    # H_f = R_f sum |M|^2 g / sum |M|^2, with error sum conj(M) nbar / sum |M|^2 ~
    # CN(0, SIGMA^2/(NREP sum |M|^2)): each |z|^2 ~ Exp(1), below 25 but with exp(-25).
    w = np.abs(field.data) ** 2 * ~mask
    truth = RESPONSE * np.sum(w * gain, axis=(1, 2)) / w.sum(axis=(1, 2))
    z2 = np.abs(h - truth) ** 2 * NREP * w.sum(axis=(1, 2)) / SIGMA**2
    assert z2.max() < 25
    # Relative to it, the element gains have power-weighted mean 1 at every frequency.
    rel = cb.element_gains(mean, field.data, h)
    assert np.allclose(np.sum(w * rel, axis=(1, 2)) / w.sum(axis=(1, 2)), 1, atol=1e-12)


# --- dead and noisy elements ----------------------------------------------------------
def test_dead_and_noisy_elements_flagged_exactly(fitted):
    cal = fitted["cal"]
    # A dead element's gain ratio is ~ SIGMA/(sqrt(NREP)|M| median|G|) ~ 0.005 << 0.1; the
    # noisy one's scatter ratio ~ 10 >> 3; a good element's squared scatter ratio is
    # chi2(nu)/nu with nu = 2*3*(NREP - 1) = 42, above 9 with probability < 1e-30.
    assert sorted(map(tuple, np.argwhere(cal.dead).tolist())) == DEAD
    assert np.argwhere(cal.noisy).tolist() == [list(NOISY)]
    h = cal.apply(fitted["raw"])
    assert np.all(h.data[:, cal.mask] == 0)
    assert np.all(h.data[:, ~cal.mask] != 0)


def test_flagged_elements_interpolated_for_display_only(fitted):
    cal = fitted["cal"]
    h = cal.apply(fitted["raw"])
    shown = cb.interpolate_for_display(h, cal.mask)
    assert np.array_equal(shown.data[:, ~cal.mask], h.data[:, ~cal.mask])
    for iy, ix in np.argwhere(cal.mask):
        nbrs = [(iy + dy, ix + dx) for dy, dx in ((-1, 0), (1, 0), (0, -1), (0, 1))
                if 0 <= iy + dy < 16 and 0 <= ix + dx < 16]
        expect = np.mean([shown.data[:, j, i] for j, i in nbrs], axis=0)
        assert np.allclose(shown.data[:, iy, ix], expect, rtol=1e-12)
    assert np.all(h.data[:, cal.mask] == 0)  # the calibrated data are left as they were


# --- the I/Q sign ---------------------------------------------------------------------
@pytest.mark.parametrize("pair", ["plate-plate", "empty-plate"])
@pytest.mark.parametrize("conjugate", [False, True])
def test_iq_sign_from_two_references(pair, conjugate):
    dev = cb.DeviceFaults(element_gain=_gains(13), response=RESPONSE, conjugate=conjugate,
                          noise=SIGMA)
    if pair == "plate-plate":
        fields = [_field("plate", z) for z in PLATES]
    else:
        fields = [_field("empty"), _field("plate", PLATES[0], include_direct=True)]
    means = []
    for j, fld in enumerate(fields):
        i, q = dev.record(fld, DEVICE, repeats=NREP, seed=50 + j).stacked()
        means.append(cb.correct_iq(i.mean(axis=0), q.mean(axis=0), 1.0, 0.0))
    ma, mb = fields[0].data, fields[1].data
    found = cb.detect_iq_sign(means[0], means[1], ma, mb)
    assert found.sign == ("I-iQ" if conjugate else "I+iQ")
    # The right sign leaves only noise: D_a M_b - D_b M_a = nbar_a M_b - nbar_b M_a, whose
    # |.|^2 has mean w = SIGMA^2/NREP (|M_a|^2 + |M_b|^2) per sample; the sum of w Exp(1)
    # has mean sum(w) and sd sqrt(sum(w^2)).
    da, db = (np.conj(m) for m in means) if conjugate else means
    den = np.sum(np.abs(da * mb) ** 2 + np.abs(db * ma) ** 2)
    right = min(found.residual_plus, found.residual_minus) * den
    w = SIGMA**2 / NREP * (np.abs(ma) ** 2 + np.abs(mb) ** 2)
    assert abs(right - w.sum()) < 5 * np.sqrt(np.sum(w**2))
    wrong = max(found.residual_plus, found.residual_minus)
    assert found.margin_db == pytest.approx(10 * np.log10(wrong * den / right))


# --- everything in order --------------------------------------------------------------
def test_fit_calibration_recovers_every_fault_and_the_field(fitted):
    cal, truth = fitted["cal"], fitted["truth"]
    off = cb.dc_offset(*fitted["dark"].stacked())
    assert np.array_equal(cal.dc_i, off.i) and np.array_equal(cal.dc_q, off.q)
    iq = cal.provenance["iq_imbalance"]
    assert abs(cal.iq_gain[0] - G_IQ) < 5 * iq["stderr_gain"][0]
    assert abs(cal.iq_phase[0] - PHI_IQ) < 5 * iq["stderr_phase_rad"][0]
    assert cal.iq_sign == "I-iQ" and cal.provenance["iq_sign"]["how"] == "detected"
    assert cal.device == DEVICE and cal.provenance["notes"] == "test bench"
    # What is left after the estimated corrections, with the sign undone: z = a' s +
    # b' conj(s) + dz + noise, a' = conj(a), b' = conj(b) from iq_residual, dz the
    # estimated DC's (known) error passed through the correction.
    a, b = cb.iq_residual(G_IQ, PHI_IQ, cal.iq_gain[0], cal.iq_phase[0])
    a, b = abs(a), abs(b)
    dz = np.abs(cb.correct_iq(truth["dc_i"] - cal.dc_i, truth["dc_q"] - cal.dc_q,
                              cal.iq_gain[:, None, None], cal.iq_phase[:, None, None]))
    good = ~cal.mask
    m = _field("plate", PLATES[0]).data
    g_true = RESPONSE[:, None, None] * truth["gain"]
    # Gains: T = conj(zbar)/M = a' G + b' conj(G M)/M + (dz + a' nbar + b' conj(nbar))/M,
    # |nbar| < 5 SIGMA/sqrt(NREP): |T - a' G| <= b |G| + (dz + (a + b) 5 SIGMA/sqrt(NREP))/|M|.
    t = cal.total_gain
    a_phase = np.conj(cb.iq_residual(G_IQ, PHI_IQ, cal.iq_gain[0], cal.iq_phase[0])[0])
    nbar = 5 * truth["sigma"] / np.sqrt(NREP)
    gain_bound = b * np.abs(g_true) + (dz + (a + b) * nbar) / np.abs(m)
    assert np.all((np.abs(t - a_phase * g_true) <= gain_bound)[:, good])
    # The survey (one frame, noise n_s): E_cal - E = [b'(conj(GE) - E conj(GM)/M) +
    # a' n_s + b' conj(n_s) + dz (1 - E/M) - E (a' nbar + b' conj(nbar))/M] / T, bounded
    # term by term with |n_s| < 5 sigma and |T| >= a |G| - gain_bound.
    e = fitted["survey"].data
    h = cal.apply(fitted["raw"])
    num = (2 * b * np.abs(g_true * e) + (a + b) * 5 * truth["sigma"]
           + dz * np.abs(1 - e / m) + np.abs(e) * (a + b) * nbar / np.abs(m))
    bound = num / (a * np.abs(g_true) - gain_bound)
    assert np.all((np.abs(h.data - e) <= bound)[:, good])
    # And as a whole: the calibrated survey is the field to about the noise.
    rel = np.linalg.norm((h.data - e)[:, good]) / np.linalg.norm(e[:, good])
    noise = np.linalg.norm(truth["sigma"][good] / np.abs(truth["gain"][good])) * np.sqrt(F.size)
    assert rel < 2 * noise / np.linalg.norm(e[:, good]) + 2 * b / a
    assert h.source is HORN and np.array_equal(h.frequency, F)
    # What it is for: the calibrated survey focuses where the true field does (the
    # brighter point, 0.40 m); the raw samples read as I + iQ do not.
    zs = np.arange(0.36, 0.48, 0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        peak = hr.migrate(fitted["survey"], zs).peak()
        assert hr.migrate(h, zs).peak() == peak
        raw = fitted["raw"]
        assert hr.migrate(hr.Hologram(raw.i + 1j * raw.q, X, X, F, source=HORN), zs).peak() != peak


@pytest.mark.filterwarnings("ignore::holoradar.calibrate.CalibrationWarning")  # one plate
def test_fit_calibration_refuses_what_cannot_be_told(fitted):
    refs = fitted["refs"]
    with pytest.raises(ValueError, match="two references"):
        cb.fit_calibration(refs[:1])
    assert cb.fit_calibration(refs[:1], iq_sign="I-iQ").iq_sign == "I-iQ"
    same = [refs[0], cb.Reference(refs[0].raw, "plate", plate_range=PLATES[0])]
    with pytest.raises(ValueError, match="tell the I/Q sign by"):
        cb.fit_calibration(same)
    other = cb.RawFrames(refs[1].raw.i, refs[1].raw.q, X, X, F, "HSR-0043", source=HORN)
    with pytest.raises(ValueError, match="one device"):
        cb.fit_calibration([refs[0], cb.Reference(other, "plate", plate_range=PLATES[1])])
    one = cb.RawFrames(refs[0].raw.i[0], refs[0].raw.q[0], X, X, F, DEVICE, source=HORN)
    with pytest.raises(ValueError, match="at least 2 repeats"):
        cb.fit_calibration([cb.Reference(one, "plate", plate_range=PLATES[0]), refs[1]])


def test_fit_calibration_warns_when_the_references_leave_the_iq_imbalance_weak(fitted):
    """A residual image above -40 dB at one standard error is warned of, with the fix."""
    refs = fitted["refs"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", cb.CalibrationWarning)
        pair = cb.fit_calibration(refs)                     # the plate pair: no warning
    iq = pair.provenance["iq_imbalance"]
    se_g, se_p = iq["stderr_gain"][0] / pair.iq_gain[0], iq["stderr_phase_rad"][0]
    # The residual image of iq_residual to first order: sqrt(dg^2/g^2 + dphi^2)/(2 cos phi).
    image = 20 * np.log10(np.hypot(se_g, se_p) / (2 * np.cos(pair.iq_phase[0])))
    assert iq["image_db_at_stderr"][0] == pytest.approx(image, rel=1e-12)
    assert image < -40
    # The first-order law itself: the terms dropped are relative O(dg/g, dphi) (|a| = 1 -
    # dg/(2g) + ..., b's second-order terms), within 4 max(dg/g, dphi) of |b/a|.
    a, b = cb.iq_residual(1.0, 0.0, 1 + se_g, se_p)
    assert abs(abs(b / a) / (np.hypot(se_g, se_p) / 2) - 1) < 4 * max(se_g, se_p)
    # One plate: SE about 3% and 1.8 degrees, -33 dB: warned, naming the fix.
    with pytest.warns(cb.CalibrationWarning, match=r"(?s)poorly.*-3\d dB.*several ranges.*"
                                                   r"second reflector"):
        one = cb.fit_calibration(refs[:1], iq_sign="I-iQ")
    assert -40 < one.provenance["iq_imbalance"]["image_db_at_stderr"][0] < -30
    with warnings.catch_warnings():                         # the limit is the caller's
        warnings.simplefilter("error", cb.CalibrationWarning)
        cb.fit_calibration(refs[:1], iq_sign="I-iQ", max_iq_image_db=-30)


# --- files ----------------------------------------------------------------------------
FIELDS = ("x", "y", "dc_i", "dc_q", "iq_gain", "iq_phase", "response", "gains", "dead",
          "noisy", "frequencies")


def test_calibration_file_round_trip_is_exact(fitted, tmp_path):
    cal = fitted["cal"]
    path = cal.save(tmp_path / "HSR-0042.nc")
    back = cb.Calibration.load(path)
    for name in FIELDS:
        a, b = getattr(cal, name), getattr(back, name)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), name
    assert (back.device, back.iq_sign, back.provenance) == (cal.device, cal.iq_sign,
                                                            cal.provenance)
    assert source_to_json(back.source) == source_to_json(cal.source)
    assert back.checksum == cal.checksum
    dev = fitted["device"]
    raw = dev.record(fitted["survey"], DEVICE, repeats=2, seed=41)  # frames (2, nf, ny, nx)
    mem = cal.apply(raw)
    for h in (back.apply(raw), cb.apply(raw, path)):       # the object, and by file name
        assert h.data.dtype == mem.data.dtype and h.data.tobytes() == mem.data.tobytes()
    assert mem.shape == (2, *SHAPE)


def test_raw_to_calibrated_to_file_to_image_equals_in_memory(fitted, tmp_path):
    cal, raw = fitted["cal"], fitted["raw"]
    z = [0.38, 0.40, 0.42]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)  # 2.5 cm > lambda/2: as built
        in_memory = hr.migrate(cal.apply(raw), z)
        cal_path = cal.save(tmp_path / "cal.nc")
        holo_path = hr.save(cb.apply(raw, cal_path), tmp_path / "survey.nc",
                            history=[cal.history_step()])
        from_file = hr.migrate(hr.load(holo_path), z)
    assert from_file.data.tobytes() == in_memory.data.tobytes()
    steps = hr.io.read_history(holo_path)
    assert steps[0]["parameters"]["calibration_sha256"] == cal.checksum


def test_calibration_refuses_another_device_shape_layout_or_band(fitted, tmp_path):
    cal, raw = fitted["cal"], fitted["raw"]
    path = cal.save(tmp_path / "cal.nc")
    other = cb.RawFrames(raw.i, raw.q, X, X, F, "HSR-0043")
    for c in (cal, path):
        with pytest.raises(ValueError, match=r"'HSR-0042'.*'HSR-0043'"):
            cb.apply(other, c)
    small = cb.RawFrames(raw.i[:, :12], raw.q[:, :12], X, X[:12], F, DEVICE)
    with pytest.raises(ValueError, match=r"16 x 16 array.*12 x 16"):
        cal.apply(small)
    with pytest.raises(ValueError, match="element coordinates"):
        cal.apply(cb.RawFrames(raw.i, raw.q, X * 0.96, X, F, DEVICE))
    with pytest.raises(ValueError, match=r"9\.5, 9\.9, 10\.3\] GHz.*10\.4\] GHz"):
        cal.apply(cb.RawFrames(raw.i, raw.q, X, X, [9.5e9, 9.9e9, 10.4e9], DEVICE))
    with pytest.raises(ValueError, match="GHz"):
        cal.apply(cb.RawFrames(raw.i[1], raw.q[1], X, X, 9.9e9, DEVICE))


def test_saving_never_replaces_a_file_unless_asked(fitted, tmp_path):
    cal = fitted["cal"]
    path = tmp_path / "cal.nc"
    path.write_bytes(b"precious")
    with pytest.raises(ValueError, match="exists"):
        cal.save(path)
    assert path.read_bytes() == b"precious"
    cal.save(path, overwrite=True)
    assert cb.Calibration.load(path).checksum == cal.checksum
    assert os.stat(path).st_mode & 0o777 == default_mode()
    with pytest.raises(ValueError, match=r"\.nc"):
        cal.save(tmp_path / "cal.txt")
    with pytest.raises(ValueError, match="does not exist"):
        cal.save(tmp_path / "missing" / "cal.nc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cal.nc"]  # no temporary left


def test_corrupt_or_foreign_files_are_refused(fitted, tmp_path):
    cal = fitted["cal"]
    good = cal.save(tmp_path / "cal.nc").read_bytes()
    cases = {"empty": b"", "truncated": good[: len(good) // 2], "noise": os.urandom(4096)}
    for name, payload in cases.items():
        p = tmp_path / f"{name}.nc"
        p.write_bytes(payload)
        with pytest.raises(ValueError, match="calibration"):
            cb.Calibration.load(p)
    with pytest.raises(ValueError, match="not a file"):
        cb.Calibration.load(tmp_path / "absent.nc")
    holo = hr.save(fitted["survey"], tmp_path / "hologram.nc")
    with pytest.raises(ValueError, match=r"not a holoradar calibration.*Hologram"):
        cb.Calibration.load(holo)
    # A flipped bit in the element gains: read as numbers, but the checksum refuses them.
    needle = np.ascontiguousarray(np.stack([cal.gains.real, cal.gains.imag], -1)).tobytes()[:64]
    at = good.find(needle)
    assert at > 0
    bad = bytearray(good)
    bad[at + 20] ^= 0x10
    p = tmp_path / "flipped.nc"
    p.write_bytes(bytes(bad))
    with pytest.raises(ValueError, match="checksum"):
        cb.Calibration.load(p)
    # Another device's name written into the file.
    import h5py

    p = tmp_path / "renamed.nc"
    p.write_bytes(good)
    with h5py.File(p, "r+") as f:
        f.attrs["device"] = "HSR-0043"
    with pytest.raises(ValueError, match="checksum"):
        cb.Calibration.load(p)
    # Flips anywhere: an error or the very same calibration, never a different one.
    rng = np.random.default_rng(0)
    for k, pos in enumerate(rng.integers(0, len(good), 20)):
        bad = bytearray(good)
        bad[pos] ^= 1 << int(rng.integers(8))
        p = tmp_path / f"fuzz{k}.nc"
        p.write_bytes(bytes(bad))
        try:
            back = cb.Calibration.load(p)
        except ValueError:
            continue
        assert back.checksum == cal.checksum


def test_calibration_checks_its_own_content():
    kw = {"iq_sign": "I+iQ", "response": [1.0], "gains": np.ones((16, 16))}
    with pytest.raises(ValueError, match="device"):
        cb.Calibration("", X, X, 9.9e9, **kw)
    with pytest.raises(ValueError, match="iq_sign"):
        cb.Calibration(DEVICE, X, X, 9.9e9, **{**kw, "iq_sign": "I*Q"})
    with pytest.raises(ValueError, match="gains must have shape"):
        cb.Calibration(DEVICE, X, X, 9.9e9, **{**kw, "gains": np.ones((3, 16))})
    with pytest.raises(ValueError, match="non-zero"):
        cb.Calibration(DEVICE, X, X, 9.9e9, **{**kw, "gains": np.zeros((16, 16))})
    with pytest.raises(ValueError, match="every element is flagged"):
        cb.Calibration(DEVICE, X, X, 9.9e9, **kw, dead=np.ones((16, 16), bool))
    with pytest.raises(ValueError, match="JSON"):
        cb.Calibration(DEVICE, X, X, 9.9e9, **kw, provenance={"when": object()})
    with pytest.raises(ValueError, match="real numbers"):
        cb.RawFrames(np.ones((2, 2), complex), np.ones((2, 2)), X[:2], X[:2], 9.9e9, DEVICE)
    with pytest.raises(ValueError, match="one shape"):
        cb.RawFrames(np.ones((2, 2)), np.ones((3, 2)), X[:2], X[:2], 9.9e9, DEVICE)
