"""A device's per-frequency response and frequency list, read from files.

A response is given in the device's own convention, as its data are recorded (where
the layout says ``iq_sign=I-iQ`` both are conjugated: dividing the recorded data by
the recorded response is what is done). A response table (CSV, a header row), or
any file :func:`holoradar.load` reads (MATLAB, NumPy, HDF5: the same names as
variables, or one complex variable), gives the device's complex response at each of
its frequencies: a ``frequency`` column and either ``re``/``im`` (also ``real``/
``imag``, ``I``/``Q``), ``amplitude``/``phase`` (also ``magnitude``; ``phase`` in
radians, ``phase_deg`` in degrees) or ``phase`` alone. Each frequency of the data is
divided by the response interpolated there
(:func:`holoradar.apply_calibration`: amplitude and unwrapped phase linear between
table frequencies; a table that does not cover the data's band is refused).

A frequency file holds the data's frequencies, one per line or separated by commas.

Frequencies in either are in Hz unless the values can only be in one other unit
between 0.1 GHz and 1 THz (``8.2`` is GHz); where two units could hold them, refused.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .band_unit import band_unit
from .layout import FREQUENCY_UNITS

__all__ = ["apply_response", "read_frequencies", "read_response"]

def _hz(values: np.ndarray, what: str) -> np.ndarray:
    unit = band_unit(values, what, "write them in Hz")
    return np.round(values * FREQUENCY_UNITS[unit], 3)


def read_frequencies(path: str | Path) -> np.ndarray:
    """The frequencies (Hz) a file lists, one per line or separated by commas or spaces.

    Raises
    ------
    ValueError
        Unreadable, empty, not numbers, not strictly increasing.

    Examples
    --------
    >>> import tempfile
    >>> p = Path(tempfile.mkdtemp()) / "f.txt"
    >>> _ = p.write_text("5.7\\n6.95\\n8.2\\n")
    >>> read_frequencies(p).tolist()
    [5700000000.0, 6950000000.0, 8200000000.0]
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{p.name}: cannot read it ({exc})") from None
    cells = [c for c in text.replace(",", " ").replace(";", " ").split()
             if not c.startswith("#")]
    try:
        f = np.array([float(c) for c in cells])
    except ValueError:
        raise ValueError(f"{p.name}: expected frequencies, numbers one per line, got "
                         f"{cells[:4]}") from None
    if f.size == 0 or not np.all(np.isfinite(f)) or np.any(np.diff(f) <= 0):
        raise ValueError(f"{p.name}: expected strictly increasing frequencies, got "
                         f"{f[:6].tolist()}")
    return _hz(f, p.name)


def read_response(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """The file's frequencies (Hz) and the complex response at each.

    A CSV or text table (module notes), or any file :func:`holoradar.load` reads
    (MATLAB, NumPy, HDF5, NetCDF): its variables are looked up by the same names
    (``frequency``...; ``re``/``im``, ``amplitude``/``phase``), a complex variable as
    long as the frequencies being the response itself.

    Raises
    ------
    ValueError
        Unreadable, no frequency variable or column, no response (naming what the file
        holds).
    """
    p = Path(path)
    if p.suffix.lower() in (".csv", ".txt", ".tsv", ".dat", ""):
        from .readers import read_csv

        try:
            cols = read_csv(p)
        except (OSError, UnicodeDecodeError) as exc:
            raise ValueError(f"{p.name}: cannot read it as a table ({exc})") from None
    else:
        from .readers import read_variables

        cols = {k: np.asarray(v) for k, v in read_variables(p).items()
                if not k.startswith("__")}
        cols = {k: v.ravel() for k, v in cols.items() if v.size > 1 and v.squeeze().ndim == 1}
    low = {k.strip().lower(): v for k, v in cols.items()}
    fname = next((k for k in ("frequency", "frequency_hz", "freq", "f", "frequency_ghz",
                              "frequencies", "freqs") if k in low), None)
    if fname is None:
        raise ValueError(f"{p.name}: a response table needs a frequency column (or a "
                         f"variable named frequency, freq or f); found {sorted(cols)}")
    fcol = low[fname]
    f = _hz(np.asarray(fcol, float), p.name)

    def pick(*names: str) -> Any:
        return next((low[n] for n in names if n in low), None)

    re, im = pick("re", "real", "i"), pick("im", "imag", "q")
    amp, ph, ph_deg = pick("amplitude", "magnitude", "amp", "mag"), pick("phase"), \
        pick("phase_deg")
    complex_ = [v for k, v in low.items()
                if k != fname and np.iscomplexobj(v) and np.size(v) == f.size]
    if re is not None and im is not None:
        r = np.asarray(re, float) + 1j * np.asarray(im, float)
    elif ph is not None or ph_deg is not None:
        phase = np.asarray(ph, float) if ph is not None else np.radians(np.asarray(ph_deg,
                                                                                  float))
        r = (np.asarray(amp, float) if amp is not None else 1.0) * np.exp(1j * phase)
    elif len(complex_) == 1:
        r = complex_[0]
    else:
        more = f" ({len(complex_)} complex ones: which?)" if complex_ else ""
        raise ValueError(f"{p.name}: a response needs re and im, or amplitude and phase (or "
                         f"phase_deg), or phase alone, or one complex variable as long as "
                         f"its frequencies{more}; found {sorted(cols)}")
    r = np.asarray(r).ravel()
    if r.size != f.size:
        raise ValueError(f"{p.name}: the response holds {r.size} values for {f.size} "
                         "frequencies")
    order = np.argsort(f)
    return f[order], np.asarray(r, complex)[order]


def apply_response(hologram: Any, path: str | Path, *, conjugate: bool = False) -> Any:
    """``hologram`` divided by the response a file gives (module notes).

    ``conjugate``: the response is written in the device's own convention, ``I - jQ``,
    as its data are; they were conjugated on reading (``iq_sign=I-iQ``), so the
    response is too before it is divided out (the same as dividing first).

    Raises
    ------
    ValueError
        The table's errors, or one that does not cover the data's frequencies
        (named with the file).
    """
    from ..data.wideband import apply_calibration

    f, r = read_response(path)
    if conjugate:
        r = np.conj(r)
    try:
        return apply_calibration(hologram, f, r, kind="complex")
    except ValueError as exc:
        raise ValueError(f"{Path(path).name}: {exc}") from None
