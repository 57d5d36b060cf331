"""Survey frames: what every frame must share, and where each one stands.

A frame is one hologram file. The frames of a survey are imaged with the same
settings into one store, so they must share a geometry (:class:`FrameGeometry`:
grid shape, pitch, frequencies, monostatic or not, the aperture's height); the
first readable frame sets it. A frame's position along the survey is the world
position of the centre of its element grid (:func:`frame_position`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..data.hologram import Hologram

__all__ = ["FrameGeometry", "frame_position", "frame_problem"]

_RTOL = 1e-9  # pitch and frequency: the same instrument writes the same numbers


@dataclass(frozen=True)
class FrameGeometry:
    """What all frames of a survey share.

    Attributes
    ----------
    ny, nx : int
        Elements along y and x.
    pitch : (float, float)
        Element pitch ``(dx, dy)``, metres.
    frequency : tuple of float
        Frequencies, Hz (one for a single-frequency hologram).
    wideband : bool
        True when the frequency is an axis of the data (``(nf, ny, nx)``).
    monostatic : bool
        Scanned transceiver (True) or receiver array (False).
    height : float
        The aperture's range below the reference plane, ``pose.center[2]``, metres.
    dtype : str
        Complex working precision, ``"complex64"`` or ``"complex128"``.

    Examples
    --------
    >>> import numpy as np
    >>> x = (np.arange(4) - 1.5) * 0.01
    >>> g = FrameGeometry.of(Hologram(np.ones((4, 4)), x, x, 9.9e9))
    >>> g.ny, g.nx, g.frequency, g.dtype
    (4, 4, (9900000000.0,), 'complex128')
    >>> FrameGeometry.from_dict(g.to_dict()) == g
    True
    """

    ny: int
    nx: int
    pitch: tuple[float, float]
    frequency: tuple[float, ...]
    wideband: bool
    monostatic: bool
    height: float
    dtype: str

    @classmethod
    def of(cls, holo: Hologram) -> FrameGeometry:
        """The geometry of one hologram (raises ``ValueError`` if it cannot be a frame)."""
        shape_problem = _shape_problem(holo)
        if shape_problem:
            raise ValueError(shape_problem)
        if getattr(holo, "tx_offset", None) is not None:
            raise ValueError("a survey's frames are transceivers or receiver arrays: a frame "
                             f"with tx_offset {holo.tx_offset} m (a transmitter beside the "
                             "receiver) is imaged on its own, with migrate or invert")
        dx, dy = holo.pitch
        return cls(int(holo.shape[-2]), int(holo.shape[-1]), (float(dx), float(dy)),
                   tuple(float(f) for f in holo.frequencies), bool(holo.is_wideband),
                   bool(holo.monostatic), float(holo.pose.center[2]),
                   "complex64" if holo.data.dtype == np.complex64 else "complex128")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (stored in the survey's attributes)."""
        return {"ny": self.ny, "nx": self.nx, "pitch_m": list(self.pitch),
                "frequency_hz": list(self.frequency), "wideband": self.wideband,
                "monostatic": self.monostatic, "height_m": self.height, "dtype": self.dtype}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> FrameGeometry:
        """Inverse of :meth:`to_dict`."""
        return cls(int(d["ny"]), int(d["nx"]), (float(d["pitch_m"][0]), float(d["pitch_m"][1])),
                   tuple(float(f) for f in d["frequency_hz"]), bool(d["wideband"]),
                   bool(d["monostatic"]), float(d["height_m"]), str(d["dtype"]))

    def image_shape(self, nz: int, upsample: int) -> tuple[int, int, int]:
        """``(nz, ny', nx')`` of a frame's image: ``n' = upsample*(n - 1) + 1``."""
        return nz, upsample * (self.ny - 1) + 1, upsample * (self.nx - 1) + 1

    def mismatch(self, holo: Hologram) -> str | None:
        """Why ``holo`` cannot join a survey of this geometry, or None if it can."""
        try:
            other = FrameGeometry.of(holo)
        except ValueError as exc:
            return str(exc)
        if other == self:  # the usual case, decided without the tolerances below
            return None
        if (other.ny, other.nx) != (self.ny, self.nx):
            return (f"grid {other.ny} x {other.nx} elements differs from the survey's "
                    f"{self.ny} x {self.nx}")
        if not np.allclose(other.pitch, self.pitch, rtol=_RTOL, atol=0.0):
            return (f"pitch {other.pitch[0]:.6g} x {other.pitch[1]:.6g} m differs from the "
                    f"survey's {self.pitch[0]:.6g} x {self.pitch[1]:.6g} m")
        if other.wideband != self.wideband or len(other.frequency) != len(self.frequency) \
                or not np.allclose(other.frequency, self.frequency, rtol=_RTOL, atol=0.0):
            return (f"frequency {_hz(other.frequency)} differs from the survey's "
                    f"{_hz(self.frequency)}")
        if other.monostatic != self.monostatic:
            kind = {True: "a scanned transceiver", False: "a receiver array"}
            return f"{kind[other.monostatic]}, the survey's frames are {kind[self.monostatic]}"
        if abs(other.height - self.height) > 1e-9:
            return (f"aperture height pose.center[2] = {other.height:.6g} m differs from the "
                    f"survey's {self.height:.6g} m (the planes z would lie at other depths)")
        return None


def _hz(f: tuple[float, ...]) -> str:
    return f"{f[0]:.6g} Hz" if len(f) == 1 else f"{len(f)} frequencies {f[0]:.6g}..{f[-1]:.6g} Hz"


def _shape_problem(holo: Hologram) -> str | None:
    core = 3 if holo.is_wideband else 2
    if holo.data.ndim != core:
        return (f"holds {holo.data.ndim - core} leading frame axes (data shape "
                f"{holo.data.shape}): a survey frame is one hologram")
    if not holo.pose.is_level:
        return (f"tilted aperture (pose tilt {np.degrees(holo.pose.tilt):.3g} deg): survey "
                "frames must be level (image tilted frames with migrate(frame='ground'))")
    return None


def frame_position(holo: Hologram) -> tuple[float, float, float]:
    """World position ``(x, y, z)`` of the centre of a frame's element grid, metres.

    For a level aperture (the only kind a survey takes) this is ``pose.center``
    plus the centre of the element coordinates: ``pose.center`` itself for the
    usual grids centred on 0 (:meth:`holoradar.Aperture.grid`), and the centre
    of the coordinates for a hologram with the identity pose.

    Examples
    --------
    >>> import numpy as np
    >>> import holoradar as hr
    >>> x = (np.arange(4) - 1.5) * 0.01
    >>> h = hr.Hologram(np.ones((4, 4)), x, x, 9.9e9, pose=hr.Pose((2.0, 0.5, 0.0)))
    >>> [round(v, 6) for v in frame_position(h)]
    [2.0, 0.5, 0.0]
    >>> frame_position(hr.Hologram(np.ones((4, 4)), x + 1.0, x, 9.9e9))[:2]
    (1.0, 0.0)
    """
    cx = 0.5 * (float(holo.x[0]) + float(holo.x[-1]))
    cy = 0.5 * (float(holo.y[0]) + float(holo.y[-1]))
    c = holo.pose.center
    return c[0] + cx, c[1] + cy, c[2]


def frame_problem(holo: Hologram, geometry: FrameGeometry | None) -> str | None:
    """Why ``holo`` is not a frame of a survey of ``geometry`` (any survey if None)."""
    if geometry is None:
        try:
            FrameGeometry.of(holo)
        except ValueError as exc:
            return str(exc)
        return None
    return geometry.mismatch(holo)
