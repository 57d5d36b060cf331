"""How a user's arrays make a hologram: which variable is the field, which axis is which,
and in what units; and the assembly of a :class:`~holoradar.Hologram` from them.

A :class:`Layout` names the variables (or leaves them to be found under their
usual names), declares the axis order and the units. It can be given in
Python, on the command line (``--layout "data=E[1],units=mm"``) or in a JSON
sidecar next to the file (``scan.npy`` + ``scan.json`` holding
``{"layout": {...}}`` and, if the file lacks them, ``x``, ``y``,
``frequency`` as numbers or lists).

Field forms: one complex variable (``data``); two real ones (``i`` and ``q``,
the sample being ``I + iQ``); amplitude and phase (``amplitude``, ``phase``,
the sample ``A exp(i phase)``); or a real array with an I/Q axis (letter ``c``
in ``axes``). A name may select along leading axes with integers:
``E_scat[1]`` is ``E_scat``'s second entry along its first axis.

Grids: coordinate vectors ``x`` (length nx) and ``y`` (ny), or a ``pitch`` for a
centred grid; or a table with one row per element (CSV), where ``x``, ``y``
(and ``frequency``) are columns as long as the field column and are gathered
into the grid.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from ..data.hologram import Hologram
from .readers import is_number as _is_number

__all__ = ["FREQUENCY_UNITS", "LENGTH_UNITS", "Layout", "assemble"]

LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
FREQUENCY_UNITS = {"Hz": 1.0, "kHz": 1e3, "MHz": 1e6, "GHz": 1e9}
_PHASE_UNITS = {"rad": 1.0, "deg": np.pi / 180}

# Usual names, tried in order when the layout does not name a variable.
_NAMES = {
    "data": ("data", "hologram", "field", "iq", "IQ", "E", "signal"),
    "i": ("I", "i", "in_phase", "real"),
    "q": ("Q", "q", "quadrature", "imag"),
    "amplitude": ("amplitude", "amp", "magnitude", "abs", "A"),
    "phase": ("phase", "angle", "arg", "phi"),
    "x": ("x", "x_m", "X"),
    "y": ("y", "y_m", "Y"),
    "frequency": ("frequency", "frequencies", "freq", "f", "frequency_hz", "f_hz", "freqs_hz",
                  "freq_hz"),
}
_REF = re.compile(r"^\s*(?P<name>[^\[\]]+?)\s*(\[(?P<idx>\s*-?\d+\s*(,\s*-?\d+\s*)*)\])?\s*$")


@dataclass(frozen=True)
class Layout:
    """Where the hologram is in a file and in what units.

    Parameters
    ----------
    data : str, optional
        The complex field variable (e.g. ``"data"``, ``"E_scat[1]"``).
    i, q : str, optional
        Separate real in-phase and quadrature variables.
    amplitude, phase : str, optional
        Amplitude and phase variables (``phase_unit`` rad or deg).
    x, y : str, optional
        Coordinate variables (element centres, ``length_unit``).
    frequency : str, float or list of float, optional
        A variable name, or the value(s) in ``frequency_unit``.
    pitch : float, optional
        Element pitch in ``length_unit`` when the file has no coordinates: a
        grid centred on 0.
    axes : str, optional
        One letter per axis of the field array, in the file's order: ``x``
        (required), ``y`` (a grid's rows; without it a line scan along x, a
        B-scan: ``fx`` or ``xf``), ``f`` (frequency), ``t`` (frames: views,
        repeats, positions), ``c`` (an I/Q pair axis of a real array, I first).
        Default: ``yx`` with leading frames, the frequency third from last when
        its length matches.
    length_unit : {"m", "cm", "mm"}
    frequency_unit : {"Hz", "kHz", "MHz", "GHz"}
    phase_unit : {"rad", "deg"}
    iq_sign : {"I+iQ", "I-iQ"}
        ``"I-iQ"``: the device records the conjugate (conjugated on reading).
    monostatic : bool, optional
        A scanned transceiver (see :class:`~holoradar.Hologram`). Not given: a line
        scan (``axes`` without ``y``) is a transceiver's (a GPR's B-scan), a grid a
        receiver array's.
    tx_offset : list of float, optional
        A transmitter beside the scanned receiver, ``[dx, dy]`` or ``[dx, dy, dz]``
        in ``length_unit`` (``tx_offset=[120, 0, 0]`` with ``units=mm``): the
        hologram's ``tx_offset`` (implies ``monostatic``).
    wide : {"reim", "magphase"}, optional
        A scanner's wide text table (any suffix): after metadata lines, a header
        row naming the coordinates (``X``, ``Y``) and each frequency twice, then one
        row per point with each frequency's real and imaginary parts (or magnitude
        and phase) (:mod:`holoradar.io.wide`). The bare word ``wide`` in the text
        form is ``wide=reim``.
    response : str, optional
        A table of the device's complex response per frequency (a CSV file:
        ``frequency`` and ``re``/``im`` or ``amplitude``/``phase``): each frequency is
        divided by it on reading (:mod:`holoradar.io.response`).

    Examples
    --------
    >>> Layout.parse("data=E_scat[1], units=mm, frequency=9.9, frequency_unit=GHz").data
    'E_scat[1]'
    """

    data: str | None = None
    i: str | None = None
    q: str | None = None
    amplitude: str | None = None
    phase: str | None = None
    x: str | None = None
    y: str | None = None
    frequency: str | float | tuple[float, ...] | None = None
    pitch: float | None = None
    axes: str | None = None
    length_unit: str = "m"
    frequency_unit: str = "Hz"
    phase_unit: str = "rad"
    iq_sign: str = "I+iQ"
    monostatic: bool | None = None
    tx_offset: tuple[float, ...] | None = None
    wide: str | None = None
    response: str | None = None
    given: frozenset[str] = field(default=frozenset(), compare=False, repr=False)
    """The keys set explicitly (by :meth:`from_mapping`): they win in :meth:`merged`
    even where they equal the default."""

    def __post_init__(self) -> None:
        for name in ("data", "i", "q", "amplitude", "phase", "x", "y"):
            v = getattr(self, name)
            if v is not None and (not isinstance(v, str) or not v.strip()):
                raise ValueError(f"layout {name} must be a variable name (optionally with "
                                 f"integer indices, e.g. E[1]), got {v!r}")
        if self.length_unit not in LENGTH_UNITS:
            raise ValueError(f"layout length_unit must be one of {list(LENGTH_UNITS)}, got "
                             f"{self.length_unit!r}")
        if self.frequency_unit not in FREQUENCY_UNITS:
            raise ValueError(f"layout frequency_unit must be one of {list(FREQUENCY_UNITS)}, "
                             f"got {self.frequency_unit!r}")
        if self.phase_unit not in _PHASE_UNITS:
            raise ValueError(f"layout phase_unit must be 'rad' or 'deg', got "
                             f"{self.phase_unit!r}")
        if self.iq_sign not in ("I+iQ", "I-iQ"):
            raise ValueError(f"layout iq_sign must be 'I+iQ' or 'I-iQ', got {self.iq_sign!r}")
        if (self.i is None) != (self.q is None):
            raise ValueError("layout i and q go together: name both (the in-phase and the "
                             "quadrature variable)")
        if (self.amplitude is None) != (self.phase is None):
            raise ValueError("layout amplitude and phase go together: name both")
        if sum(v is not None for v in (self.data, self.i, self.amplitude)) > 1:
            raise ValueError("layout: name one field form: data, or i and q, or amplitude and "
                             "phase")
        if self.axes is not None:
            a = self.axes
            if (not isinstance(a, str) or set(a) - set("yxftc") or a.count("y") > 1
                    or a.count("x") != 1 or a.count("f") > 1 or a.count("c") > 1):
                raise ValueError("layout axes must name each axis of the field with one letter "
                                 "of x (once), y, f, c (at most once each), t, e.g. 'fyx' "
                                 "(a grid) or 'fx' (a line scan along x), got "
                                 f"{a!r}")
        if self.pitch is not None and not (isinstance(self.pitch, int | float)
                                           and np.isfinite(self.pitch) and self.pitch > 0):
            raise ValueError(f"layout pitch must be a number > 0, got {self.pitch!r}")
        f = self.frequency
        if f is not None and not isinstance(f, str):
            vals = np.atleast_1d(np.asarray(f, dtype=float)) if _numeric(f) else None
            if vals is None or vals.ndim != 1 or not np.all(np.isfinite(vals)) \
                    or np.any(vals <= 0):
                raise ValueError("layout frequency must be a variable name or positive "
                                 f"number(s), got {f!r}")
        if self.monostatic is not None and not isinstance(self.monostatic, bool):
            raise ValueError(f"layout monostatic must be true or false, got {self.monostatic!r}")
        d = self.tx_offset
        if d is not None and (isinstance(d, str) or not _numeric(d)
                              or np.shape(d) not in ((2,), (3,))
                              or not np.all(np.isfinite(np.asarray(d, float)))):
            raise ValueError("layout tx_offset must be [dx, dy] or [dx, dy, dz] in the "
                             f"layout's length unit, got {d!r}")
        if self.response is not None and (not isinstance(self.response, str)
                                          or not self.response.strip()):
            raise ValueError(f"layout response must be a file's path, got {self.response!r}")
        if self.wide not in (None, "reim", "magphase"):
            raise ValueError("layout wide must be 'reim' (each frequency's real and imaginary "
                             f"parts) or 'magphase', got {self.wide!r}")

    @classmethod
    def from_mapping(cls, mapping: Mapping[str, Any], what: str = "layout") -> Layout:
        """A layout from a dict (e.g. a JSON sidecar's ``"layout"``); ``units`` is an
        alias of ``length_unit``."""
        if not isinstance(mapping, Mapping):
            raise ValueError(f"{what} must be a mapping of layout keys, got "
                             f"{type(mapping).__name__}")
        m = dict(mapping)
        if "units" in m:
            m["length_unit"] = m.pop("units")
        known = {f.name for f in fields(cls)} - {"given"}
        unknown = sorted(set(m) - known)
        if unknown:
            raise ValueError(f"{what}: unknown key(s) {unknown}; known: {sorted(known)} "
                             "(and units)")
        for key in ("frequency", "tx_offset"):
            if isinstance(m.get(key), list):
                m[key] = tuple(m[key])
        if m.get("wide") is True or (isinstance(m.get("wide"), str)
                                     and m["wide"].lower() in ("true", "yes", "1")):
            m["wide"] = "reim"
        elif m.get("wide") is False:
            m["wide"] = None
        try:
            return cls(**m, given=frozenset(m))
        except TypeError as exc:
            raise ValueError(f"{what}: {exc}") from None

    @classmethod
    def parse(cls, text: str) -> Layout:
        """A layout from ``key=value`` pairs separated by commas (the command line's form).

        Numbers are read for ``pitch`` and ``frequency`` (``frequency=9.9``, a list
        ``frequency=[8.2, 9.1, 10]``, or a variable name); ``monostatic=true``; the
        bare word ``wide``. A comma inside ``[...]`` does not
        split.
        """
        m: dict[str, Any] = {}
        for part in re.split(r",(?![^\[]*\])", text):
            if not part.strip():
                continue
            key, sep, value = part.partition("=")
            if not sep and key.strip() == "wide":
                m["wide"] = "reim"          # the bare word: a wide table of Re, Im
                continue
            if not sep:
                raise ValueError(f"layout entries are key=value (or the word wide), got "
                                 f"{part.strip()!r}")
            key, value = key.strip(), value.strip()
            if key in ("pitch", "frequency") and _is_number(value):
                m[key] = float(value)
            elif key in ("frequency", "tx_offset") and value.startswith("[") \
                    and value.endswith("]"):
                # a list: frequency=[8.2, 9.1, 10.0] (commas or spaces between)
                items = [v for v in re.split(r"[,\s]+", value[1:-1]) if v]
                if not items or not all(_is_number(v) for v in items):
                    raise ValueError(f"layout {key} must be a list of numbers such as "
                                     f"[8.2, 9.1, 10], got {value!r}")
                m[key] = tuple(float(v) for v in items)
            elif key == "tx_offset":
                raise ValueError("layout tx_offset must be a list [dx, dy, dz] in the "
                                 f"layout's length unit, got {value!r}")
            elif key == "monostatic":
                if value.lower() not in ("true", "false", "1", "0", "yes", "no"):
                    raise ValueError(f"layout monostatic must be true or false, got {value!r}")
                m[key] = value.lower() in ("true", "1", "yes")
            else:
                m[key] = value
        return cls.from_mapping(m)

    def merged(self, other: Layout | None) -> Layout:
        """This layout with every field that ``other`` sets: its explicitly given keys
        (:meth:`parse`, :meth:`from_mapping`), or else those that differ from the default."""
        if other is None:
            return self
        default = Layout()
        keys = other.given or {f.name for f in fields(self) if f.name != "given"
                               and getattr(other, f.name) != getattr(default, f.name)}
        changes = {k: getattr(other, k) for k in keys}
        return replace(self, **changes, given=self.given | frozenset(keys))


def layout_tx_offset(lay: Layout) -> tuple[float, ...] | None:
    """The layout's ``tx_offset`` in metres (None: none given)."""
    if lay.tx_offset is None:
        return None
    return tuple(float(v) * LENGTH_UNITS[lay.length_unit] for v in lay.tx_offset)


def _numeric(v: Any) -> bool:
    try:
        np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        return False
    return True


def _describe(variables: Mapping[str, np.ndarray]) -> str:
    parts = [f"{k} {tuple(v.shape)} {v.dtype}" for k, v in variables.items()
             if not k.startswith("__")]
    other = variables.get("__other__")
    if other is not None and other.size:
        parts.append(f"(not numeric: {', '.join(map(str, other))})")
    return "; ".join(parts) if parts else "nothing numeric"


def _get(variables: Mapping[str, np.ndarray], ref: str, what: str) -> np.ndarray:
    if ref in variables and not ref.startswith("__"):  # a name such as "I [V]" as it is
        return np.asarray(variables[ref])
    m = _REF.match(ref)
    if m is None:
        raise ValueError(f"{what}: bad variable reference {ref!r}")
    name = m["name"]
    if name not in variables or name.startswith("__"):
        raise ValueError(f"{what} has no variable {name!r}; found: {_describe(variables)}")
    arr = variables[name]
    if m["idx"]:
        idx = tuple(int(v) for v in m["idx"].split(","))
        if len(idx) > arr.ndim or any(not -s <= i < s for i, s in zip(idx, arr.shape,
                                                                      strict=False)):
            raise ValueError(f"{what}: {ref!r} is out of range for {name} of shape "
                             f"{arr.shape}")
        arr = arr[idx]
    return np.asarray(arr)


def _find(variables: Mapping[str, np.ndarray], role: str) -> str | None:
    hits = [n for n in _NAMES[role] if n in variables]
    return hits[0] if hits else None


def _field(variables: Mapping[str, np.ndarray], lay: Layout, what: str) -> np.ndarray:
    data_ref, i_ref, a_ref = lay.data, lay.i, lay.amplitude
    q_ref, p_ref = lay.q, lay.phase
    if data_ref is None and i_ref is None and a_ref is None:
        data_ref = _find(variables, "data")
        if data_ref is None:
            i_ref, q_ref = _find(variables, "i"), _find(variables, "q")
            if i_ref is None or q_ref is None:
                i_ref = q_ref = None
                a_ref, p_ref = _find(variables, "amplitude"), _find(variables, "phase")
                if a_ref is None or p_ref is None:
                    raise ValueError(
                        f"{what}: no hologram found. Needed: a complex variable named data "
                        "(or hologram, field), or I and Q, or amplitude and phase; or name "
                        "yours with the layout (e.g. data=E_scat[1], or i=...,q=...). Found: "
                        f"{_describe(variables)}")
    if data_ref is not None:
        d = _get(variables, data_ref, what)
        if d.dtype.kind not in "biufc":
            raise ValueError(f"{what}: {data_ref!r} is not numeric ({d.dtype})")
        if d.dtype.kind != "c" and "c" not in (lay.axes or ""):
            raise ValueError(f"{what}: {data_ref!r} is real: holoradar needs the complex "
                             "field. Give I and Q (i=..., q=...), amplitude and phase, or "
                             "declare the I/Q axis with the letter c in axes (e.g. axes=yxc)")
        return d
    if i_ref is not None:
        i, q = _get(variables, i_ref, what), _get(variables, q_ref or "", what)
        if i.shape != q.shape:
            raise ValueError(f"{what}: I {i_ref!r} {i.shape} and Q {q_ref!r} {q.shape} differ "
                             "in shape")
        if i.dtype.kind not in "biuf" or q.dtype.kind not in "biuf":
            raise ValueError(f"{what}: I and Q must be real numbers, got {i.dtype}, {q.dtype}")
        return i.astype(float) + 1j * q.astype(float)
    a, p = _get(variables, a_ref or "", what), _get(variables, p_ref or "", what)
    if a.shape != p.shape:
        raise ValueError(f"{what}: amplitude {a.shape} and phase {p.shape} differ in shape")
    if a.dtype.kind not in "biuf" or p.dtype.kind not in "biuf":
        raise ValueError(f"{what}: amplitude and phase must be real numbers")
    if lay.phase_unit == "rad" and p.size and float(np.max(np.abs(p))) > 2 * np.pi + 1e-6:
        raise ValueError(f"{what}: phases up to {float(np.max(np.abs(p))):.4g} exceed 2 pi: "
                         "degrees read as radians? (declare phase_unit=deg)")
    return a.astype(float) * np.exp(1j * p.astype(float) * _PHASE_UNITS[lay.phase_unit])


def _frequency(variables: Mapping[str, np.ndarray], lay: Layout, what: str) -> np.ndarray:
    f = lay.frequency
    if f is None:
        hits = [n for n in _NAMES["frequency"] if n in variables]
        if not hits:
            raise ValueError(f"{what}: no frequency found. Needed: a variable named frequency "
                             "(Hz), or give it with the layout (frequency=9.9e9 or "
                             f"frequency=NAME). Found: {_describe(variables)}")
        vals = [np.ravel(np.asarray(variables[h], float)) for h in hits]
        if any(v.shape != vals[0].shape or not np.allclose(v, vals[0]) for v in vals[1:]):
            raise ValueError(f"{what}: several frequency variables disagree ({hits}); name "
                             "one with the layout (frequency=NAME)")
        out = vals[0]
    elif isinstance(f, str):
        out = np.ravel(_get(variables, f, what)).astype(float)
    else:
        out = np.atleast_1d(np.asarray(f, dtype=float))
    return out * FREQUENCY_UNITS[lay.frequency_unit]


def _coordinate(variables: Mapping[str, np.ndarray], lay: Layout, role: str, n: int,
                what: str) -> np.ndarray | None:
    named = getattr(lay, role)
    if named is not None and lay.pitch is not None:
        raise ValueError(f"{what}: the layout gives both {role}={named} and pitch={lay.pitch}: "
                         "give the coordinates or the pitch, not both")
    # A declared pitch wins over coordinates found under their usual names (the file's
    # "x" may be an element index).
    ref = named or (None if lay.pitch is not None else _find(variables, role))
    if ref is None:
        if lay.pitch is None:
            return None
        return (np.arange(n) - (n - 1) / 2) * lay.pitch * LENGTH_UNITS[lay.length_unit]
    v = _get(variables, ref, what)
    if v.dtype.kind not in "biuf":
        raise ValueError(f"{what}: coordinate {ref!r} must be real numbers, got {v.dtype}")
    if v.ndim == 2 and min(v.shape) > 1:
        # MATLAB's meshgrid: X(iy, ix) = x(ix) (rows alike), Y(iy, ix) = y(iy) (columns)
        line = v[0, :] if role == "x" else v[:, 0]
        alike = np.allclose(v, line[None, :] if role == "x" else line[:, None], rtol=0,
                            atol=1e-9 * float(np.max(np.abs(v)) or 1.0))
        if not alike:
            raise ValueError(f"{what}: coordinate {ref!r} is a 2-D array {v.shape} that is not "
                             f"a meshgrid of {role}: give the 1-D {role} of the elements")
        v = line
    return np.ravel(v).astype(float) * LENGTH_UNITS[lay.length_unit]


def _default_axes(shape: tuple[int, ...], nf: int) -> str:
    nd = len(shape)
    if nd < 2:
        raise ValueError(f"the field must have at least 2 axes (y, x), got shape {shape}")
    if nd >= 3 and shape[-3] == nf:  # (nf == 1: a frequency axis of one, dropped)
        return "t" * (nd - 3) + "fyx"
    return "t" * (nd - 2) + "yx"


def _levels(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct values of a table column and each row's index into them; values
    within a millionth of the column's span are one (printing rounds coordinates)."""
    order = np.unique(v)
    tol = 1e-6 * float(order[-1] - order[0]) if order.size > 1 else 0.0
    group = np.concatenate([[0], np.cumsum(np.diff(order) > tol)])
    levels = np.array([order[group == g].mean() for g in range(int(group[-1]) + 1)])
    return levels, group[np.searchsorted(order, v)]


def _table(field: np.ndarray, xs: np.ndarray, ys: np.ndarray, fs: np.ndarray | None,
           what: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Gather a table (one row per element and frequency) into a (nf,) ny x nx grid."""
    ux, ix = _levels(xs)
    uy, iy = _levels(ys)
    if fs is not None and fs.size == field.size and np.unique(fs).size > 1:
        uf, jf = _levels(fs)
    else:
        uf, jf = None, np.zeros(field.size, int)
    nf = 1 if uf is None else uf.size
    grid = np.zeros((nf, uy.size, ux.size), complex)
    count = np.zeros(grid.shape, int)
    np.add.at(count, (jf, iy, ix), 1)
    if np.any(count > 1):
        raise ValueError(f"{what}: the table lists some element (x, y"
                         f"{', frequency' if uf is not None else ''}) more than once")
    if not np.all(count == 1):
        missing = int(np.sum(count == 0))
        raise ValueError(f"{what}: the table's rows do not fill a grid: {missing} of "
                         f"{count.size} (x, y{', frequency' if uf is not None else ''}) "
                         f"positions have no row ({ux.size} x values, {uy.size} y values)")
    grid[jf, iy, ix] = field
    return (grid if uf is not None else grid[0]), ux, uy, uf


def assemble(variables: Mapping[str, np.ndarray], layout: Layout | None = None,
             what: str = "file") -> Hologram:
    """Build a Hologram from a file's variables and a layout.

    Parameters
    ----------
    variables : mapping of str to ndarray
        What :func:`~holoradar.io.readers.read_variables` returned.
    layout : Layout, optional
        Names, axes and units; unnamed variables are looked up under their usual
        names (``data``/``hologram``/``field``, ``I``/``Q``,
        ``amplitude``/``phase``, ``x``, ``y``, ``frequency``).
    what : str
        The file's name, for messages.

    Raises
    ------
    ValueError
        A variable missing (the message lists what the file holds and what is
        needed), shapes that disagree with the coordinates or the declared axes.

    Examples
    --------
    >>> import numpy as np
    >>> v = {"I": np.ones((2, 3)), "Q": np.zeros((2, 3)), "freq_GHz": np.array(9.9)}
    >>> h = assemble(v, Layout(frequency="freq_GHz", frequency_unit="GHz", pitch=2.5,
    ...                        length_unit="cm"))
    >>> h.frequency, h.pitch
    (9900000000.0, (0.025, 0.025))
    """
    lay = layout or Layout()
    field = _field(variables, lay, what)
    freq = _frequency(variables, lay, what)
    if lay.iq_sign == "I-iQ":
        field = np.conj(field) if field.dtype.kind == "c" else field
    x_ref, y_ref = lay.x or _find(variables, "x"), lay.y or _find(variables, "y")
    declared_line = lay.axes is not None and "y" not in lay.axes and \
        len(lay.axes) == field.ndim
    if field.ndim == 1 and not declared_line and (x_ref is None or y_ref is None):
        raise ValueError(f"{what}: the field is one column ({field.size} values): a table "
                         "needs x and y columns too; name them with the layout (x=..., "
                         f"y=...). Found: {_describe(variables)}")
    if field.ndim == 1 and not declared_line:
        xs = _coordinate(variables, lay, "x", 0, what)
        ys = _coordinate(variables, lay, "y", 0, what)
        assert xs is not None and ys is not None
        if xs.size != field.size or ys.size != field.size:
            raise ValueError(f"{what}: a table needs x, y columns as long as the field "
                             f"({field.size} rows), got {xs.size} and {ys.size}")
        fs = freq if freq.size == field.size else None
        if fs is None and freq.size != 1:
            raise ValueError(f"{what}: a table's frequency must be one value or a column "
                             f"as long as the field, got {freq.size} values")
        grid, x, y, uf = _table(field, xs, ys, fs, what)
        f: Any = uf if uf is not None else float(fs[0] if fs is not None else freq[0])
        return _hologram(grid, x, y, f, lay, what)
    axes = lay.axes or _default_axes(field.shape, freq.size)
    if len(axes) != field.ndim:
        raise ValueError(f"{what}: layout axes {axes!r} names {len(axes)} axes but the field "
                         f"has {field.ndim} (shape {field.shape})")
    if "c" in axes:
        if field.dtype.kind == "c" or field.shape[axes.index("c")] != 2:
            raise ValueError(f"{what}: the I/Q axis (c) must be a real axis of length 2, got "
                             f"{field.dtype} of length {field.shape[axes.index('c')]}")
        c = axes.index("c")
        field = np.take(field, 0, axis=c) + 1j * np.take(field, 1, axis=c)
        if lay.iq_sign == "I-iQ":
            field = np.conj(field)
        axes = axes.replace("c", "")
    order = [i for i, a in enumerate(axes) if a == "t"] + \
            [axes.index(a) for a in "fyx" if a in axes]
    field = np.transpose(field, order)
    line = "y" not in axes
    if line:   # a line scan along x: one row, at y = 0
        field = field[..., None, :]
    ny, nx = field.shape[-2:]
    x = _coordinate(variables, lay, "x", nx, what)
    y = np.zeros(1) if line else _coordinate(variables, lay, "y", ny, what)
    if x is None or y is None:
        raise ValueError(f"{what}: no coordinates found. Needed: variables x and y (element "
                         "centres) or a pitch in the layout (pitch=0.025). Found: "
                         f"{_describe(variables)}")
    if x.size != nx or y.size != ny:
        hint = (" (x and y look swapped: declare axes=xy)"
                if x.size == ny and y.size == nx and nx != ny else "")
        if not lay.axes and freq.size > 1 and nx == freq.size:
            hint = (f" (the last axis has {freq.size} entries, one per frequency: MATLAB's "
                    "(ny, nx, nf) order? declare axes=yxf)")
        raise ValueError(f"{what}: the field's last axes are y={ny}, x={nx} but the "
                         f"coordinates hold y={y.size}, x={x.size}{hint}")
    if "f" in axes:
        if field.shape[-3] != freq.size:
            raise ValueError(f"{what}: the frequency axis has {field.shape[-3]} entries but "
                             f"{freq.size} frequencies were given")
        f = freq if freq.size > 1 else float(freq[0])
        if freq.size == 1:
            field = field[..., 0, :, :]
    elif freq.size == 1:
        f = float(freq[0])
    else:
        hint = ""
        if not lay.axes and field.ndim == 3 and field.shape[-1] == freq.size:
            hint = (f" (its last axis has {freq.size} entries: MATLAB's (ny, nx, nf) order? "
                    "declare axes=yxf)")
        raise ValueError(f"{what}: {freq.size} frequencies but no frequency axis of that "
                         f"length in the field of shape {field.shape}: declare it in axes "
                         f"(e.g. axes=fyx){hint}")
    return _hologram(field, x, y, f, lay, what)


def _hologram(field: np.ndarray, x: np.ndarray, y: np.ndarray, f: Any, lay: Layout,
              what: str) -> Hologram:
    try:
        line = lay.axes is not None and "y" not in lay.axes
        mono = lay.monostatic if lay.monostatic is not None else line
        return Hologram(field, x, y, f, monostatic=mono,
                        tx_offset=layout_tx_offset(lay))
    except ValueError as exc:
        raise ValueError(f"{what}: {exc}") from None
