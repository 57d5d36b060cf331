"""A robot near-field scanner's export, read as it comes (tests/data/nf_ku_band).

Measured planes in front of a Ku-band horn lens (12.4-18 GHz, 21 x 21 points at 10 mm,
Z = 0, 105.3 and 200 mm), exported by the scanner's software: a metadata block, the
header repeated in a second block with section titles, rows labelled ``Point N``.
Nobody here made them. The check is physics: the field of the farthest plane carried
back towards the horn (``hr.propagate``) is the field measured on each nearer plane.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import holoradar as hr

DATA = Path(__file__).parent / "data" / "nf_ku_band"
LAYOUT = "wide,units=mm,iq_sign=I-iQ"
PLANES = {0.0: "Ku-band Plane 00.txt", 0.1053: "Ku-band Plane 10.txt",
          0.2: "Ku-band Plane 19.txt"}


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    """The median over frequencies of |<a, b>| / (|a| |b|)."""
    c = [abs(np.vdot(a[i], b[i])) / (np.linalg.norm(a[i]) * np.linalg.norm(b[i]))
         for i in range(a.shape[0])]
    return float(np.median(c))


def test_the_export_reads_as_it_comes():
    h = hr.load(DATA / PLANES[0.0], layout=LAYOUT)
    assert h.data.shape == (31, 21, 21)
    np.testing.assert_allclose(h.frequencies[[0, -1]], [12.4e9, 18.0e9])
    np.testing.assert_allclose(h.pitch, (0.01, 0.01))
    np.testing.assert_allclose(h.x[[0, -1]], [-0.1, 0.1])


def test_the_far_plane_carried_back_is_the_near_planes_field():
    # The asked bound, 0.98 (median over the band): what the free-space angular
    # spectrum leaves is the probe's positioning (a millimetre is 0.2 rad at 18 GHz),
    # the scan's 20 x 20 cm window (the horn's field beyond it is missing, and the
    # padded FFT does not know it) and the VNA's noise; measured 0.98-1.0 here.
    far = hr.load(DATA / PLANES[0.2], layout=LAYOUT)
    for z in (0.0, 0.1053):
        near = hr.load(DATA / PLANES[z], layout=LAYOUT)
        assert _correlation(hr.propagate(far, -(0.2 - z)).data, near.data) >= 0.98


def test_read_as_i_plus_iq_the_field_goes_the_other_way():
    # The conjugate is the field travelling towards the horn: carried back it does not
    # match (the check the sign depends on).
    far = hr.load(DATA / PLANES[0.2], layout="wide,units=mm,iq_sign=I+iQ", check=False)
    near = hr.load(DATA / PLANES[0.0], layout="wide,units=mm,iq_sign=I+iQ", check=False)
    assert _correlation(hr.propagate(far, -0.2).data, near.data) < 0.9


def test_a_cut_export_is_refused_with_the_line(tmp_path):
    text = (DATA / PLANES[0.0]).read_text().splitlines()
    cut = tmp_path / "cut.txt"
    last = text[-1]
    cut.write_text("\n".join([*text[:-1], last[: len(last) // 2]]) + "\n")
    with pytest.raises(ValueError, match=r"cut\.txt line \d+: \d+ values for the header's 66"):
        hr.load(cut, layout=LAYOUT)


def test_info_reads_a_wide_export(tmp_path):
    from cli_helpers import run

    res = run("info", DATA / PLANES[0.0], "--layout", LAYOUT)
    assert "(31, 21, 21)" in res.output
