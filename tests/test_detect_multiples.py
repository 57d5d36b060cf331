"""Surface multiples: a weaker copy of an object at twice its depth, under it, is said
as a multiple and not listed as an object.

The scene is simulated by holoradar's own line model, with the multiple stood in for by
a thinner parallel bar at twice the depth (the model has no surface multiples): this
checks the recognition and how it is said, not the physics of the bounce (the
full-wave mat of tests/test_fdtd_suite.py does that).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr

warnings.filterwarnings("ignore", category=hr.AliasingWarning)

Y = (0, 1, 0)
Z0 = 0.10
CONCRETE = hr.Medium.half_space(Z0, 5.0)


@pytest.fixture(scope="module")
def bar_and_echo(tmp_path_factory):
    bar = hr.LineTarget((0.0, -0.2, Z0 + 0.03), (0.0, 0.2, Z0 + 0.03), radius=0.006)
    echo = hr.LineTarget((0.0, -0.2, Z0 + 0.06), (0.0, 0.2, Z0 + 0.06), radius=0.003)
    scene = hr.Scene(CONCRETE, hr.PlaneWave(polarization=Y), [bar, echo])
    h = hr.simulate(scene, hr.Aperture.grid(24, 0.01, polarization=Y),
                    np.linspace(9e9, 11e9, 11), include_surface=False, snr_db=30, seed=2)
    img = hr.migrate(h, np.arange(Z0 + 0.01, Z0 + 0.08, 0.0025), medium=CONCRETE)
    d = tmp_path_factory.mktemp("multiple")
    return h, img, hr.save(h, d / "h.nc"), hr.save(img, d / "img.nc")


def test_the_copy_at_twice_the_depth_is_a_multiple_not_an_object(bar_and_echo):
    h, img, _, _ = bar_and_echo
    df = hr.detect(img, hologram=h, medium=CONCRETE)
    assert list(df.kind) == ["line"], df[["kind", "x", "depth"]]
    (m,) = df.attrs["multiples"]
    # at twice the bar's depth within half a range cell c / (2 B n) (module rule)
    assert m["depth"] == pytest.approx(2 * m["of_depth"], abs=hr.C0 / (4 * 2e9 * 5**0.5))
    assert m["of_x"] == pytest.approx(float(df.x[0]))


def test_the_command_line_says_the_multiple(bar_and_echo):
    from cli_helpers import run

    _, _, holo, image = bar_and_echo
    res = run("detect", image, "--hologram", holo, "--eps", "5", "--z-surface", str(Z0))
    assert "1 object(s) (1 line(s))" in res.output
    assert "1 surface multiple(s), not objects: line at x" in res.output
