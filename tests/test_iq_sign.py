"""Data recorded as I - iQ (the engineering convention exp(+j omega t)) are told from the
data and said, with the fix; data in holoradar's convention never are."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from click.testing import CliRunner

import holoradar as hr
from holoradar.app.cli import main
from holoradar.imaging.iq import DECISIVE_RATIO, IQSignWarning, check_iq_sign, warn_if_conjugated

pytestmark = pytest.mark.filterwarnings("ignore::holoradar.AliasingWarning")

SAND = hr.Medium.half_space(0.30, hr.permittivity(2.5, tan_delta=0.005))
ONE, BAND = 9.9e9, np.linspace(8e9, 12e9, 11)
ZS = np.arange(0.30, 0.60, 0.005)


def _scene(ground: bool, direct: bool = False) -> hr.Scene:
    # a horn 5 cm behind the array when its direct wave is in the data (it then focuses
    # behind the array too), else beside it in the array's plane (the paper's stand)
    horn = (hr.PointSource((0.0, -0.15, -0.05), pattern_exponent=4, axis=(0.0, 0.15, 0.35))
            if direct else hr.PointSource((0.0, -0.25, 0.0), pattern_exponent=2))
    medium = SAND if ground else hr.Medium.free_space()
    return hr.Scene(medium, horn, [hr.PointTarget((0.02, 0.01, 0.42), 0.05)])


CASES = {
    "free space": dict(ground=False, surface=False, direct=False),
    "half-space, no glare": dict(ground=True, surface=False, direct=False),
    "half-space with glare": dict(ground=True, surface=True, direct=False),
    "glare and the horn's direct wave": dict(ground=True, surface=True, direct=True),
}


def _said(fn, *args, **kw):
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        fn(*args, **kw)
    return [w for w in said if issubclass(w.category, IQSignWarning)]


@pytest.mark.parametrize("frequency", [ONE, BAND], ids=["one frequency", "11 frequencies"])
@pytest.mark.parametrize("case", list(CASES))
def test_correct_data_are_never_flagged_and_their_conjugate_always(case, frequency):
    c = CASES[case]
    scene = _scene(c["ground"], c["direct"])
    h = hr.simulate(scene, hr.Aperture.paper(), frequency, include_surface=c["surface"],
                    include_direct=c["direct"])
    medium = SAND if c["ground"] else None
    for z, kw in ((ZS, {"medium": medium}), (None, {})):  # the imaged ranges, or the default
        assert not _said(warn_if_conjugated, h, z, **kw)
        said = _said(warn_if_conjugated, hr.conjugate(h), z, **kw)
        assert len(said) == 1
        assert "iq_sign=I-iQ" in str(said[0].message)
        assert check_iq_sign(h, z, **kw).sign == "I+iQ"


def test_a_scanned_transceiver_too():
    ap = hr.Aperture.grid(24, 0.0062, monostatic=True)
    for f in (ONE, BAND):
        h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.01, 0.0, 0.2))]), ap, f)
        assert check_iq_sign(h).sign == "I+iQ"
        assert check_iq_sign(hr.conjugate(h)).sign == "I-iQ"


@pytest.mark.parametrize("seed", range(5))
def test_noise_alone_is_undecided(seed):
    # Nothing focuses on either side: the peak-to-mean of speckle over N cells is
    # ln N + 0.58 +- 1.28 on both, and DECISIVE_RATIO = 3 is out of its reach
    # (probability ~ 0.3 / N^2, see DECISIVE_RATIO).
    rng = np.random.default_rng(seed)
    x = hr.Aperture.paper().x
    h = hr.Hologram(rng.normal(size=(16, 16)) + 1j * rng.normal(size=(16, 16)), x, x, ONE)
    r = check_iq_sign(h, ZS, medium=SAND)
    assert r.sign is None and 1 / DECISIVE_RATIO < r.ratio < DECISIVE_RATIO
    # nothing at all, or numbers near the float limit (a damaged file): no verdict, no
    # overflow
    assert check_iq_sign(h.with_data(np.zeros((16, 16)))).sign is None
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert check_iq_sign(h.with_data(h.data * 1e300), ZS, medium=SAND).sign is None


@pytest.mark.parametrize("seed", range(5))
def test_band_of_noise_is_undecided_by_both_stages(seed):
    """Noise across a band: neither the frequencies alone nor the band's coherent image
    focuses (each stage's speckle reaches DECISIVE_RATIO with probability ~0.3/N^2)."""
    rng = np.random.default_rng(100 + seed)
    x = (np.arange(24) - 11.5) * 0.008
    f = np.linspace(8e9, 12e9, 32)
    h = hr.Hologram(rng.normal(size=(32, 24, 24)) + 1j * rng.normal(size=(32, 24, 24)), x, x,
                    f, monostatic=True)
    assert check_iq_sign(h).sign is None


def test_a_faint_point_is_decided_by_the_band_where_each_frequency_is_not():
    """A point 25 dB under the noise per element: one frequency's image holds it at
    about 30 dB of array gain less 25, a few dB, not enough to decide; the band's 64
    frequencies add 18 dB of coherent gain and a range focus: decided, both ways, as
    iq_convention decides."""
    f = np.linspace(8e9, 12e9, 64)
    ap = hr.Aperture.grid(24, 0.008, monostatic=True)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.01, 0.0, 0.15))]), ap, f)
    rng = np.random.default_rng(0)
    sigma = np.sqrt(np.mean(np.abs(h.data) ** 2)) * 10 ** (25 / 20) / np.sqrt(2)
    h = h.with_data(h.data + sigma * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)))
    assert check_iq_sign(h.at_frequency(32)).sign is None
    r = check_iq_sign(h)
    assert r.sign == "I+iQ" and r.ratio >= DECISIVE_RATIO
    assert check_iq_sign(hr.conjugate(h)).sign == "I-iQ"
    assert hr.iq_convention(h, r.z) == "I+iQ"


def _device_file(path, h):
    # a device that writes I and Q with Q negated: I - jQ of the field
    np.savez(path, I=h.data.real, Q=-h.data.imag, x=h.x * 1000, y=h.y * 1000, f=9.9)


def test_load_says_when_a_devices_file_is_i_minus_iq(tmp_path):
    h = hr.simulate(_scene(True), hr.Aperture.paper(), ONE)
    _device_file(tmp_path / "scan.npz", h)
    layout = "i=I,q=Q,units=mm,frequency_unit=GHz"
    said = _said(hr.load, tmp_path / "scan.npz", layout=layout)
    assert len(said) == 1 and "scan.npz" in str(said[0].message)
    # declared, it is read right and nothing is said
    assert not _said(hr.load, tmp_path / "scan.npz", layout=layout + ",iq_sign=I-iQ")
    fixed = hr.load(tmp_path / "scan.npz", layout=layout + ",iq_sign=I-iQ")
    np.testing.assert_allclose(fixed.data, h.data)
    # the same device writing I + iQ: nothing said
    np.savez(tmp_path / "ok.npz", I=h.data.real, Q=h.data.imag, x=h.x * 1000, y=h.y * 1000,
             f=9.9)
    assert not _said(hr.load, tmp_path / "ok.npz", layout=layout)


def test_image_command_warns_once_with_the_fix(tmp_path):
    h = hr.simulate(_scene(True), hr.Aperture.paper(), ONE)
    _device_file(tmp_path / "scan.npz", h)
    hr.save(hr.conjugate(h), tmp_path / "conj.nc")
    hr.save(h, tmp_path / "ok.nc")
    ground = ["--eps", "2.5+0.0125j", "--z-surface", "0.30", "--z", "0.30:0.60:0.005"]
    layout = "i=I,q=Q,units=mm,frequency_unit=GHz"
    res = CliRunner().invoke(main, ["image", str(tmp_path / "scan.npz"), *ground,
                                    "--layout", layout, "-o", str(tmp_path / "a.nc")])
    assert res.exit_code == 0, res.output
    # one line (the check at the planes imaged), naming the layout that fixes it
    assert res.output.count("(IQSignWarning)") == 1
    assert f"--layout {layout},iq_sign=I-iQ" in res.output
    res = CliRunner().invoke(main, ["image", str(tmp_path / "conj.nc"), *ground,
                                    "-o", str(tmp_path / "b.nc")])
    assert res.exit_code == 0 and res.output.count("(IQSignWarning)") == 1
    assert "hr.conjugate" in res.output
    res = CliRunner().invoke(main, ["image", str(tmp_path / "ok.nc"), *ground,
                                    "-o", str(tmp_path / "c.nc")])
    assert res.exit_code == 0 and "IQSignWarning" not in res.output


def test_a_large_array_with_many_frames_is_judged_on_a_part_of_it(monkeypatch):
    # 300 x 300 elements and 10 frames: the check looks at the central 128 x 128 and 4
    # frames (a few FFTs of 256 x 256), and the centre still focuses the point in front
    ap = hr.Aperture.grid(300, 0.005)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.05, 0.0, 0.3))]), ap, ONE)
    h = h.with_data(np.stack([h.data] * 10))
    from holoradar.imaging import iq

    shapes = []
    real_migrate = iq.migrate

    def spy(holo, *a, **k):
        shapes.append(holo.data.shape)
        return real_migrate(holo, *a, **k)

    monkeypatch.setattr(iq, "migrate", spy)
    assert check_iq_sign(h).sign == "I+iQ"
    assert check_iq_sign(hr.conjugate(h)).sign == "I-iQ"
    # what was imaged: at most 4 frames of at most 128 x 128 elements
    assert shapes and all(s[-2:] == (128, 128) and (len(s) == 2 or s[0] <= 4)
                          for s in shapes)


def test_bad_arguments_are_refused_by_name():
    ap = hr.Aperture.grid(16, 0.0125)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))]), ap, 9.9e9)
    with pytest.raises(ValueError, match=r"^z must"):
        hr.check_iq_sign(h, z="abc")
    with pytest.raises(ValueError, match=r"^z must"):
        hr.check_iq_sign(h, z=-0.3)
    with pytest.raises(TypeError, match="medum"):
        hr.check_iq_sign(h, medum=hr.Medium.half_space(0.3, 2.5))


def test_a_survey_checks_its_first_frame_only(tmp_path, monkeypatch):
    # One device, one convention: the sign is checked on the frame probed for the
    # survey's geometry, not again for every frame (it costs about a small frame's image).
    from holoradar.imaging import iq
    from holoradar.survey.worker import read_frame

    h = hr.simulate(_scene(True), hr.Aperture.paper(), ONE)
    _device_file(tmp_path / "scan.npz", h)
    layout = "i=I,q=Q,units=mm,frequency_unit=GHz"
    calls = []
    real = iq.check_iq_sign
    monkeypatch.setattr(iq, "check_iq_sign", lambda *a, **k: calls.append(1) or real(*a, **k))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IQSignWarning)
        probe, _ = read_frame(str(tmp_path / "scan.npz"), None, layout)
        assert len(calls) == 1
        geometry = hr.survey.FrameGeometry.of(probe)
        for _ in range(3):
            read_frame(str(tmp_path / "scan.npz"), geometry, layout)
    assert len(calls) == 1


def test_an_undecided_check_says_why_and_iq_convention_warns_of_nothing_it_was_not_asked():
    # Noise alone focuses nowhere: no verdict, and the reason names the ranges, the
    # ratio and the way on. iq_convention across a band without a source combines the
    # frequencies for both images alike: no IlluminationWarning about it.
    rng = np.random.default_rng(3)
    x = (np.arange(24) - 11.5) * 0.0125
    f = [9e9, 10e9, 11e9]
    h = hr.Hologram(rng.normal(size=(3, 24, 24)) + 1j * rng.normal(size=(3, 24, 24)), x, x, f)
    r = hr.check_iq_sign(h, [0.2, 0.3])
    assert r.sign is None and "focus alike" in r.reason and "imaged together" in r.reason
    with warnings.catch_warnings():
        warnings.simplefilter("error", hr.IlluminationWarning)
        hr.iq_convention(h, [0.2, 0.3])


def test_image_command_takes_planes_from_the_aperture_itself(tmp_path):
    """Planes from z = 0 (a scanned transceiver imaged from its own plane): the I/Q check
    looks at the planes in front of the array only; the image is made."""
    from cli_helpers import run

    ap = hr.Aperture.grid(24, 0.0062, monostatic=True)
    h = hr.simulate(hr.Scene(targets=[hr.PointTarget((0.01, 0.0, 0.1))]), ap, BAND)
    src = hr.save(h, tmp_path / "h.nc")
    run("image", src, "--z", "0:0.15:0.01", "--upsample", "1", "--no-png", "-o",
        tmp_path / "i.nc")
    assert hr.load(tmp_path / "i.nc").z[0] == 0.0
