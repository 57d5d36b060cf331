"""A device's per-frequency response and frequency list, read from small text tables.

A response table (CSV, a header row) gives the device's complex response at each of
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
    """The table's frequencies (Hz) and the complex response at each.

    Raises
    ------
    ValueError
        No frequency column, no response columns (naming the columns found).
    """
    from .readers import read_csv

    p = Path(path)
    try:
        cols = read_csv(p)
    except OSError as exc:
        raise ValueError(f"{p.name}: cannot read it ({exc})") from None
    low = {k.strip().lower(): v for k, v in cols.items()}
    fcol = next((low[k] for k in ("frequency", "frequency_hz", "freq", "f", "frequency_ghz")
                 if k in low), None)
    if fcol is None:
        raise ValueError(f"{p.name}: a response table needs a frequency column; found "
                         f"{sorted(cols)}")
    f = _hz(np.asarray(fcol, float), p.name)

    def pick(*names: str) -> Any:
        return next((low[n] for n in names if n in low), None)

    re, im = pick("re", "real", "i"), pick("im", "imag", "q")
    amp, ph, ph_deg = pick("amplitude", "magnitude", "amp", "mag"), pick("phase"), \
        pick("phase_deg")
    if re is not None and im is not None:
        r = np.asarray(re, float) + 1j * np.asarray(im, float)
    elif ph is not None or ph_deg is not None:
        phase = np.asarray(ph, float) if ph is not None else np.radians(np.asarray(ph_deg,
                                                                                  float))
        r = (np.asarray(amp, float) if amp is not None else 1.0) * np.exp(1j * phase)
    else:
        raise ValueError(f"{p.name}: a response table needs re and im, or amplitude and "
                         f"phase (or phase_deg), or phase alone; found {sorted(cols)}")
    order = np.argsort(f)
    return f[order], np.asarray(r, complex)[order]


def apply_response(hologram: Any, path: str | Path) -> Any:
    """``hologram`` divided by the response a table gives (module notes).

    Raises
    ------
    ValueError
        The table's errors, or one that does not cover the data's frequencies
        (named with the file).
    """
    from ..data.wideband import apply_calibration

    f, r = read_response(path)
    try:
        return apply_calibration(hologram, f, r, kind="complex")
    except ValueError as exc:
        raise ValueError(f"{Path(path).name}: {exc}") from None
