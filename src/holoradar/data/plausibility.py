"""Catch unit mistakes before imaging: a hologram whose numbers cannot be a microwave
measurement gives a confident, wrong image, so it is refused with the likely cause.

The tests are physical, not stylistic. A holographic radar samples its field
at a pitch of the order of the wavelength (the paper's array: 2.5 cm at
3.03 cm; a scan: a few millimetres): a pitch beyond :data:`MAX_PITCH_WAVELENGTHS`
wavelengths or below 1/:data:`MIN_PITCH_FRACTION` of one means coordinates in
the wrong unit (millimetres read as metres gives 1000 times the pitch;
centimetres 100 times). A frequency below :data:`MIN_FREQUENCY` Hz is a value
in GHz or MHz read as Hz. Data that are zero everywhere carry no image.

Ranges are judged against the array: an array of width A focuses to a cell
``lambda L / A`` wide at the apparent range L, so beyond ``A^2 / lambda``
(:func:`far_range`) the cell is wider than the array and nothing can be
focused; 35 m in front of a 40 cm array at 9.9 GHz (a range in centimetres
read as metres) lies far beyond it (5.3 m). :func:`range_problem` says so with
the unit that would bring the range back; :func:`plane_problem` refuses a
depth outside the planes an image or survey holds.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from .hologram import C0, Hologram

__all__ = ["MAX_PITCH_WAVELENGTHS", "MIN_FREQUENCY", "MIN_PITCH_FRACTION", "PlausibilityWarning",
           "check_plausible", "far_range", "plane_problem", "plausibility_problems",
           "range_problem", "unit_slip"]

MIN_FREQUENCY = 1e8
"""100 MHz: below it no microwave holography; 9.9 given for 9.9 GHz lands here."""
MAX_FREQUENCY = 1e13
MAX_PITCH_WAVELENGTHS = 20.0
"""A pitch of 20 wavelengths aliases everything but the axial wave; a 2.5 cm pitch read
from millimetres as metres is 825 wavelengths at 9.9 GHz, from centimetres 82."""
MIN_PITCH_FRACTION = 1000.0
"""A pitch under lambda/1000 oversamples a thousandfold: 2.5 cm given in metres but read as
millimetres is lambda/1211 at 9.9 GHz. (A ground-penetrating radar at 150 MHz sampled
every centimetre is lambda/200, and passes.)"""


def plausibility_problems(hologram: Hologram) -> list[str]:
    """Every implausible feature of a hologram, each with its likely cause ([] if none).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.arange(16) * 25.0                      # millimetres taken for metres
    >>> h = Hologram(np.ones((16, 16), complex), x, x, 9.9e9)
    >>> print(plausibility_problems(h)[0])  # doctest: +ELLIPSIS
    element pitch 25 m is 825.6 wavelengths at 9.9 GHz: coordinates in millimetres...
    """
    out: list[str] = []
    f = hologram.frequencies
    if f.min() < MIN_FREQUENCY:
        out.append(f"frequency {f.min():.6g} Hz is below {MIN_FREQUENCY / 1e6:.0f} MHz: a value "
                   "in GHz or MHz read as Hz? (holoradar expects Hz; declare "
                   "frequency_unit=GHz)")
    elif f.max() > MAX_FREQUENCY:
        out.append(f"frequency {f.max():.6g} Hz is above 10 THz: a value in kHz or a "
                   "wavelength given for a frequency? (holoradar expects Hz)")
    else:
        lam = C0 / f.max()
        px, py = hologram.pitch
        for axis, p in (("x", px), ("y", py)):
            ratio = p / lam
            if ratio > MAX_PITCH_WAVELENGTHS:
                unit = "millimetres" if ratio > 300 else "centimetres"
                out.append(f"element pitch {p:.6g} m is {ratio:.1f} wavelengths at "
                           f"{f.max() / 1e9:.3g} GHz: coordinates in {unit} read as metres? "
                           f"(holoradar expects metres; declare length_unit="
                           f"{'mm' if unit == 'millimetres' else 'cm'})")
                break
            if ratio < 1 / MIN_PITCH_FRACTION:
                out.append(f"element pitch {p:.6g} m along {axis} is lambda/{1 / ratio:.0f} at "
                           f"{f.max() / 1e9:.3g} GHz: coordinates given in metres read as "
                           "millimetres, or a frequency in the wrong unit?")
                break
    if not np.any(hologram.data):
        out.append("every sample is zero: a dead channel, a blank frame or the wrong "
                   "variable")
    return out


def check_plausible(hologram: Hologram, what: str = "hologram") -> Hologram:
    """Raise ``ValueError`` naming the likely mistake if the hologram is implausible.

    Returns the hologram unchanged, so it can wrap a reader.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.arange(16) * 0.025
    >>> check_plausible(Hologram(np.ones((16, 16), complex), x, x, 9.9)) # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: hologram: frequency 9.9 Hz is below 100 MHz: a value in GHz or MHz read as Hz?...
    """
    problems = plausibility_problems(hologram)
    if problems:
        raise ValueError(f"{what}: " + "; ".join(problems))
    return hologram


class PlausibilityWarning(UserWarning):
    """A value that can be meant but is likely a slip (e.g. every plane above the ground)."""


_SLIPS = ((100.0, "centimetres"), (1000.0, "millimetres"))


def _span(v: np.ndarray) -> str:
    lo, hi = float(np.min(v)), float(np.max(v))
    return f"{lo:.4g}" if lo == hi else f"{lo:.4g}..{hi:.4g}"


def _slip(fits: Callable[[float], bool]) -> tuple[float, str] | None:
    """The first unit slip (centimetres, then millimetres) whose correction ``fits``."""
    return next(((f, unit) for f, unit in _SLIPS if fits(f)), None)


def far_range(aperture: float, frequency: float) -> float:
    """``A^2 / lambda``: the apparent range beyond which an array focuses nothing.

    There the resolution cell ``lambda L / A`` is as wide as the array itself.

    Parameters
    ----------
    aperture : float
        The array's larger full width, metres.
    frequency : float
        Its highest frequency, Hz (the shortest wavelength: the most lenient limit).

    Examples
    --------
    >>> round(far_range(0.40, 9.9e9), 2)
    5.28
    """
    return float(aperture) ** 2 * float(frequency) / C0


def _apparent(z: float, medium: Any) -> float:
    return float(z) if medium is None else float(medium.apparent_distance(float(z)))


def unit_slip(ranges: Any, aperture: float, frequency: float, medium: Any = None,
              offset: float = 0.0) -> float | None:
    """The factor (100: centimetres, 1000: millimetres) that brings implausible ranges
    within :func:`far_range`, or None (the ranges are plausible, or no factor helps).

    ``offset`` is added to every value and is not scaled (the surface's range, for
    values that are depths below it).
    """
    far = float(np.max(np.asarray(ranges, dtype=float)))
    limit = far_range(aperture, frequency)
    if _apparent(offset + far, medium) <= limit:
        return None
    hit = _slip(lambda f: _apparent(offset + far / f, medium) <= limit)
    return None if hit is None else hit[0]


def range_problem(ranges: Any, aperture: float, frequency: float, medium: Any = None,
                  what: str | None = None, offset: float = 0.0) -> str | None:
    """Why ranges cannot be meant for an array of this width, with the likely unit slip.

    Parameters
    ----------
    ranges : float or array_like
        Ranges from the array plane, metres.
    aperture : float
        The array's larger full width, metres.
    frequency : float
        Its highest frequency, Hz.
    medium : Medium, optional
        The ground: ranges below its surface are judged by their apparent range.
    what : str, optional
        How the message names the ranges (default ``"35..55 m"``).
    offset : float, optional
        A range added to every value and not scaled by a unit slip (the
        surface's, for values that are depths below it).

    Returns
    -------
    str or None
        A sentence naming the ranges, or None when they can be focused.

    Examples
    --------
    >>> print(range_problem([35.0, 55.0], 0.4, 9.9e9))  # doctest: +NORMALIZE_WHITESPACE
    35..55 m in front of a 0.4 m array at 9.9 GHz: beyond A^2/lambda = 5.3 m its resolution
    cell (lambda L / A, here 4.16 m) is wider than the array and nothing can be focused;
    centimetres given for metres?
    >>> range_problem(0.42, 0.4, 9.9e9) is None
    True
    """
    z = np.atleast_1d(np.asarray(ranges, dtype=float))
    limit = far_range(aperture, frequency)
    far = _apparent(offset + float(z.max()), medium)
    if far <= limit:
        return None
    cell = C0 / frequency * far / aperture
    hit = _slip(lambda f: _apparent(offset + float(z.max()) / f, medium) <= limit)
    return (f"{what or _span(z) + ' m'} in front of a {aperture:.3g} m array at "
            f"{frequency / 1e9:.3g} GHz: beyond A^2/lambda = {limit:.2g} m its resolution cell "
            f"(lambda L / A, here {cell:.3g} m) is wider than the array and nothing can be "
            "focused" + ("" if hit is None else f"; {hit[1]} given for metres?"))


def plane_problem(value: float, planes: Any, what: str = "planes") -> tuple[str, float] | None:
    """A range outside the planes an image or a survey holds (more than half a plane
    step beyond the first or last): the reason, and the factor of a likely unit slip
    (100, 1000; 1.0 when none fits), or None when a plane lies there.

    Examples
    --------
    >>> plane_problem(42.0, [0.30, 0.35, 0.40, 0.45, 0.50], "stored planes")
    ('42 m is outside the stored planes 0.3..0.5 m; centimetres given for metres?', 100.0)
    >>> plane_problem(0.43, [0.30, 0.35, 0.40, 0.45, 0.50]) is None
    True
    """
    z = np.sort(np.atleast_1d(np.asarray(planes, dtype=float)))
    step = float(np.min(np.diff(z))) if z.size > 1 else 0.0
    tol = max(step / 2, 1e-6)

    def inside(v: float) -> bool:
        return bool(z[0] - tol <= v <= z[-1] + tol)

    if inside(value):
        return None
    hit = _slip(lambda f: inside(value / f))
    return (f"{value:.4g} m is outside the {what} {_span(z)} m"
            + ("" if hit is None else f"; {hit[1]} given for metres?"),
            1.0 if hit is None else hit[0])
