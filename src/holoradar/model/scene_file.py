"""Scenes and grounds described in TOML files, validated key by key.

A scene file (all lengths in metres, frequencies in Hz, angles in degrees)::

    frequency = 9.9e9                 # or a list of frequencies

    [aperture]
    n = 16                            # elements along x (ny = ... for a rectangle)
    pitch = 0.025
    # monostatic = true               # a scanned transceiver
    # center = [0.0, -0.15, 0.05]     # a posed (tilted) array: world centre,
    # tilt_deg = 35.0                 # tilt from level and
    # azimuth_deg = 90.0              # the azimuth of the tilt axis
    # polarization = [0.0, 1.0, 0.0]  # the field component recorded (world axes):
    #                                 # the vector model, with a polarised source

    [ground]                          # omit for free space
    surface = 0.30                    # range of the surface from the array plane
    eps = 2.5                         # or "2.5+0.0125j"
    tan_delta = 0.005                 # optional; sigma = 0.01 (S/m) also
    # or layers, top-down, each from its top down to the next:
    # [[ground.layer]]
    # top = 0.30
    # eps = 5.0

    [source]                          # omit for a normal plane wave
    type = "point"                    # "plane", "point", "gaussian" or "dipole"
    position = [0.0, -0.25, 0.0]
    pattern_exponent = 20
    axis = [0.0, 0.5, 1.0]            # plane: alpha_deg, beta_deg; gaussian: waist, center
    # polarization = [0.0, 1.0, 0.0]  # plane, point, gaussian: the field's direction
    # a Hertzian dipole: type = "dipole", position, moment = [0, 1, 0] (complex
    # components as numbers or strings, "0+1j"), amplitude (optional, complex)

    [[target]]
    type = "point"
    position = [0.0, 0.0, 0.42]
    amplitude = 1.0
    # polarizability = 1e-3           # vector model: a number or a 3 x 3 list of lists

    [[target]]
    type = "line"                     # a rebar, pipe or wire (a perfect conductor)
    start = [-0.15, 0.0, 0.35]
    end = [0.15, 0.0, 0.35]
    radius = 0.006
    # eps = "1.0"                     # a dielectric cylinder (1.0: an air-filled void)

    [[target]]
    type = "shape"                    # a planar object (Kirchhoff)
    shape = "letter_r"                # disk, ring, rectangle, letter_r
    z = 0.42
    reflection = 1.0                  # -1 for metal
    width = 0.10                      # the shape's own sizes
    height = 0.15

    [simulate]
    include_surface = true
    include_direct = false
    snr_db = 40.0                     # optional receiver noise
    seed = 1

A conductivity is turned into a permittivity at the (centre) frequency:
``eps = eps' (1 + i tan_delta) + i sigma / (omega eps0)``.
"""

from __future__ import annotations

import inspect
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..data.hologram import C0
from ..data.pose import Pose
from ..physics.dipole import Dipole
from ..physics.medium import Medium, check_ground_permittivity, permittivity
from ..physics.sources import GaussianBeam, PlaneWave, PointSource
from . import shapes
from .scene import Aperture, Scene
from .targets import LineTarget, PlanarTarget, PointTarget

__all__ = ["SceneSpec", "load_scene", "medium_from_mapping", "parse_complex",
           "scene_from_mapping"]

_MISSING = object()


@dataclass(frozen=True)
class SceneSpec:
    """A scene file's content: what :func:`holoradar.simulate` needs."""

    scene: Scene
    aperture: Aperture
    frequency: float | np.ndarray
    options: dict[str, Any] = field(default_factory=dict)


def parse_complex(value: Any, where: str) -> complex:
    """A permittivity: a number or a string such as ``"2.5+0.0125j"`` (parsed, never
    evaluated)."""
    if isinstance(value, bool):
        raise ValueError(f"{where} must be a number or a complex string like "
                         f"'2.5+0.0125j', got {value!r}")
    if isinstance(value, int | float | complex):
        return complex(value)
    if isinstance(value, str):
        try:
            return complex(value.replace(" ", "").replace("i", "j"))
        except ValueError:
            pass
    raise ValueError(f"{where} must be a number or a complex string like '2.5+0.0125j', "
                     f"got {value!r}")


def _number(m: Mapping[str, Any], key: str, where: str, default: Any = _MISSING, *,
            positive: bool = False, minimum: float | None = None,
            integer: bool = False, unit: str = "") -> Any:
    if key not in m:
        if default is _MISSING:
            what = "an integer" if integer else "a number"
            raise ValueError(f"{where}: missing key {key!r} ({what}"
                             f"{' in ' + unit if unit else ''})")
        return default
    v = m[key]
    ok = isinstance(v, int) if integer else isinstance(v, int | float)
    if isinstance(v, bool) or not ok or not math.isfinite(v):
        raise ValueError(f"{where}.{key} must be {'an integer' if integer else 'a number'}"
                         f"{' in ' + unit if unit else ''}, got {v!r}")
    if positive and v <= 0:
        raise ValueError(f"{where}.{key} must be > 0{' ' + unit if unit else ''}, got {v!r}")
    if minimum is not None and v < minimum:
        raise ValueError(f"{where}.{key} must be >= {minimum}, got {v!r}")
    return v


def _vector(m: Mapping[str, Any], key: str, where: str, n: int, default: Any = _MISSING) \
        -> Any:
    if key not in m:
        if default is _MISSING:
            raise ValueError(f"{where}: missing key {key!r} (a list of {n} numbers, metres)")
        return default
    v = m[key]
    if (not isinstance(v, list) or len(v) != n
            or not all(isinstance(e, int | float) and not isinstance(e, bool)
                       and math.isfinite(e) for e in v)):
        raise ValueError(f"{where}.{key} must be a list of {n} numbers, got {v!r}")
    return tuple(float(e) for e in v)


def _direction(m: Mapping[str, Any], key: str, where: str) -> tuple[float, float, float] | None:
    """An optional direction (a ``polarization``): three numbers, not all zero, returned
    normalised; None when absent."""
    if key not in m:
        return None
    v = m[key]
    if (not isinstance(v, list) or len(v) != 3
            or not all(isinstance(e, int | float) and not isinstance(e, bool)
                       and math.isfinite(e) for e in v)):
        raise ValueError(f"{where}.{key} must be a direction of 3 numbers [x, y, z] in the "
                         f"scene's axes, e.g. [0, 1, 0] for a field along y, got {v!r}")
    norm = math.hypot(*(float(e) for e in v))
    if not norm > 0:
        raise ValueError(f"{where}.{key} must not be zero: give the field's direction, e.g. "
                         f"[0, 1, 0] for a field along y")
    return tuple(float(e) / norm for e in v)  # (hypot: no underflow for tiny components)


def _complex_list(v: Any, where: str, n: int) -> list[complex]:
    if not isinstance(v, list) or len(v) != n:
        raise ValueError(f"{where} must be a list of {n} numbers (complex ones as strings like "
                         f"'0+1j'), got {v!r}")
    out = [parse_complex(e, where) for e in v]
    if not all(math.isfinite(e.real) and math.isfinite(e.imag) for e in out):
        raise ValueError(f"{where} must hold finite numbers, got {v!r}")
    return out


def _moment(m: Mapping[str, Any], where: str) -> list[complex]:
    if "moment" not in m:
        raise ValueError(f"{where}: missing key 'moment' (the dipole moment [px, py, pz], "
                         "e.g. [0, 1, 0] for a dipole along y)")
    p = _complex_list(m["moment"], f"{where}.moment", 3)
    if not any(p):
        raise ValueError(f"{where}.moment must not be zero: a dipole without a moment radiates "
                         "nothing (give its direction, e.g. [0, 1, 0])")
    return p


def _polarizability(m: Mapping[str, Any], where: str) -> Any:
    """A point target's polarizability: a (complex) number, or a 3 x 3 list of lists."""
    if "polarizability" not in m:
        return None
    v, w = m["polarizability"], f"{where}.polarizability"
    if not isinstance(v, list):
        a = parse_complex(v, w)
        if not (math.isfinite(a.real) and math.isfinite(a.imag)):
            raise ValueError(f"{w} must be finite, got {v!r}")
        return a
    if len(v) != 3 or not all(isinstance(row, list) and len(row) == 3 for row in v):
        raise ValueError(f"{w} must be a number or a 3 x 3 tensor (a list of 3 rows of 3 "
                         f"numbers, metres), got {v!r}")
    return [_complex_list(row, w, 3) for row in v]


def _bool(m: Mapping[str, Any], key: str, where: str, default: bool) -> bool:
    v = m.get(key, default)
    if not isinstance(v, bool):
        raise ValueError(f"{where}.{key} must be true or false, got {v!r}")
    return v


def _table(doc: Mapping[str, Any], key: str, where: str) -> Mapping[str, Any]:
    v = doc.get(key, {})
    if not isinstance(v, Mapping):
        raise ValueError(f"{where}: [{key}] must be a table, got {type(v).__name__}")
    return v


def _unknown(m: Mapping[str, Any], allowed: set[str], where: str) -> None:
    extra = sorted(set(m) - allowed)
    if extra:
        raise ValueError(f"{where}: unknown key(s) {extra}; allowed: {sorted(allowed)}")


def _eps(m: Mapping[str, Any], where: str, frequency: float) -> complex:
    eps = parse_complex(m["eps"], f"{where}.eps") if "eps" in m else None
    if eps is None:
        raise ValueError(f"{where}: missing key 'eps' (relative permittivity, e.g. 2.5 or "
                         "'2.5+0.0125j')")
    # Judged as given, before the loss is added: -2.5 with tan_delta 0.005 is a sign
    # slip, not "a medium with gain" (-2.5-0.0125j), and is named as one.
    check_ground_permittivity(eps, f"{where}.eps")
    tan_delta = _number(m, "tan_delta", where, 0.0, minimum=0.0)
    sigma = _number(m, "sigma", where, None, minimum=0.0, unit="S/m")
    if (tan_delta or sigma) and eps.imag:
        raise ValueError(f"{where}: give the loss either as Im(eps) or as tan_delta/sigma, "
                         "not both")
    if tan_delta or sigma:
        return permittivity(eps.real, tan_delta, sigma=sigma, frequency=frequency)
    return eps


def medium_from_mapping(m: Mapping[str, Any], frequency: float, where: str = "[ground]",
                        polarization: str = "TE") -> Medium:
    """A :class:`~holoradar.Medium` from ``{surface, eps[, tan_delta, sigma]}`` or
    ``{layer: [{top, eps, ...}, ...]}`` (ranges in metres, top-down).

    Examples
    --------
    >>> medium_from_mapping({"surface": 0.3, "eps": 2.5, "tan_delta": 0.005}, 9.9e9).eps[1]
    (2.5+0.0125j)
    """
    if not isinstance(m, Mapping):
        raise ValueError(f"{where} must be a table, got {type(m).__name__}")
    if "layer" in m:
        _unknown(m, {"layer", "polarization"}, where)
        layers = m["layer"]
        if not isinstance(layers, list) or not layers or \
                not all(isinstance(la, Mapping) for la in layers):
            raise ValueError(f"{where}.layer must be a list of tables [[ground.layer]] with "
                             "top and eps")
        tops, eps = [], []
        for i, la in enumerate(layers):
            w = f"{where}.layer[{i}]"
            _unknown(la, {"top", "eps", "tan_delta", "sigma"}, w)
            tops.append(float(_number(la, "top", w, positive=True, unit="m")))
            eps.append(_eps(la, w, frequency))
        return Medium.layered(tops, eps, polarization=m.get("polarization", polarization))
    _unknown(m, {"surface", "eps", "tan_delta", "sigma", "polarization"}, where)
    # 0: the antennas on the ground (ground-coupled).
    surface = float(_number(m, "surface", where, minimum=0.0, unit="m"))
    return Medium.half_space(surface, _eps(m, where, frequency),
                             polarization=m.get("polarization", polarization))


def _source(m: Mapping[str, Any], where: str) -> Any:
    if not m:
        return PlaneWave()
    kind = m.get("type", "plane")
    if kind == "plane":
        _unknown(m, {"type", "alpha_deg", "beta_deg", "polarization"}, where)
        return PlaneWave(math.radians(_number(m, "alpha_deg", where, 0.0)),
                         math.radians(_number(m, "beta_deg", where, 0.0)),
                         polarization=_direction(m, "polarization", where))
    if kind == "point":
        _unknown(m, {"type", "position", "pattern_exponent", "axis", "amplitude", "dipole",
                     "polarization"}, where)
        pol = _direction(m, "polarization", where)
        if pol is not None and m.get("dipole") is True:
            raise ValueError(f"{where}: give either dipole = true (the scalar stand-in for a "
                             "dipole) or polarization (the vector horn), not both; or use "
                             "type = \"dipole\"")
        return PointSource(_vector(m, "position", where, 3),
                           pattern_exponent=float(_number(m, "pattern_exponent", where, 0.0,
                                                          minimum=0.0)),
                           axis=_vector(m, "axis", where, 3, (0.0, 0.0, 1.0)),
                           amplitude=parse_complex(m.get("amplitude", 1.0), f"{where}.amplitude"),
                           dipole=_bool(m, "dipole", where, False), polarization=pol)
    if kind == "gaussian":
        _unknown(m, {"type", "waist", "center", "alpha_deg", "beta_deg", "amplitude",
                     "polarization"}, where)
        return GaussianBeam(float(_number(m, "waist", where, positive=True, unit="m")),
                            center=_vector(m, "center", where, 3, (0.0, 0.0, 0.0)),
                            alpha=math.radians(_number(m, "alpha_deg", where, 0.0)),
                            beta=math.radians(_number(m, "beta_deg", where, 0.0)),
                            amplitude=parse_complex(m.get("amplitude", 1.0),
                                                    f"{where}.amplitude"),
                            polarization=_direction(m, "polarization", where))
    if kind == "dipole":
        _unknown(m, {"type", "position", "moment", "amplitude"}, where)
        return Dipole(_vector(m, "position", where, 3), moment=_moment(m, where),
                      amplitude=parse_complex(m.get("amplitude", 1.0), f"{where}.amplitude"))
    raise ValueError(f"{where}.type must be 'plane', 'point', 'gaussian' or 'dipole', got "
                     f"{kind!r}")


def _targets(items: Any, where: str) -> list[PointTarget | LineTarget | PlanarTarget]:
    if not isinstance(items, list) or not all(isinstance(t, Mapping) for t in items):
        raise ValueError(f"{where} must be a list of tables [[target]]")
    out: list[PointTarget | LineTarget | PlanarTarget] = []
    for i, t in enumerate(items):
        w = f"{where}[{i}]"
        kind = t.get("type", "point")
        if kind == "point":
            _unknown(t, {"type", "position", "amplitude", "polarizability"}, w)
            out.append(_within(w, PointTarget, _vector(t, "position", w, 3),
                               parse_complex(t.get("amplitude", 1.0), f"{w}.amplitude"),
                               _polarizability(t, w)))
        elif kind == "line":
            _unknown(t, {"type", "start", "end", "radius", "eps"}, w)
            eps = parse_complex(t["eps"], f"{w}.eps") if "eps" in t else None
            out.append(_within(w, LineTarget, _vector(t, "start", w, 3),
                               _vector(t, "end", w, 3),
                               float(_number(t, "radius", w, positive=True, unit="m")), eps))
        elif kind == "shape":
            name = t.get("shape")
            if name not in shapes.__all__:
                raise ValueError(f"{w}.shape must be one of {shapes.__all__}, got {name!r}")
            sizes = {k: float(_number(t, k, w, positive=True, unit="m")) for k in t
                     if k not in ("type", "shape", "z", "center", "reflection", "pixel")}
            takes = [p for p in inspect.signature(getattr(shapes, name)).parameters
                     if p not in ("X", "Y")]
            wrong = sorted(set(sizes) - set(takes))
            if wrong:
                raise ValueError(f"{w}: a {name} takes the sizes {takes} (metres), not "
                                 f"{wrong}")
            out.append(PlanarTarget.from_shape(
                name, float(_number(t, "z", w, positive=True, unit="m")),
                center=_vector(t, "center", w, 2, (0.0, 0.0)),
                reflection=parse_complex(t.get("reflection", 1.0), f"{w}.reflection"),
                pixel=float(_number(t, "pixel", w, 0.002, positive=True, unit="m")), **sizes))
        else:
            raise ValueError(f"{w}.type must be 'point', 'line' or 'shape', got {kind!r}")
    return out


def _aperture(m: Mapping[str, Any], where: str) -> Aperture:
    _unknown(m, {"n", "ny", "pitch", "pitch_y", "monostatic", "center", "tilt_deg",
                 "azimuth_deg", "polarization"}, where)
    n = int(_number(m, "n", where, integer=True))
    ny = int(_number(m, "ny", where, n, integer=True))
    for key, v in (("n", n), ("ny", ny)):
        if not 2 <= v <= 4096:
            raise ValueError(f"{where}.{key} must be an integer from 2 to 4096, got {v}")
    pitch = float(_number(m, "pitch", where, positive=True, unit="m"))
    pitch_y = float(_number(m, "pitch_y", where, pitch, positive=True, unit="m"))
    pose = None
    if any(k in m for k in ("center", "tilt_deg", "azimuth_deg")):
        pose = Pose(_vector(m, "center", where, 3, (0.0, 0.0, 0.0)),
                    tilt=math.radians(_number(m, "tilt_deg", where, 0.0)),
                    azimuth=math.radians(_number(m, "azimuth_deg", where, 0.0)))
    pol = _direction(m, "polarization", where)
    if pol is not None:
        normal = (pose or Pose()).normal
        if abs(float(np.dot(pol, normal))) > 1 - 1e-9:
            raise ValueError(f"{where}.polarization {m['polarization']!r} lies along the "
                             f"array's line of sight (its normal "
                             f"{np.round(normal, 6).tolist()}): the elements would record "
                             "nothing; give a component across the array, e.g. [0, 1, 0]")
    return Aperture.grid(n, pitch, ny=ny, pitch_y=pitch_y,
                         monostatic=_bool(m, "monostatic", where, False), pose=pose,
                         polarization=pol)


def _within(where: str, build: Any, *args: Any) -> Any:
    """Call ``build``; a library error that does not say where it arose gets ``where``."""
    try:
        return build(*args)
    except ValueError as exc:
        if str(exc).startswith(where):
            raise
        raise ValueError(f"{where}: {exc}") from None
    except TypeError as exc:  # e.g. a shape given a size it does not take
        raise ValueError(f"{where}: {exc}") from None


def _plausible_pitch(aperture: Aperture, f_max: float, where: str) -> None:
    """The checks :func:`~holoradar.data.plausibility.check_plausible` makes on a file."""
    from ..data.plausibility import MAX_PITCH_WAVELENGTHS, MIN_PITCH_FRACTION

    lam = C0 / f_max
    for key, p in (("pitch", float(aperture.x[1] - aperture.x[0])),
                   ("pitch_y", float(aperture.y[1] - aperture.y[0]))):
        if p / lam > MAX_PITCH_WAVELENGTHS:
            raise ValueError(f"{where}.aperture.{key} {p:g} m is {p / lam:.1f} wavelengths: "
                             "millimetres or centimetres given for metres?")
        if p / lam < 1 / MIN_PITCH_FRACTION:
            raise ValueError(f"{where}.aperture.{key} {p:g} m is lambda/{lam / p:.0f}: a "
                             "pitch in metres is expected")


def _plausible_ranges(aperture: Aperture, medium: Medium, targets: list[Any], f_max: float,
                      where: str) -> None:
    """The ranges the command line checks: no target or interface where an array of
    this width focuses nothing (a range in centimetres or millimetres read as metres)."""
    from ..data.plausibility import range_problem

    width = max(aperture.x.size * abs(float(aperture.x[1] - aperture.x[0])),
                aperture.y.size * abs(float(aperture.y[1] - aperture.y[0])))
    height = float(aperture.pose.center[2])  # ranges are from the array, not the world's 0
    ranges: list[tuple[str, float]] = []
    if not medium.is_free_space:
        key = "ground.surface" if medium.n_regions == 2 else \
            f"ground.layer[{medium.n_regions - 2}].top"
        ranges.append((key, float(medium.z_interfaces[-1])))
    for i, t in enumerate(targets):
        if isinstance(t, PointTarget):
            ranges.append((f"target[{i}].position", float(t.position[2])))
        elif isinstance(t, LineTarget):
            ranges.append((f"target[{i}].start/end", float(max(t.start[2], t.end[2]))))
        elif isinstance(t, PlanarTarget):
            ranges.append((f"target[{i}].z", float(t.z)))
    for key, z in ranges:
        problem = range_problem(z - height, width, f_max,
                                None if medium.is_free_space else medium,
                                f"{where}.{key} at range {z:.4g} m")
        if problem is not None:
            raise ValueError(problem)


def scene_from_mapping(doc: Mapping[str, Any], where: str = "scene") -> SceneSpec:
    """A :class:`SceneSpec` from a parsed TOML document (see the module's example)."""
    _unknown(doc, {"frequency", "aperture", "ground", "source", "target", "simulate"}, where)
    if "frequency" not in doc:
        raise ValueError(f"{where}: missing key 'frequency' (Hz, a number or a list)")
    fv = doc["frequency"]
    fl = fv if isinstance(fv, list) else [fv]
    if not fl or not all(isinstance(f, int | float) and not isinstance(f, bool)
                         and math.isfinite(f) and f > 0 for f in fl):
        raise ValueError(f"{where}.frequency must be a number > 0 (Hz) or a list of them, got "
                         f"{fv!r}")
    if len(fl) > 1 and np.any(np.diff(fl) <= 0):
        raise ValueError(f"{where}.frequency: a list must be strictly increasing, got {fv!r}")
    if min(fl) < 1e8:
        raise ValueError(f"{where}.frequency {min(fl)!r} Hz is below 100 MHz: given in GHz? "
                         "(the scene's frequency is in Hz, e.g. 9.9e9)")
    freq: float | np.ndarray = float(fl[0]) if not isinstance(fv, list) else np.array(fl, float)
    fc = float(np.mean(fl))
    if "aperture" not in doc:
        raise ValueError(f"{where}: missing table [aperture] (n, pitch)")
    aperture = _within(f"{where}.aperture", _aperture, _table(doc, "aperture", where),
                       f"{where}.aperture")
    ground = _table(doc, "ground", where)
    medium = _within(f"{where}.ground", medium_from_mapping, ground, fc, f"{where}.ground") \
        if ground else Medium.free_space()
    source = _within(f"{where}.source", _source, _table(doc, "source", where),
                     f"{where}.source")
    targets = _within(f"{where}.target", _targets, doc.get("target", []), f"{where}.target")
    sim = _table(doc, "simulate", where)
    _unknown(sim, {"include_surface", "include_direct", "include_targets", "snr_db", "seed"},
             f"{where}.simulate")
    options: dict[str, Any] = {
        "include_surface": _bool(sim, "include_surface", f"{where}.simulate", True),
        "include_direct": _bool(sim, "include_direct", f"{where}.simulate", False),
        "include_targets": _bool(sim, "include_targets", f"{where}.simulate", True),
        "snr_db": _number(sim, "snr_db", f"{where}.simulate", None, unit="dB"),
        "seed": _number(sim, "seed", f"{where}.simulate", None, integer=True, minimum=0),
    }
    _plausible_pitch(aperture, float(np.max(fl)), where)
    _plausible_ranges(aperture, medium, targets, float(np.max(fl)), where)
    if isinstance(source, GaussianBeam) and source.waist < C0 / float(np.max(fl)) / 4:
        raise ValueError(f"{where}.source.waist {source.waist:g} m is below a quarter "
                         "wavelength: such a beam is mostly evanescent (metres expected)")
    scene = Scene(medium, source, targets)  # (a monostatic aperture does not use it)
    return SceneSpec(scene, aperture, freq, options)


def load_scene(path: str | Path) -> SceneSpec:
    """Read and validate a TOML scene file.

    Raises
    ------
    ValueError
        Not TOML, or a key missing, unknown, of the wrong type or out of range:
        the message names the key (``scene.aperture.pitch must be > 0 m``).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "s.toml"
    >>> _ = p.write_text('frequency = 9.9e9\\n[aperture]\\nn = 16\\npitch = 0.025\\n')
    >>> load_scene(p).aperture.x.size
    16
    """
    src = Path(path)
    if not src.is_file():
        raise ValueError(f"scene file {str(src)!r} is not a file")
    if src.stat().st_size > 16 * 2**20:
        raise ValueError(f"scene file {src.name} is larger than 16 MiB")
    try:
        doc = tomllib.loads(src.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{src.name} is not valid TOML ({exc})") from None
    try:
        return scene_from_mapping(doc, where=src.stem)
    except (TypeError, OverflowError) as exc:  # a value of a type no check foresaw
        raise ValueError(f"{src.name}: {exc}") from None
