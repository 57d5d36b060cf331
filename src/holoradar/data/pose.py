"""Where an aperture stands in the world: its centre and how its plane is tilted.

Frames
------
The world frame is the medium's: ``x``, ``y`` horizontal, ``z`` the range below
the reference plane (interfaces are planes ``z = const``; the ground's surface
is ``Medium.z_interfaces[0]``). An aperture has its own frame: element
coordinates ``(x', y')`` in its plane and its normal ``n``, which points
towards the scene. For the identity pose the two frames coincide (today's
frontal layout: the aperture on the plane ``z = 0``, looking down).

A :class:`Pose` with ``tilt`` theta and ``azimuth`` phi turns the aperture
about the horizontal axis ``a = (-sin phi, cos phi, 0)`` by theta, so that its
normal leans from the vertical towards ``(cos phi, sin phi, 0)``:

    R = Rz(phi) Ry(theta) Rz(-phi),      world = center + R @ (x', y', 0),
    n = R @ (0, 0, 1) = (sin theta cos phi, sin theta sin phi, cos theta).

``Ry(theta)`` turns ``z`` towards ``+x``. For ``phi = 0`` the aperture's own
``x'`` axis is ``(cos theta, 0, -sin theta)``: the edge of the array on the side
the normal leans to rises (towards smaller z), and ``y'`` stays ``+y``. For
``phi = 90 deg``, ``x'`` stays ``+x`` and ``y' = (0, cos theta, -sin theta)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Pose"]


@dataclass(frozen=True)
class Pose:
    """An aperture's centre in the world frame and the tilt of its plane.

    Parameters
    ----------
    center : (x, y, z)
        World position of the aperture's local origin (element coordinates
        ``x' = y' = 0``), metres; ``z`` is the range below the reference plane.
    tilt : float
        Angle between the aperture's normal and the world z axis, radians, in
        ``[0, pi/2)``.
    azimuth : float
        Direction in which the normal leans, radians from ``+x`` towards ``+y``.

    Examples
    --------
    >>> import numpy as np
    >>> p = Pose((0.0, 0.0, 0.1), tilt=np.radians(40), azimuth=np.radians(90))
    >>> np.round(p.normal, 3)
    array([0.   , 0.643, 0.766])
    >>> np.round(p.to_world(np.array([0.0, 0.1]), np.array([0.0, 0.0])), 3) + 0.0
    array([[0. , 0. , 0.1],
           [0.1, 0. , 0.1]])
    """

    center: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tilt: float = 0.0
    azimuth: float = 0.0

    def __post_init__(self) -> None:
        try:
            c = tuple(float(v) for v in np.asarray(self.center, dtype=float).ravel())
        except (TypeError, ValueError):
            c = ()
        if len(c) != 3 or not all(np.isfinite(c)):
            raise ValueError(f"center must be a world position (x, y, z) in metres, got "
                             f"{self.center!r}")
        for name in ("tilt", "azimuth"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float | np.floating | np.integer) \
                    or not np.isfinite(v):
                raise ValueError(f"{name} must be a finite angle in radians, got {v!r}")
        if not 0.0 <= float(self.tilt) < np.pi / 2:
            raise ValueError(f"tilt must be in [0, pi/2) radians (0: the aperture faces straight "
                             f"down; pi/2 would look along the ground), got {self.tilt!r} "
                             f"({np.degrees(float(self.tilt)):.1f} deg)")
        object.__setattr__(self, "center", c)
        object.__setattr__(self, "tilt", float(self.tilt))
        object.__setattr__(self, "azimuth", float(self.azimuth))

    @property
    def is_identity(self) -> bool:
        """True for the frontal layout at the origin (the aperture on z = 0)."""
        return self.tilt == 0.0 and self.center == (0.0, 0.0, 0.0)

    @property
    def is_level(self) -> bool:
        """True when the aperture is parallel to the ground (no tilt)."""
        return self.tilt == 0.0

    @property
    def rotation(self) -> np.ndarray:
        """``R = Rz(azimuth) Ry(tilt) Rz(-azimuth)`` (3, 3): columns are the
        aperture's x' and y' axes and its normal, in world coordinates."""
        ct, st = np.cos(self.tilt), np.sin(self.tilt)
        cp, sp = np.cos(self.azimuth), np.sin(self.azimuth)
        rz = np.array([[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]])
        ry = np.array([[ct, 0.0, st], [0.0, 1.0, 0.0], [-st, 0.0, ct]])
        r = rz @ ry @ rz.T
        r[np.abs(r) < 1e-15] = 0.0  # cos(pi/2) = 6e-17: keep axes along world axes exact
        if self.tilt == 0.0:
            r = np.eye(3)   # exactly: the level layout must reproduce the plain one bit for bit
        return r

    @property
    def u(self) -> np.ndarray:
        """The aperture's own x' axis in world coordinates (unit vector)."""
        return self.rotation[:, 0]

    @property
    def v(self) -> np.ndarray:
        """The aperture's own y' axis in world coordinates (unit vector)."""
        return self.rotation[:, 1]

    @property
    def normal(self) -> np.ndarray:
        """The aperture's normal (towards the scene) in world coordinates."""
        return self.rotation[:, 2]

    def to_world(self, xl: np.ndarray, yl: np.ndarray) -> np.ndarray:
        """World positions (..., 3) of points ``(x', y')`` in the aperture's plane."""
        xl, yl = np.broadcast_arrays(np.asarray(xl, float), np.asarray(yl, float))
        return (np.asarray(self.center) + xl[..., None] * self.u + yl[..., None] * self.v)

    def to_local(self, points: np.ndarray) -> np.ndarray:
        """Coordinates (..., 3) of world points in the aperture's frame: along its
        x and y axes and along its normal (``z'`` > 0 on the side it faces).

        Examples
        --------
        >>> p = Pose((0.0, 0.0, 0.1), tilt=np.radians(30))
        >>> [round(float(v), 6) for v in p.to_local(p.center + 0.2 * p.normal + 0.05 * p.u)]
        [0.05, 0.0, 0.2]
        """
        d = np.asarray(points, float) - np.asarray(self.center)
        return np.stack([d @ self.u, d @ self.v, d @ self.normal], axis=-1)

    def grid_points(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """World positions (ny, nx, 3) of a grid of element coordinates."""
        X, Y = np.meshgrid(np.asarray(x, float), np.asarray(y, float))
        return self.to_world(X, Y)


IDENTITY = Pose()
