"""A permittivity for a person: its value to the digits its uncertainty allows."""

from __future__ import annotations

import math
from typing import Any

__all__ = ["eps_summary", "eps_text"]

Z95 = 1.959963984540054
"""The two-sided 95 % normal quantile."""


def _decimals(std: float) -> int:
    """Decimals that show two significant digits of ``std`` (at least one, at most 6)."""
    if not (std > 0 and math.isfinite(std)):
        return 3
    return max(1, min(6, 1 - math.floor(math.log10(std))))


def eps_text(eps: complex, std: Any = None, *, rough: str = "") -> str:
    """``eps`` with its 1-sigma and 95 % interval, or marked rough.

    Parameters
    ----------
    eps : complex
        The estimate (eps' + i eps'').
    std : (float, float) or None
        1-sigma of the real and imaginary parts.
    rough : str
        Why the estimate has no uncertainty (how it was made, and the way to one).

    Examples
    --------
    >>> eps_text(2.5213 + 0.0131j, (0.041, 0.0023))
    "eps' = 2.521 +- 0.041 (95 %: 2.441 .. 2.602), eps'' = 0.0131 +- 0.0023"
    >>> eps_text(2.64 + 3.1e-23j, rough="from the Gaussian fit's strength")
    "eps' about 2.6 (rough, no uncertainty: from the Gaussian fit's strength)"
    """
    e = complex(eps)
    if std is None or not all(math.isfinite(float(s)) for s in std):
        text = f"eps' about {e.real:.2g}"
        if abs(e.imag) > 1e-3 * abs(e.real):
            text += f", eps'' about {e.imag:.1g}"
        return text + (f" (rough, no uncertainty: {rough})" if rough else " (no uncertainty)")
    sr, si = (float(s) for s in std)
    d = _decimals(sr)
    text = (f"eps' = {e.real:.{d}f} +- {sr:.{d}f} (95 %: {e.real - Z95 * sr:.{d}f} .. "
            f"{e.real + Z95 * sr:.{d}f})")
    if abs(e.imag) > max(si, 1e-9 * abs(e.real)):   # an eps'' told from zero
        di = _decimals(si)
        text += f", eps'' = {e.imag:.{di}f} +- {si:.{di}f}"
    elif si > 0 and math.isfinite(si):
        text += f", eps'' below {Z95 * si + abs(e.imag):.2g} (95 %)"
    return text


def eps_summary(eps: Any, std: Any = None, rough: str = "") -> dict[str, Any]:
    """The JSON form: ``eps`` (re, im), ``eps_std``, ``eps_interval_95`` of eps', and
    ``eps_rough`` (the reason) where there is no uncertainty."""
    if eps is None:
        return {"eps": None}
    e = complex(eps)
    out: dict[str, Any] = {"eps": [e.real, e.imag]}
    if std is not None and all(math.isfinite(float(s)) for s in std):
        sr, si = (float(s) for s in std)
        out.update(eps_std=[sr, si], eps_interval_95=[e.real - Z95 * sr, e.real + Z95 * sr])
    else:
        out.update(eps_std=None, eps_interval_95=None, eps_rough=rough or True)
    return out
