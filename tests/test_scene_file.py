"""The TOML scene parser: valid scenes build, and anything else is a ValueError naming the key
(property-based: random documents over the real keys with values of every type)."""

from __future__ import annotations

import math
from pathlib import Path

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


VECTOR = {
    "frequency": 9.9e9,
    "aperture": {"n": 8, "pitch": 0.015, "polarization": [0, 2, 0]},
    "ground": {"surface": 0.3, "eps": "6+0.3j"},
    "source": {"type": "dipole", "position": [-0.2, 0.0, 0.2], "moment": [0, "1+0.5j", 0],
               "amplitude": "2-1j"},
    "target": [{"type": "line", "start": [-0.05, 0.0, 0.35], "end": [0.05, 0.0, 0.35],
                "radius": 0.006},
               {"type": "line", "start": [0.0, -0.05, 0.4], "end": [0.0, 0.05, 0.4],
                "radius": 0.003, "eps": "1.0"},
               {"type": "point", "position": [0.02, 0.01, 0.38], "amplitude": 0.5,
                "polarizability": [[1e-3, 0, 0], [0, "2e-3+1e-4j", 0], [0, 0, 0]]},
               {"type": "point", "position": [-0.02, 0.01, 0.38], "polarizability": "1e-3j"}],
}


def test_a_vector_scene_is_the_scene_written_in_python():
    """The dipole source, the aperture's polarization, line targets and polarizabilities are
    read into the same objects as in Python: the simulated holograms agree bit for bit."""
    spec = scene_from_mapping(VECTOR)
    src = spec.scene.source
    assert isinstance(src, hr.Dipole) and src.amplitude == 2 - 1j
    np.testing.assert_array_equal(src.moment, [0, 1 + 0.5j, 0])
    np.testing.assert_array_equal(spec.aperture.polarization, [0.0, 1.0, 0.0])
    line, void, point, iso = spec.scene.targets
    assert isinstance(line, hr.LineTarget) and line.eps is None and line.radius == 0.006
    assert isinstance(void, hr.LineTarget) and void.eps == 1.0
    assert point.tensor[1, 1] == 2e-3 + 1e-4j and point.amplitude == 0.5
    np.testing.assert_array_equal(iso.tensor, 1e-3j * np.eye(3))
    scene = hr.Scene(hr.Medium.half_space(0.3, 6 + 0.3j),
                     hr.Dipole((-0.2, 0.0, 0.2), moment=(0, 1 + 0.5j, 0), amplitude=2 - 1j),
                     [hr.LineTarget((-0.05, 0.0, 0.35), (0.05, 0.0, 0.35), 0.006),
                      hr.LineTarget((0.0, -0.05, 0.4), (0.0, 0.05, 0.4), 0.003, eps=1.0),
                      hr.PointTarget((0.02, 0.01, 0.38), 0.5,
                                     polarizability=np.diag([1e-3, 2e-3 + 1e-4j, 0])),
                      hr.PointTarget((-0.02, 0.01, 0.38), polarizability=1e-3j)])
    ap = hr.Aperture.grid(8, 0.015, polarization=(0, 1, 0))
    a = hr.simulate(spec.scene, spec.aperture, spec.frequency, **spec.options)
    b = hr.simulate(scene, ap, 9.9e9)
    assert a.is_vector and np.array_equal(a.polarization, [0.0, 1.0, 0.0])
    assert np.array_equal(a.data, b.data) and np.any(a.data)


@pytest.mark.parametrize(("source", "want"), [
    ({"type": "plane", "alpha_deg": 0.0, "polarization": [0, 3, 0]}, (0.0, 1.0, 0.0)),
    ({"type": "point", "position": [0, -0.2, 0], "polarization": [1, 0, 0]}, (1.0, 0.0, 0.0)),
    ({"type": "gaussian", "waist": 0.05, "polarization": [0, 1, 0]}, (0.0, 1.0, 0.0)),
])
def test_sources_take_a_polarization(source, want):
    doc = {**VALID, "source": source, "aperture": {"n": 8, "pitch": 0.02,
                                                   "polarization": [1, 0, 0]}}
    spec = scene_from_mapping(doc)
    assert spec.scene.source.polarization == want
    np.testing.assert_array_equal(spec.aperture.polarization, [1.0, 0.0, 0.0])
    scalar = scene_from_mapping({**doc, "source": {k: v for k, v in source.items()
                                                   if k != "polarization"}})
    assert scalar.scene.source.polarization is None


def test_the_dipole_rebar_example_is_a_vector_scene():
    spec = load_scene(Path(__file__).resolve().parents[1] / "examples" / "scenes"
                      / "dipole_rebar.toml")
    src, (rebar,) = spec.scene.source, spec.scene.targets
    assert isinstance(src, hr.Dipole) and src.moment.tolist() == [0, 1, 0]
    np.testing.assert_array_equal(src.position, [-0.2, 0.0, 0.2])
    assert spec.scene.medium.eps[1] == 6 + 0.3j and spec.scene.medium.z_interfaces[0] == 0.3
    assert spec.aperture.x.size == spec.aperture.y.size == 24
    np.testing.assert_array_equal(spec.aperture.polarization, [0.0, 1.0, 0.0])
    assert isinstance(rebar, hr.LineTarget) and rebar.radius == 0.006 and rebar.eps is None
    np.testing.assert_array_equal(rebar.direction, [1.0, 0.0, 0.0])
    assert rebar.start[2] - 0.3 == pytest.approx(0.05)


@pytest.mark.parametrize(("table", "change", "message"), [
    ("source", {"moment": [0, 0, 0]}, r"scene\.source\.moment must not be zero"),
    ("source", {"moment": ["0", "0j", 0.0]}, r"scene\.source\.moment must not be zero"),
    ("source", {"moment": [0, 1]}, r"scene\.source\.moment must be a list of 3"),
    ("source", {"moment": [0, "one", 0]}, r"scene\.source\.moment must be a number"),
    ("source", {"moment": None}, r"scene\.source: missing key 'moment'"),
    ("source", {"pattern_exponent": 2}, r"scene\.source: unknown key\(s\) \['pattern_exponent'\]"),
    ("source", {"type": "horn"}, r"scene\.source\.type must be .*'dipole'"),
    ("aperture", {"polarization": [0, 0, 0]}, r"scene\.aperture\.polarization must not be zero"),
    ("aperture", {"polarization": [0, 1]}, r"scene\.aperture\.polarization must be a direction"),
    ("aperture", {"polarization": [0, 0, 1]},
     r"scene\.aperture\.polarization \[0, 0, 1\] lies along"),
    ("aperture", {"polarisation": [0, 1, 0]},
     r"scene\.aperture: unknown key\(s\) \['polarisation'\]"),
    ("target", {"polarizability": [[1, 0], [0, 1]]},
     r"scene\.target\[2\]\.polarizability must be a number or a 3 x 3"),
    ("target", {"polarizability": [[1, 0, 0], [0, 1, 0], [0, 0, "x"]]},
     r"scene\.target\[2\]\.polarizability must be a number"),
    ("target", {"polarizability": True}, r"scene\.target\[2\]\.polarizability must be a number"),
    ("target", {"radius": 0.01}, r"scene\.target\[2\]: unknown key\(s\) \['radius'\]"),
])
def test_bad_vector_keys_name_the_key(table, change, message):
    doc = {k: (dict(v) if isinstance(v, dict) else [dict(t) for t in v] if isinstance(v, list)
               else v) for k, v in VECTOR.items()}
    entry = doc[table][2] if table == "target" else doc[table]
    for key, value in change.items():
        if value is None:
            entry.pop(key)
        else:
            entry[key] = value
    with pytest.raises(ValueError, match=message):
        scene_from_mapping(doc)


@pytest.mark.parametrize(("source", "message"), [
    ({"type": "plane", "polarization": [0, 0, 0]},
     r"scene\.source\.polarization must not be zero"),
    ({"type": "gaussian", "waist": 0.05, "polarization": [0.0, -0.0, 0]},
     r"scene\.source\.polarization must not be zero"),
    ({"type": "point", "position": [0, 0, 0], "polarization": "y"},
     r"scene\.source\.polarization must be a direction"),
    ({"type": "point", "position": [0, 0, 0], "polarization": [0, 1, 0], "dipole": True},
     r"scene\.source: give either dipole = true .* or polarization"),
])
def test_bad_source_polarizations_name_the_key(source, message):
    with pytest.raises(ValueError, match=message):
        scene_from_mapping({**VALID, "source": source})


@pytest.mark.parametrize(("target", "message"), [
    ({"type": "line", "start": [0, 0, 0.4], "end": [0, 0, 0.4], "radius": 0.01},
     r"scene\.target\[0\]: start and end must differ"),
    ({"type": "line", "start": [0, 0, 0.4], "end": [0.1, 0, 0.4]},
     r"scene\.target\[0\]: missing key 'radius'"),
    ({"type": "line", "start": [0, 0, 0.4], "end": [0.1, 0, 0.4], "radius": -1},
     r"scene\.target\[0\]\.radius must be > 0"),
    ({"type": "line", "start": [0, 0, 0.4], "end": [0.1, 0, 0.4], "radius": 0.01, "eps": "x"},
     r"scene\.target\[0\]\.eps must be a number"),
    ({"type": "wire"}, r"scene\.target\[0\]\.type must be 'point', 'line' or 'shape'"),
])
def test_bad_line_targets_name_the_key(target, message):
    with pytest.raises(ValueError, match=message):
        scene_from_mapping({**VALID, "target": [target]})


_values = st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6),
                    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
                    st.lists(st.floats(-1, 1), max_size=4), st.just("2.5+0.1j"),
                    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2))
_keys = {
    "": ["frequency", "aperture", "ground", "source", "target", "simulate", "junk"],
    "aperture": ["n", "ny", "pitch", "pitch_y", "monostatic", "center", "tilt_deg", "x",
                 "polarization"],
    "ground": ["surface", "eps", "tan_delta", "sigma", "layer", "polarization"],
    "source": ["type", "position", "pattern_exponent", "axis", "waist", "alpha_deg",
               "polarization", "moment"],
    "target": ["type", "position", "amplitude", "shape", "z", "diameter", "width",
               "polarizability", "start", "end", "radius"],
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
