"""Scene (medium + source + targets) and the receiver aperture."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validate import as_axis, as_polarization
from ..data.pose import IDENTITY, Pose
from ..data.tx_offset import as_tx_offset
from ..physics.medium import Medium
from ..physics.sources import PlaneWave
from .targets import LineTarget, PlanarTarget, PointTarget

__all__ = ["Aperture", "Scene"]


@dataclass(frozen=True, eq=False)
class Aperture:
    """A receiver array: a grid, or elements anywhere on its plane, placed by a pose.

    Parameters
    ----------
    x, y : array_like
        Element coordinates along x and y, metres, strictly increasing (a
        non-uniform grid is allowed; migration needs a uniform one).
    elements : array_like, shape (N, 2), optional
        Arbitrary element positions (x, y) in metres; use
        :meth:`from_positions`. Such an aperture is not a grid:
        :func:`holoradar.simulate` then returns the N element fields as an array.
    monostatic : bool
        The elements are positions of a scanned transceiver (each sends and
        receives) rather than receivers lit by a separate source.
    pose : Pose
        Where the aperture's plane stands in the world (default: the plane z = 0,
        facing down); ``x``, ``y`` and ``elements`` are coordinates in that plane.
    polarization : (float, float, float), optional
        Unit vector (world axes) of the field component the elements record;
        with a polarised source, :func:`holoradar.simulate` uses the vector model
        and the hologram carries it. Default ``None``: the scalar model.
    tx_offset : (float, float, float), optional
        A transmitter beside each scan position, metres (``dx, dy`` in the
        aperture's plane, ``dz`` towards the scene): the elements are the
        positions of a scanned receiver whose transmitter moves with it (implies
        ``monostatic``; the scalar model). See :class:`holoradar.Hologram`.

    Examples
    --------
    >>> Aperture.paper().x.size, round(Aperture.paper().size[0], 3)
    (16, 0.4)
    >>> Aperture.from_positions([[0.0, 0.0], [0.05, 0.01]]).points.shape
    (2, 3)
    """

    x: np.ndarray
    y: np.ndarray
    elements: np.ndarray | None = None
    monostatic: bool = False
    pose: Pose = IDENTITY
    polarization: np.ndarray | None = None
    tx_offset: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        pol = as_polarization(self.polarization, "polarization")
        object.__setattr__(self, "polarization", pol)
        object.__setattr__(self, "x", as_axis(self.x, "x"))
        object.__setattr__(self, "y", as_axis(self.y, "y"))
        offset = as_tx_offset(self.tx_offset, self.x, self.y)
        object.__setattr__(self, "tx_offset", offset)
        if offset is not None:
            object.__setattr__(self, "monostatic", True)
        if self.pose is None:
            object.__setattr__(self, "pose", IDENTITY)
        if not isinstance(self.pose, Pose):
            raise ValueError(f"pose must be a holoradar.Pose, got {type(self.pose).__name__}")
        object.__setattr__(self, "x", as_axis(self.x, "x"))
        object.__setattr__(self, "y", as_axis(self.y, "y"))
        if self.elements is not None:
            try:
                el = np.array(self.elements, dtype=float)
            except (TypeError, ValueError):
                el = np.empty((0, 0))
            if el.ndim != 2 or el.shape[1] != 2 or el.shape[0] < 1 or not np.all(np.isfinite(el)):
                raise ValueError("elements must be finite positions of shape (N, 2), metres")
            el.setflags(write=False)
            object.__setattr__(self, "elements", el)

    @classmethod
    def from_positions(cls, positions: np.ndarray, *, monostatic: bool = False,
                       pose: Pose | None = None, polarization: Any = None) -> Aperture:
        """Elements at arbitrary positions (N, 2) in the aperture's plane, metres."""
        el = np.asarray(positions, dtype=float)
        if el.ndim != 2 or el.shape[1] != 2:
            raise ValueError(f"positions must have shape (N, 2), got {el.shape}")
        xs, ys = np.unique(el[:, 0]), np.unique(el[:, 1])
        return cls(xs, ys, el, monostatic, pose or IDENTITY, polarization)

    @property
    def is_grid(self) -> bool:
        """True for a grid (``simulate`` returns a Hologram)."""
        return self.elements is None

    @classmethod
    def grid(cls, n: int, pitch: float, *, ny: int | None = None, pitch_y: float | None = None,
             center: tuple[float, float] = (0.0, 0.0), monostatic: bool = False,
             pose: Pose | None = None, polarization: Any = None,
             tx_offset: Any = None) -> Aperture:
        """A regular ``ny x n`` grid centred on ``center``: ``x_i = (i - (n-1)/2)*pitch``.

        ``monostatic=True`` makes it the scan grid of one transceiver; ``pose``
        places and tilts its plane (``center`` is then in the aperture's own
        coordinates; the pose's centre is the world position of their origin);
        ``polarization`` is the recorded field component (world axes);
        ``tx_offset`` a transmitter moving beside the scanned receiver, metres.

        Examples
        --------
        >>> Aperture.grid(24, 0.015, polarization=(0, 1, 0)).polarization.tolist()
        [0.0, 1.0, 0.0]
        """
        for name, v in (("n", n), ("ny", ny)):
            if v is not None and (not float(v).is_integer() or int(v) < 1):
                raise ValueError(f"{name} must be a whole number of elements >= 1, got {v!r}")
        if not pitch > 0 or (pitch_y is not None and not pitch_y > 0):
            raise ValueError(f"pitch must be > 0 m, got {pitch}, {pitch_y}")
        ny = int(n if ny is None else ny)
        py = pitch if pitch_y is None else pitch_y
        x = (np.arange(int(n)) - (int(n) - 1) / 2) * pitch + center[0]
        y = (np.arange(ny) - (ny - 1) / 2) * py + center[1]
        return cls(x, y, monostatic=monostatic, pose=pose or IDENTITY,
                   polarization=polarization, tx_offset=tx_offset)

    @classmethod
    def paper(cls) -> Aperture:
        """The paper's receiver array: 16 x 16 elements at 2.5 cm, 40 cm square."""
        return cls.grid(16, 0.025)

    @property
    def size(self) -> tuple[float, float]:
        """Full widths (A, B) = n * pitch (mean pitch for a non-uniform grid), metres."""
        def width(a: np.ndarray) -> float:
            return float(a.size * (a[-1] - a[0]) / (a.size - 1)) if a.size > 1 else 0.0
        return width(self.x), width(self.y)

    @property
    def points(self) -> np.ndarray:
        """World positions (N, 3) of the elements, metres (on z = 0 for the identity
        pose); row-major over (y, x) for a grid."""
        if self.elements is not None:
            return self.pose.to_world(self.elements[:, 0], self.elements[:, 1])
        return self.pose.grid_points(self.x, self.y).reshape(-1, 3)


@dataclass(frozen=True)
class Scene:
    """What the radar looks at: a medium, an illuminating source and targets.

    Parameters
    ----------
    medium : Medium
        Layered ground (default free space).
    source : PlaneWave, PointSource, GaussianBeam or Dipole
        Illumination (default: a normal plane wave).
    targets : sequence of PointTarget, LineTarget or PlanarTarget
        The scatterers.

    Examples
    --------
    >>> s = Scene(Medium.half_space(0.3, 2.5), targets=[PointTarget((0, 0, 0.4))])
    >>> len(s.targets)
    1
    """

    medium: Medium = field(default_factory=Medium.free_space)
    source: Any = field(default_factory=PlaneWave)
    targets: Sequence[PointTarget | LineTarget | PlanarTarget] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.medium, Medium):
            raise ValueError("medium must be a holoradar.Medium, got "
                             f"{type(self.medium).__name__}")
        if not (hasattr(self.source, "field") and hasattr(self.source, "reflected")):
            raise ValueError("source must be a PlaneWave, PointSource, GaussianBeam or Dipole")
        tg = tuple(self.targets)
        for i, t in enumerate(tg):
            if not isinstance(t, PointTarget | PlanarTarget | LineTarget):
                raise ValueError(f"targets[{i}] must be a PointTarget, LineTarget or "
                                 f"PlanarTarget, got {type(t).__name__}")
        object.__setattr__(self, "targets", tg)
