"""What the inspector tells the report: the specified minimum cover, and the fields of
the inspection (site, element, operator, scan...) shown at its top."""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

__all__ = ["FIELDS", "as_length", "as_meta"]

FIELDS = ("site", "element", "operator", "scan", "date", "device", "notes")
"""The usual fields, shown first and in this order (others follow as given)."""

_UNITS = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}


def as_length(value: Any, name: str = "min_cover") -> float | None:
    """A cover in metres: a number of metres, or text with its unit (``"35mm"``,
    ``"3.5 cm"``, ``"0.035"``, ``"0.035 m"``); None stays None.

    Raises
    ------
    ValueError
        Not a length, not positive, or over a metre (a cover; a unit slip).

    Examples
    --------
    >>> as_length("35mm"), as_length("3.5 cm"), as_length(0.035)
    (0.035, 0.035, 0.035)
    """
    if value is None:
        return None
    how = "a length such as 35mm, 3.5cm or 0.035 (metres)"
    if isinstance(value, str):
        m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*(mm|cm|m)?\s*", value)
        try:
            if m is None:
                raise ValueError
            v = float(m.group(1)) * _UNITS[m.group(2) or "m"]
        except ValueError:
            raise ValueError(f"{name}: expected {how}, got {value!r}") from None
    elif isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{name}: expected {how}, got {value!r}")
    else:
        v = float(value)
    if not (math.isfinite(v) and 0 < v <= 1.0):
        raise ValueError(f"{name}: expected a cover above 0 and at most 1 m ({how}), got "
                         f"{value!r}")
    return round(v, 12)


def as_meta(value: Any, name: str = "meta") -> list[tuple[str, str]]:
    """The inspection's fields as (label, text) pairs, the usual ones first.

    Parameters
    ----------
    value : mapping, path or None
        A mapping of field to text, or a TOML or JSON file holding one (a table of
        fields; nested tables are refused).
    name : str
        The argument's name in messages.

    Raises
    ------
    ValueError
        A file that cannot be read or is not a table of fields.

    Examples
    --------
    >>> as_meta({"operator": "A. N. Other", "site": "Bridge 7"})
    [('site', 'Bridge 7'), ('operator', 'A. N. Other')]
    """
    if value is None:
        return []
    if isinstance(value, str | os.PathLike):
        path = Path(value)
        try:
            text = path.read_text(encoding="utf-8")
            if path.suffix.lower() == ".json":
                data = json.loads(text)
            else:
                import tomllib

                data = tomllib.loads(text)
        except (OSError, UnicodeDecodeError, ValueError) as exc:
            raise ValueError(f"{name}: cannot read {path.name} as a TOML or JSON table of "
                             f"fields (site = \"...\", operator = \"...\"): {exc}") from None
        value = data
    if not isinstance(value, Mapping) or any(isinstance(v, Mapping | list) for v in
                                             value.values()):
        raise ValueError(f"{name}: expected a table of fields such as site, element, "
                         "operator, scan (each a text or a number), got "
                         f"{type(value).__name__}")
    fields = {str(k): str(v) for k, v in value.items() if v is not None and str(v) != ""}
    order = [k for k in FIELDS if k in fields] + [k for k in fields if k not in FIELDS]
    return [(k, fields[k]) for k in order]
