"""The TOML scene parser: valid scenes build, and anything else is a ValueError naming the key
(property-based: random documents over the real keys with values of every type)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import holoradar as hr
from conftest import FUZZED
from holoradar.model.scene_file import load_scene, scene_from_mapping

VALID = {
    "frequency": 9.9e9,
    "aperture": {"n": 8, "pitch": 0.02},
    "ground": {"surface": 0.3, "eps": "2.5+0.0125j"},
    "source": {"type": "point", "position": [0.0, -0.2, 0.0], "pattern_exponent": 2},
    "target": [{"type": "point", "position": [0.0, 0.0, 0.4]},
               {"type": "shape", "shape": "disk", "z": 0.45, "diameter": 0.05}],
    "simulate": {"snr_db": 30.0, "seed": 1},
}


def test_a_valid_scene_is_the_scene_written_in_python():
    spec = scene_from_mapping(VALID)
    scene = hr.Scene(hr.Medium.half_space(0.3, 2.5 + 0.0125j),
                     hr.PointSource((0.0, -0.2, 0.0), pattern_exponent=2),
                     [hr.PointTarget((0.0, 0.0, 0.4)),
                      hr.PlanarTarget.from_shape("disk", 0.45, diameter=0.05)])
    ap = hr.Aperture.grid(8, 0.02)
    a = hr.simulate(spec.scene, spec.aperture, spec.frequency, **spec.options)
    b = hr.simulate(scene, ap, 9.9e9, snr_db=30.0, seed=1)
    assert np.array_equal(a.data, b.data)


_values = st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6),
                    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
                    st.lists(st.floats(-1, 1), max_size=4), st.just("2.5+0.1j"),
                    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2))
_keys = {
    "": ["frequency", "aperture", "ground", "source", "target", "simulate", "junk"],
    "aperture": ["n", "ny", "pitch", "pitch_y", "monostatic", "center", "tilt_deg", "x"],
    "ground": ["surface", "eps", "tan_delta", "sigma", "layer", "polarization"],
    "source": ["type", "position", "pattern_exponent", "axis", "waist", "alpha_deg"],
    "target": ["type", "position", "amplitude", "shape", "z", "diameter", "width"],
    "simulate": ["include_surface", "snr_db", "seed", "include_direct"],
}


@st.composite
def documents(draw):
    doc = {k: (dict(v) if isinstance(v, dict) else [dict(t) for t in v] if isinstance(v, list)
               else v) for k, v in VALID.items()}
    for _ in range(draw(st.integers(1, 4))):
        table = draw(st.sampled_from(list(_keys)))
        key = draw(st.sampled_from(_keys[table]))
        value = draw(_values)
        if table == "":
            if draw(st.booleans()):
                doc.pop(key, None)
            else:
                doc[key] = value
        elif table == "target":
            targets = doc.get("target")
            if isinstance(targets, list) and targets and isinstance(targets[0], dict):
                targets[0][key] = value
        elif isinstance(doc.get(table), dict):
            if draw(st.booleans()):
                doc[table].pop(key, None)
            else:
                doc[table][key] = value
    return doc


@settings(max_examples=300, deadline=None)
@given(doc=documents())
def test_fuzzed_scenes_build_or_name_the_key(doc):
    FUZZED["scene parser: mutated scene documents"] += 1
    try:
        spec = scene_from_mapping(doc)
    except ValueError as exc:
        assert str(exc).startswith("scene")  # the message names where: scene.<table>.<key>
    else:
        assert spec.aperture.x.size >= 2 and math.isfinite(float(np.min(spec.frequency)))


@settings(max_examples=200, deadline=None)
@given(text=st.text(max_size=200))
def test_fuzzed_toml_text_gives_one_clear_error(tmp_path_factory, text):
    FUZZED["scene parser: arbitrary TOML text"] += 1
    p = tmp_path_factory.mktemp("toml") / "s.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError):
        load_scene(p)


@settings(max_examples=60, deadline=None)
@given(doc=documents())
def test_fuzzed_scenes_that_build_also_simulate(doc):
    """A scene the parser accepts simulates, or says clearly why not (a ValueError)."""
    FUZZED["scene parser: accepted scenes simulated"] += 1
    try:
        spec = scene_from_mapping(doc)
    except ValueError:
        return
    if spec.aperture.x.size * spec.aperture.y.size > 64 * 64:
        return  # a valid but large array (up to 4096 x 4096): not simulated in a unit test
    try:
        h = hr.simulate(spec.scene, spec.aperture, spec.frequency, **spec.options)
    except ValueError as exc:
        assert str(exc)
    else:
        assert np.all(np.isfinite(h.data))
