"""Ranges and a ground checked against the array that is to focus them, and a range
against the planes a file or a survey holds: a unit slip (centimetres typed for metres)
is refused with the argument's name and the metres meant.

The refusals are :class:`RangeError`, a ``ValueError`` that carries the argument's
name as the caller spells it (an option such as ``--z``, or a keyword): the command
line shows it as an error of that option.
"""

from __future__ import annotations

import re
import warnings
from typing import Any

import numpy as np

__all__ = ["RangeError", "array_of", "check_ground", "check_planes", "check_ranges",
           "refuse_outside_planes", "scaled", "warn_above_ground"]


class RangeError(ValueError):
    """A range or a ground refused, naming the argument that gave it.

    Attributes
    ----------
    name : str
        The argument, as the caller named it (``"--z"``, ``"--z-surface"``, ``"z"``).
    """

    def __init__(self, message: str, name: str) -> None:
        super().__init__(message)
        self.name = name

    def __reduce__(self) -> tuple[Any, ...]:
        return type(self), (str(self), self.name)


def array_of(holo: Any) -> tuple[float, float]:
    """The larger full width (n * pitch, m) and the highest frequency (Hz) of a hologram's
    array (of an image: of its pixels, which span the array)."""

    def width(v: np.ndarray) -> float:
        v = np.asarray(v, dtype=float)
        return float(np.ptp(v) * v.size / (v.size - 1)) if v.size > 1 else 0.0

    return max(width(holo.x), width(holo.y)), float(np.max(holo.frequency))


def scaled(text: str, factor: float) -> str:
    """An option's numbers divided by a unit factor: ``35:55:0.5`` / 100 is
    ``0.35:0.55:0.005`` (the form a user should have typed).

    Examples
    --------
    >>> scaled("35:55:0.5", 100)
    '0.35:0.55:0.005'
    """
    return "".join(p if p in (":", ",") else f"{float(p) / factor:.6g}"
                   for p in re.split(r"([:,])", text.strip()))


def check_ranges(ranges: Any, text: str, name: str, aperture: float, frequency: float,
                 medium: Any = None, *, what: str | None = None, offset: float = 0.0,
                 escape: str | None = "--no-check") -> None:
    """Refuse ranges that no array of this width can focus (most likely centimetres or
    millimetres typed for metres), naming the argument and the metres meant.

    Parameters
    ----------
    ranges : float or array_like
        The ranges from the array plane the argument asks for, metres.
    text : str
        The argument's value as typed (for the corrected example).
    name : str
        The argument, e.g. ``"--z"``.
    aperture, frequency : float
        The array's larger width (m) and highest frequency (Hz).
    medium : Medium, optional
        The ground: ranges below it are judged by their apparent range.
    what : str, optional
        How the message names the ranges (default their span in metres).
    offset : float, optional
        The surface's range, for values that are depths below it.
    escape : str or None
        The flag that skips the check, named in the message.

    Raises
    ------
    RangeError
    """
    from .plausibility import range_problem, unit_slip

    problem = range_problem(ranges, aperture, frequency, medium, what, offset)
    if problem is None:
        return
    factor = unit_slip(ranges, aperture, frequency, medium, offset)
    raise RangeError(problem + _advice(
        None if factor is None else f"{name} {scaled(text, factor)}", escape), name)


def _advice(example: str | None, escape: str | None) -> str:
    """The way out of a refusal: the metres meant, and the flag that skips the check."""
    parts = ([f"give metres, e.g. {example}"] if example else []) + \
        ([f"{escape} takes the value as given"] if escape else [])
    return f" ({'; '.join(parts)})" if parts else ""


def _ground_flag(spec: dict[str, Any]) -> str:
    return ("--medium" if spec.get("medium_file") is not None else
            "--layers" if spec.get("layers") is not None else "--z-surface")


def check_ground(medium: Any, spec: dict[str, Any], aperture: float, frequency: float, *,
                 escape: str | None = "--no-check") -> None:
    """Refuse a ground whose surface or layers lie where the array focuses nothing
    (``--z-surface 30`` for 30 cm), naming the flag that gave it (``spec``: the command
    line's ground flags; ``--z-surface`` when none of ``--layers``, ``--medium``)."""
    if medium is None or medium.is_free_space:
        return
    name = _ground_flag(spec)
    deepest = float(medium.z_interfaces[-1])
    if name == "--z-surface":
        check_ranges(deepest, f"{deepest:g}", name, aperture, frequency, medium,
                     what=f"a ground surface {deepest:.4g} m", escape=escape)
        return
    from .plausibility import range_problem

    problem = range_problem(deepest, aperture, frequency, medium,
                            f"a layer top at {deepest:.4g} m")
    if problem is not None:
        raise RangeError(problem + _advice(None, escape), name)


def warn_above_ground(planes: Any, medium: Any, spec: dict[str, Any], name: str = "--z") -> None:
    """Warn when every plane lies in the air above the ground: it can be meant (looking
    at something above the surface), but the ground then plays no part."""
    if medium is None or medium.is_free_space:
        return
    z = np.atleast_1d(np.asarray(planes, dtype=float))
    surface = float(medium.z_interfaces[0])
    if z.max() < surface:
        from .plausibility import PlausibilityWarning, _span

        warnings.warn(f"every plane of {name} ({_span(z)} m) lies above the ground surface "
                      f"at {surface:.4g} m ({_ground_flag(spec)}): the image is in air and "
                      "the ground plays no part", PlausibilityWarning, stacklevel=2)


def check_planes(holo: Any, zs: Any, text: str, medium: Any, spec: dict[str, Any],
                 check: bool, name: str = "--z") -> None:
    """The checks of an imaging command's ranges and ground against the hologram's array:
    :func:`check_ranges`, :func:`check_ground`, :func:`warn_above_ground` (none without
    ``check``)."""
    if not check:
        return
    aperture, frequency = array_of(holo)
    check_ranges(zs, text, name, aperture, frequency, medium)
    check_ground(medium, spec, aperture, frequency)
    warn_above_ground(zs, medium, spec, name)


def refuse_outside_planes(value: float, planes: Any, name: str, what: str) -> None:
    """Refuse a range outside the planes a file or store holds (the nearest plane would
    be taken silently), naming the likely unit slip and the metres meant.

    Raises
    ------
    RangeError
    """
    from .plausibility import plane_problem

    problem = plane_problem(value, planes, what)
    if problem is None:
        return
    reason, factor = problem
    raise RangeError(reason + _advice(
        f"{name} {value / factor:.6g}" if factor != 1.0 else None, None), name)
