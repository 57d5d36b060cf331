"""A device's response per frequency and its frequency list, given as small text tables
(the layout's ``response``; the command line's --response and --frequency-file)."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from cli_helpers import one_line_error, run

F = np.array([5.7e9, 6.95e9, 8.2e9])
X = (np.arange(12) - 5.5) * 0.018


def _device(tmp_path):
    """A point's field seen through a device response r(f) (a delay and a slope), as an
    .npz without frequencies; the response table (in GHz) and the frequency file."""
    scene = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.17))])
    h = hr.simulate(scene, hr.Aperture.grid(12, 0.018, monostatic=True), F)
    resp = (1 + 0.2 * np.arange(3)) * np.exp(1j * np.array([0.3, 1.9, 3.4]))
    np.savez(tmp_path / "scan.npz", data=h.data * resp[:, None, None], x=X, y=X)
    # GHz: the data's frequencies and one beyond each end (a table covers the band)
    tf = np.r_[5.5, F / 1e9, 8.5]
    tr = np.r_[resp[0], resp, resp[-1]]
    table = tmp_path / "response.csv"
    table.write_text("frequency,re,im\n" + "".join(f"{a},{b.real},{b.imag}\n"
                                                   for a, b in zip(tf, tr, strict=True)))
    freqs = tmp_path / "f.txt"
    freqs.write_text("\n".join(str(v / 1e9) for v in F) + "\n")
    return h, table, freqs


def test_the_response_is_divided_out_on_reading(tmp_path):
    # The table holds the response at the data's own frequencies: nothing is
    # interpolated, the division is exact to rounding.
    h, table, _ = _device(tmp_path)
    lay = f"axes=fyx, frequency=[5.7, 6.95, 8.2], frequency_unit=GHz, monostatic=true, " \
          f"response={table.name}, iq_sign=I+iQ"
    got = hr.load(tmp_path / "scan.npz", layout=lay)
    err = np.max(np.abs(got.data - h.data)) / np.max(np.abs(h.data))
    assert err < 1e-12, err
    # without it the image's focus is the response's blur
    raw = hr.load(tmp_path / "scan.npz", layout=lay.replace(f", response={table.name}", ""))
    assert np.max(np.abs(raw.data - h.data)) / np.max(np.abs(h.data)) > 0.5


def test_the_command_line_takes_both_files(tmp_path):
    h, table, freqs = _device(tmp_path)
    out = tmp_path / "img.nc"
    run("image", tmp_path / "scan.npz", "--z", "0.17", "--layout",
        "axes=fyx,monostatic=true,iq_sign=I+iQ", "--frequency-file", freqs, "--response",
        table, "--upsample", "4", "-o", out, "--no-png", "-q")
    img = hr.load(out)
    ref = hr.migrate(h, 0.17, upsample=4)
    peak = np.unravel_index(np.argmax(np.abs(img.data)), img.data.shape)
    assert peak == np.unravel_index(np.argmax(np.abs(ref.data)), ref.data.shape)


def test_bad_tables_are_refused_by_name(tmp_path):
    _device(tmp_path)
    short = tmp_path / "short.csv"
    short.write_text("frequency,re,im\n6.0,1,0\n8.0,1,0\n")
    with pytest.raises(ValueError, match=r"short\.csv: .*cover"):
        hr.load(tmp_path / "scan.npz", layout="axes=fyx, frequency=[5.7, 6.95, 8.2], "
                f"frequency_unit=GHz, response={short.name}, iq_sign=I+iQ")
    bad = tmp_path / "bad.csv"
    bad.write_text("f_ghz,gain\n6,1\n")
    with pytest.raises(ValueError, match=r"bad\.csv: a response table needs a frequency"):
        hr.load(tmp_path / "scan.npz", layout=f"axes=fyx, frequency=[5.7, 6.95, 8.2], "
                f"frequency_unit=GHz, response={bad.name}")
    words = tmp_path / "words.txt"
    words.write_text("five\nsix\n")
    one_line_error(run("image", tmp_path / "scan.npz", "--z", "0.17", "--frequency-file",
                       words, "-o", tmp_path / "o.nc", ok=False), "--frequency-file")
    assert not (tmp_path / "o.nc").exists()


def test_a_sidecars_layout_may_name_the_response(tmp_path):
    # scan.npz + scan.json holding {"layout": {..., "response": "response.csv"}}: the
    # device's own description, applied as if given.
    import json

    h, table, _ = _device(tmp_path)
    (tmp_path / "scan.json").write_text(json.dumps({"layout": {
        "axes": "fyx", "frequency": [5.7, 6.95, 8.2], "frequency_unit": "GHz",
        "monostatic": True, "response": table.name, "iq_sign": "I+iQ"}}))
    got = hr.load(tmp_path / "scan.npz")
    assert np.max(np.abs(got.data - h.data)) / np.max(np.abs(h.data)) < 1e-12


def test_frequencies_written_in_hz_are_taken_in_hz():
    # 0.2-0.9 GHz written in Hz fit Hz (and, as numbers, kHz): taken as written.
    import tempfile
    from pathlib import Path

    from holoradar.io.response import read_frequencies

    p = Path(tempfile.mkdtemp()) / "f.txt"
    p.write_text("2e8\n5e8\n9e8\n")
    assert read_frequencies(p).tolist() == [2e8, 5e8, 9e8]


@pytest.mark.parametrize("kind", ["mat", "npz"])
def test_a_response_in_the_devices_own_convention_from_any_file(tmp_path, kind):
    # A device recording I - jQ (the conjugate of holoradar's I + iQ) measures its own
    # response in that convention too. Both given as recorded, with iq_sign=I-iQ, the
    # division gives the scene's field exactly (the response is conjugated with the
    # data). Divided the other way round, the response's phase would count twice.
    import scipy.io

    h, _, _ = _device(tmp_path)
    resp = (1 + 0.2 * np.arange(3)) * np.exp(1j * np.array([0.3, 1.9, 3.4]))
    np.savez(tmp_path / "scan.npz", data=np.conj(h.data * resp[:, None, None]), x=X, y=X)
    recorded = np.conj(resp)            # the response as the device records it
    if kind == "mat":
        path = tmp_path / "ProbeResponse.mat"
        scipy.io.savemat(path, {"freq": F, "S21": recorded})
    else:
        path = tmp_path / "probe.npz"
        np.savez(path, frequency=F, re=recorded.real, im=recorded.imag)
    got = hr.load(tmp_path / "scan.npz", layout="axes=fyx, frequency=[5.7, 6.95, 8.2], "
                  f"frequency_unit=GHz, monostatic=true, response={path.name}, iq_sign=I-iQ")
    assert np.max(np.abs(got.data - h.data)) <= 1e-12 * np.max(np.abs(h.data))


def test_a_response_file_that_is_not_one_is_named(tmp_path):
    import scipy.io

    _device(tmp_path)
    path = tmp_path / "two.mat"
    scipy.io.savemat(path, {"freq": F, "a": F * 1j, "b": F * 2j})
    with pytest.raises(ValueError, match=r"two\.mat: a response needs .*\(2 complex ones"):
        hr.load(tmp_path / "scan.npz", layout="axes=fyx, frequency=[5.7, 6.95, 8.2], "
                f"frequency_unit=GHz, monostatic=true, response={path.name}")
