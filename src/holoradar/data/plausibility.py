"""Catch unit mistakes before imaging: a hologram whose numbers cannot be a microwave
measurement gives a confident, wrong image, so it is refused with the likely cause.

The tests are physical, not stylistic. A holographic radar samples its field
at a pitch of the order of the wavelength (the paper's array: 2.5 cm at
3.03 cm; a scan: a few millimetres): a pitch beyond :data:`MAX_PITCH_WAVELENGTHS`
wavelengths or below 1/:data:`MIN_PITCH_FRACTION` of one means coordinates in
the wrong unit (millimetres read as metres gives 1000 times the pitch;
centimetres 100 times). A frequency below :data:`MIN_FREQUENCY` Hz is a value
in GHz or MHz read as Hz. Data that are zero everywhere carry no image.
"""

from __future__ import annotations

import numpy as np

from .hologram import C0, Hologram

__all__ = ["MAX_PITCH_WAVELENGTHS", "MIN_FREQUENCY", "MIN_PITCH_FRACTION", "check_plausible",
           "plausibility_problems"]

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
