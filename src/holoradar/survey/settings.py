"""The imaging settings of a survey: one set for every frame, kept in the store.

A rerun on an existing store must ask for the same settings (the frames it
resumes were imaged with them); :meth:`Settings.differences` says what differs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validate import check_nonnegative_ranges
from ..imaging.migration.settings import MigrationSettings
from ..physics.medium import Medium

__all__ = ["Settings"]


@dataclass(frozen=True, eq=False)
class Settings:
    """Planes, ground and method shared by every frame of a survey.

    Attributes
    ----------
    z : ndarray
        Ranges of the image planes from the aperture, metres (1-D, >= 0).
    medium : Medium or None
        Layered ground (None: free space).
    migration : MigrationSettings
        How each frame is migrated (its ``method`` and ``upsample`` are the survey's;
        every other option is ``migrate``'s default).

    Examples
    --------
    >>> s = Settings.make([0.2, 0.3], None, "angular", 1)
    >>> Settings.from_dict(s.to_dict()).differences(s)
    []
    >>> s.differences(Settings.make(0.25, None, "angular", 1))
    ['z: the store has [0.2, 0.3] m, this run asks [0.25] m']
    """

    z: np.ndarray
    medium: Medium | None
    migration: MigrationSettings

    @property
    def method(self) -> str:
        """Migration method, ``"angular"`` or ``"fresnel"``."""
        return self.migration.method

    @property
    def upsample(self) -> int:
        """Output pixels per element pitch."""
        return self.migration.upsample

    @classmethod
    def make(cls, z: float | Sequence[float] | np.ndarray, medium: Medium | None, method: str,
             upsample: int) -> Settings:
        """Validated settings (``ValueError`` on a bad value, as ``migrate`` says it)."""
        zs = np.array(check_nonnegative_ranges(z, "z"), dtype=float).ravel()
        if medium is not None and not isinstance(medium, Medium):
            raise ValueError(f"medium must be a holoradar.Medium or None, got "
                             f"{type(medium).__name__}")
        migration = MigrationSettings(method=method, upsample=upsample, progress=False)
        zs.setflags(write=False)
        return cls(zs, medium, migration)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form: numbers, lists and strings only (complex as ``[re, im]``)."""
        med = None if self.medium is None else {
            "z_interfaces_m": [float(v) for v in self.medium.z_interfaces],
            "eps": [[float(complex(e).real), float(complex(e).imag)] for e in self.medium.eps],
            "polarization": self.medium.polarization}
        return {"z_m": [float(v) for v in self.z], "medium": med, "method": self.method,
                "upsample": self.upsample}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Settings:
        """Inverse of :meth:`to_dict`."""
        m = d.get("medium")
        medium = None if m is None else Medium(
            tuple(m["z_interfaces_m"]), tuple(complex(re, im) for re, im in m["eps"]),
            m["polarization"])
        return cls.make(d["z_m"], medium, d["method"], int(d["upsample"]))

    def differences(self, asked: Settings) -> list[str]:
        """What ``asked`` changes against these (stored) settings, one line each."""
        mine, other = self.to_dict(), asked.to_dict()
        out = []
        for key, label, unit in (("z_m", "z", " m"), ("medium", "medium", ""),
                                 ("method", "method", ""), ("upsample", "upsample", "")):
            if mine[key] != other[key]:
                out.append(f"{label}: " + _contrast(mine[key], other[key], unit))
        return out


def _contrast(stored: Any, asked: Any, unit: str) -> str:
    """"the store has A, this run asks B": numbers to 6 digits (0.42, not
    0.42000000000000004), more only where the two would otherwise read the same."""
    for digits in (6, 9, 12, 17):
        a, b = _show(stored, digits), _show(asked, digits)
        if a != b:
            return f"the store has {a}{unit}, this run asks {b}{unit}"
    # Two lists of planes that differ only past the summary: name the first plane that does.
    k = next(i for i, (u, v) in enumerate(zip(stored, asked, strict=True)) if u != v)
    return (f"the store has {_show(stored)}{unit}, this run asks the same but for plane "
            f"{k + 1}: {stored[k]!r}{unit} stored, {asked[k]!r}{unit} asked")


def _show(v: Any, digits: int = 6) -> str:
    """A setting as a person reads it, numbers to ``digits`` significant digits.

    Examples
    --------
    >>> _show([0.38, 0.42000000000000004]), _show(list(np.arange(0.3, 0.5, 0.01)))
    ('[0.38, 0.42]', '20 planes 0.3..0.49 (step 0.01)')
    """

    def num(x: float) -> str:
        return repr(float(x)) if digits >= 17 else f"{x:.{digits}g}"

    if v is None:
        return "free space"
    if isinstance(v, dict):
        eps = ", ".join(f"{num(re)}{num(im) if im < 0 else '+' + num(im)}j"
                        for re, im in v["eps"])
        tops = ", ".join(num(t) for t in v["z_interfaces_m"])
        return f"interfaces [{tops}] m, eps ({eps}), {v['polarization']}"
    if isinstance(v, list) and len(v) > 6:
        steps = np.diff(v)
        step = f" (step {num(float(np.mean(steps)))})" \
            if np.allclose(steps, steps[0], rtol=1e-6, atol=0) else " (uneven steps)"
        return f"{len(v)} planes {num(v[0])}..{num(v[-1])}{step}"
    if isinstance(v, list):
        return "[" + ", ".join(num(x) for x in v) + "]"
    if isinstance(v, float):
        return num(v)
    return repr(v) if isinstance(v, str) else str(v)
