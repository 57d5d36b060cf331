"""Inputs read as the commands and the report read them: a hologram file (an image
refused by name), and the ground an image file was imaged through (its history)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["history_medium", "medium_of_history", "read_hologram"]


def read_hologram(path: Path, layout: Any, check: bool, *, iq_check: bool = True) -> Any:
    """A hologram from any supported file (:func:`holoradar.load`; ``iq_check`` as
    there).

    Raises
    ------
    ValueError
        The file cannot be read, or it holds an image (named: ``"NAME holds an image,
        not a hologram"``).
    """
    from ..data.hologram import Hologram
    from . import load

    obj = load(path, layout=layout, check=check, iq_check=iq_check)
    if not isinstance(obj, Hologram):
        raise ValueError(f"{path.name} holds an image, not a hologram")
    return obj


def history_medium(path: Path) -> Any:
    """The ground a holoradar image file was made through: the medium of the last
    ``migrate`` step of its history; None for another file, a file without that step
    or a step imaged in free space (anything unreadable is None too)."""
    from .netcdf import read_history

    if path.suffix.lower() not in (".nc", ".nc4"):
        return None
    try:
        steps = read_history(path)
    except (ValueError, OSError):
        return None
    return medium_of_history(steps)


def medium_of_history(steps: Any) -> Any:
    """The medium of the last ``migrate`` step of a processing history (a list of step
    dicts, as :attr:`Image.history` holds), or None (none, free space, unreadable).

    Examples
    --------
    >>> medium_of_history([{"step": "migrate", "parameters": {"medium": {
    ...     "z_interfaces": [0.3], "eps": ["(1+0j)", "(2.5+0.0125j)"]}}}]).eps[1]
    (2.5+0.0125j)
    """
    from ..physics.medium import Medium

    for step in reversed(list(steps or [])):
        if isinstance(step, dict) and step.get("step") == "migrate":
            g = (step.get("parameters") or {}).get("medium")
            if not g:
                return None
            try:
                return Medium(tuple(float(z) for z in g["z_interfaces"]),
                              tuple(complex(str(e).replace(" ", "")) for e in g["eps"]))
            except (KeyError, TypeError, ValueError):
                return None
    return None
