"""Scanner exports as wide text tables: one row per measured point, its coordinates,
then two columns per frequency.

A near-field scanner (a probe on a robot, a VNA) writes, after some lines of
metadata, a header row and one row per point::

    Frequency, X, Y, Z, 8.2, 8.2, 9.1, 9.1, ...
    1, -64.1667, -64.1667, 10.0, 0.0132, -0.0021, 0.0101, 0.0044, ...

The header names the coordinate columns (``X``, ``Y``, and ``Z`` or an index column,
any case; other names are ignored) and then each frequency twice: the real and the
imaginary part (or, with ``wide=magphase``, the magnitude and the phase). The lines
above the header (the export's metadata) are skipped, and so are, below it, lines of
words and the header repeated (an export may repeat its header block, with section
titles, before the points); a row may carry its index as ``Point N``. A row of
numbers of another length than the header's is refused (a cut or damaged file).
Columns are separated by commas, semicolons, tabs or spaces.

:func:`read_wide` turns such a table into the long form the layout's table
gathering takes (one row per point and frequency: ``x``, ``y``, ``frequency`` and
``I``/``Q`` or ``amplitude``/``phase``). The frequencies are in the layout's
``frequency_unit`` when it gives one; otherwise the unit that puts them between
0.1 GHz and 1 THz (GHz for ``8.2``, Hz for ``8.2e9``), refused where two units could
(the layout then has to say).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from .band_unit import band_unit
from .layout import FREQUENCY_UNITS

__all__ = ["read_wide"]

_SPLIT = re.compile(r"\s*[,;\t]\s*|\s+")


def _cells(line: str) -> list[str]:
    return [c for c in _SPLIT.split(line.strip()) if c != ""]


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def read_wide(path: Path, frequency_unit: str | None, values: str = "reim"
              ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """A wide table as long-form variables, and what was read.

    Parameters
    ----------
    path : Path
        The text export (any suffix).
    frequency_unit : str or None
        The header's frequency unit (``Hz``, ``kHz``, ``MHz``, ``GHz``); None: found
        from the values (module notes).
    values : {"reim", "magphase"}
        What each frequency's two columns hold.

    Returns
    -------
    variables : dict
        ``x``, ``y`` (the table's units), ``frequency`` (Hz) and ``I``, ``Q`` (or
        ``amplitude``, ``phase``), one entry per point and frequency.
    info : dict
        ``metadata`` (the lines above the header), ``frequency_unit`` (as read),
        ``z`` (the plane's Z, the table's units, or None).

    Raises
    ------
    ValueError
        No header row, frequency columns that do not pair, rows of another length, a
        table of several planes (Z), an ambiguous frequency unit.

    Examples
    --------
    >>> import tempfile
    >>> p = Path(tempfile.mkdtemp()) / "scan.txt"
    >>> _ = p.write_text("probe: WR-90\\nFrequency, X, Y, Z, 9.9, 9.9, 10.1, 10.1\\n"
    ...                  "1, 0, 0, 5, 1, 0, 2, 0\\n2, 1, 0, 5, 0, 1, 0, 2\\n")
    >>> v, info = read_wide(p, None)
    >>> v["frequency"].tolist(), v["I"].tolist(), info["frequency_unit"], info["z"]
    ([9900000000.0, 10100000000.0, 9900000000.0, 10100000000.0], [1.0, 2.0, 0.0, 0.0], 'GHz', 5.0)
    """
    if values not in ("reim", "magphase"):
        raise ValueError(f"layout wide must be 'reim' or 'magphase' (what each frequency's two "
                         f"columns hold), got {values!r}")
    try:
        lines = path.read_text(encoding="utf-8-sig", errors="strict").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path.name}: cannot read it as text ({exc})") from None
    head = _header(lines, path.name)
    names = _cells(lines[head])
    coords = {n.lower(): j for j, n in enumerate(names) if _number(n) is None}
    if "x" not in coords or "y" not in coords:
        raise ValueError(f"{path.name}: the header row names no X and Y columns: {names[:6]}")
    first = max(coords.values()) + 1
    fcols = names[first:]
    freq = [_number(c) for c in fcols]
    if len(fcols) < 2 or len(fcols) % 2 or any(v is None for v in freq) or \
            any(freq[2 * i] != freq[2 * i + 1] for i in range(len(freq) // 2)):
        raise ValueError(f"{path.name}: after the coordinates the header must name each "
                         f"frequency twice ({'Re, Im' if values == 'reim' else 'mag, phase'}), "
                         f"got {fcols[:8]}{' ...' if len(fcols) > 8 else ''}")
    f = np.array(freq[::2], dtype=float)
    unit = frequency_unit or band_unit(
        f, f"{path.name} header", "say which in the layout, frequency_unit=GHz (or "
        "Hz, kHz, MHz)")
    hz = np.round(f * FREQUENCY_UNITS[unit], 3)     # 8.2 GHz is 8200000000 Hz, not ...999.999
    rows = []
    for n, line in enumerate(lines[head + 1:], start=head + 2):
        cells = _point_label(_cells(line))
        if not cells or cells == names or _number(cells[0]) is None:
            # A blank line, the header again, or a line of words (an export repeats
            # its header block, with section titles, before the points): not a point.
            continue
        if len(cells) != len(names):
            raise ValueError(f"{path.name} line {n}: {len(cells)} values for the header's "
                             f"{len(names)} columns")
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            raise ValueError(f"{path.name} line {n}: not all numbers: {cells[:6]}") from None
    if not rows:
        raise ValueError(f"{path.name}: a header but no rows of points")
    t = np.array(rows)
    z = None
    if "z" in coords:
        zs = np.unique(t[:, coords["z"]])
        if zs.size > 1:
            raise ValueError(f"{path.name}: the table holds {zs.size} planes (Z from {zs[0]:g} "
                             f"to {zs[-1]:g}): write one plane per file, or select the rows "
                             "of one Z")
        z = float(zs[0])
    a, b = t[:, first::2], t[:, first + 1::2]         # (points, frequencies)
    npts, nf = a.shape
    pair = ("I", "Q") if values == "reim" else ("amplitude", "phase")
    variables = {"x": np.repeat(t[:, coords["x"]], nf), "y": np.repeat(t[:, coords["y"]], nf),
                 "frequency": np.tile(hz, npts), pair[0]: a.ravel(), pair[1]: b.ravel()}
    return variables, {"metadata": lines[:head], "frequency_unit": unit, "z": z}


def _point_label(cells: list[str]) -> list[str]:
    """A row labelled ``Point N`` (a scanner's own label of its index column): the
    index alone, as the header's first column holds it."""
    if len(cells) > 1 and cells[0].lower() == "point" and _number(cells[1]) is not None:
        return cells[1:]
    return cells


def _header(lines: list[str], name: str) -> int:
    """The header row: the first with X and Y among its names followed by numbers."""
    for i, line in enumerate(lines):
        cells = _cells(line)
        low = [c.lower() for c in cells]
        if "x" in low and "y" in low and any(_number(c) is not None for c in cells):
            return i
    raise ValueError(f"{name}: no header row (coordinate names X, Y, then the frequencies, "
                     "each twice) in a wide table")
