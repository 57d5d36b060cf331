"""Scanner exports as they come: a wide text table (metadata lines, a header naming X, Y
and each frequency twice, one row per point), coordinates written to four decimals in
mm, an I - jQ device; read by hr.load with a layout, on the command line too."""

from __future__ import annotations

import json

import numpy as np
import pytest

import holoradar as hr
from cli_helpers import one_line_error, run

X_MM = (np.arange(16) - 7.5) * 35 / 6          # 5.8333 mm pitch, -43.75 ... 43.75
F_GHZ = (8.2, 9.1, 10.0)


def _field(f_ghz: float) -> np.ndarray:
    """A point 20 cm below the plane, its field under exp(-i omega t): (ny, nx)."""
    k = 2 * np.pi * f_ghz * 1e9 / hr.C0
    xx, yy = np.meshgrid(X_MM * 1e-3, X_MM * 1e-3)
    r = np.sqrt(xx**2 + yy**2 + 0.2**2)
    return np.exp(1j * k * r) / r


def _export(path, *, conj=True, header=None, extra_z=False, meta=33):
    """The scanner's export: ``meta`` metadata lines, the header, a row per point (index,
    X, Y, Z in mm to four decimals, then Re, Im per frequency of the device's I - jQ)."""
    lines = [f"Meta {i}: value {i}" for i in range(meta)]
    lines.append(header or "Frequency, X, Y, Z, " + ", ".join(f"{f}, {f}" for f in F_GHZ))
    fields = [np.conj(_field(f)) if conj else _field(f) for f in F_GHZ]
    n = 0
    for iy, y in enumerate(X_MM):
        for ix, x in enumerate(X_MM):
            z = 110.0 if extra_z and n == 3 else 100.0
            vals = ", ".join(f"{v[iy, ix].real:.9g}, {v[iy, ix].imag:.9g}" for v in fields)
            lines.append(f"{n + 1}, {x:.4f}, {y:.4f}, {z:.1f}, {vals}")
            n += 1
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_a_scanners_export_is_read_by_its_layout(tmp_path):
    p = _export(tmp_path / "plane.txt")
    with pytest.warns(hr.CoordinateWarning, match="snapped"):
        h = hr.load(p, layout="wide,units=mm,iq_sign=I-iQ")
    assert h.data.shape == (3, 16, 16)
    np.testing.assert_allclose(h.frequencies, np.array(F_GHZ) * 1e9)
    # the least-squares pitch of coordinates each off by up to 5e-8 m (four decimals
    # in mm): off by at most 2 x 5e-8 m over the 87.5 mm span, relative 1.2e-6
    assert h.pitch[0] == pytest.approx(35e-3 / 6, rel=1.2e-6)
    # the conjugate undone, each sample as written (nine digits)
    for i, f in enumerate(F_GHZ):
        np.testing.assert_allclose(h.data[i], _field(f), rtol=1e-8)


def test_the_command_line_reads_it_with_layout(tmp_path):
    p = _export(tmp_path / "plane.dat")
    res = run("info", p, "--layout", "wide,units=mm,iq_sign=I-iQ", "--json")
    # the coordinates' snapping is said on stderr; the summary is the JSON line
    info = json.loads(res.output[res.output.index("{\n"):])
    got = info["readable_as"]
    assert got["kind"] == "Hologram" and got["shape"] == [3, 16, 16]
    assert got["frequency_hz"] == [8.2e9, 9.1e9, 10e9]


@pytest.mark.parametrize(("kwargs", "layout", "needle"), [
    ({"header": "Frequency, X, Y, Z, 8.2, 9.1, 10.0, 10.0, 11, 11"}, "wide",
     "each frequency twice"),
    ({"extra_z": True}, "wide,units=mm", "holds 2 planes"),
    # 500-700: GHz or MHz would both be radar frequencies
    ({"header": "Frequency, X, Y, Z, 500, 500, 600, 600, 700, 700"}, "wide,units=mm",
     "frequency_unit=GHz"),
    ({"header": "index, a, b, c, 8.2, 8.2, 9.1, 9.1, 10, 10"}, "wide", "no header row"),
    ({"header": "Frequency, X, Y, 8.2, 8.2, 9.1, 9.1, 10, 10"}, "wide", "line 35"),
])
def test_bad_tables_are_refused_by_what_is_wrong(tmp_path, kwargs, layout, needle):
    p = _export(tmp_path / "bad.txt", **kwargs)
    with pytest.raises(ValueError, match=needle):
        hr.load(p, layout=layout)


def test_a_text_table_without_the_wide_layout_says_how(tmp_path):
    p = _export(tmp_path / "plane.txt")
    with pytest.raises(ValueError, match=r"layout 'wide,\.\.\.'"):
        hr.load(p)
    one_line_error(run("info", p, ok=False), "wide")


def test_a_matlab_struct_is_read_by_its_fields(tmp_path):
    # An inverse-SAR export: data.measurements (x, y, f in MATLAB's order, data(iy, ix, if))
    # with data.x, data.y (m) and data.f (Hz) beside it. The layout names the fields;
    # a field that does not exist is refused with the fields there are.
    from scipy.io import savemat

    x = (np.arange(12) - 5.5) * 0.018
    f = np.linspace(5.7e9, 8.2e9, 5)
    meas = (np.arange(12 * 12 * 5).reshape(12, 12, 5) + 1j).astype(complex)
    p = tmp_path / "tape.mat"
    savemat(p, {"data": {"measurements": meas, "x": x, "y": x, "f": f,
                         "note": "copper tape"}})
    h = hr.load(p, layout="data=data.measurements, x=data.x, y=data.y, frequency=data.f, "
                          "axes=yxf, iq_sign=I+iQ", check=False)
    assert h.data.shape == (5, 12, 12)
    np.testing.assert_array_equal(h.data[2], meas[:, :, 2])
    with pytest.raises(ValueError, match=r"data\.measurement\b.*data\.measurements"):
        hr.load(p, layout="data=data.measurement, x=data.x, y=data.y, frequency=data.f",
                check=False)


def test_a_frequency_list_in_the_layout_text():
    from holoradar.io.layout import Layout

    assert Layout.parse("data=E, frequency=[8.2, 9.1 10], frequency_unit=GHz").frequency \
        == (8.2, 9.1, 10.0)
    with pytest.raises(ValueError, match=r"a list of numbers such as \[8\.2"):
        Layout.parse("frequency=[8.2, x]")


def test_an_image_with_nan_samples_is_said_on_reading(tmp_path):
    # An image whose bytes were overwritten with NaN: info and plot (and every reader)
    # say how many samples are not numbers.
    from holoradar.io import NonFiniteWarning

    x = (np.arange(8) - 3.5) * 0.01
    img = hr.migrate(hr.Hologram(np.ones((8, 8)), x, x, 9.9e9), 0.2)
    data = np.array(img.data)
    data[2:4] = np.nan
    p = hr.save(hr.Image(data, img.x, img.y, img.z, img.frequency, img.method,
                         has_z_axis=img.has_z_axis), tmp_path / "i.nc")
    with pytest.warns(NonFiniteWarning, match=f"{2 * img.x.size} of {data.size} samples"):
        hr.load(p)
    res = run("info", p)
    assert "NaN or infinite" in res.output
