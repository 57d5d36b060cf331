"""The field a long buried cylinder (rebar, pipe) sends to the elements, and its match.

A horizontal line of length ``L`` at range ``z``, centred on ``(x, y)`` along the
azimuth ``phi``, scatters as a row of induced dipoles (:class:`~holoradar.LineTarget`):
``P(s) = alpha E0(r(s)) ds`` with ``alpha = a_along t t^T + a_across (I - t t^T)``, the
exact 2-D cylinder's polarizabilities per unit length for a given radius
(:func:`~holoradar.model.targets.cylinder_polarizabilities`), one unknown complex
factor for all frequencies. Element ``e`` records, by reciprocity,

    g_e = sum_m w_m (G(r_m <- e) u) . P_m,

over Gauss-Legendre nodes ``s_m`` along the line (enough for its lateral phase: waves
that reach the air change phase by at most ``2 k0`` per metre along it), ``G`` from the
point response's tables of the dyadic's radial functions (the same windows, the same
interpolation), the incident field at the nodes from the source's table. A spectral
route (one FFT per frequency) was tried and dropped: the periodic copies of a line's
slowly decaying (cylindrical) field reach the aperture, 15% of the field with the grid
padded to four apertures.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..data.hologram import Hologram
from ..model.targets import cylinder_polarizabilities
from ..physics.dyadic import dyadic_times
from ..physics.green import legendre
from ..physics.medium import Medium
from .point_response import PointResponse

__all__ = ["LineResponse"]


class LineResponse(PointResponse):
    """Normalised matched filter of a long horizontal cylinder against a hologram.

    ``xy`` in the methods is ``(x, y, azimuth, length)``: the line's centre
    (metres), its direction in radians from +x towards +y, and its length
    (metres). Needs the vector model (a hologram with a ``polarization`` and a
    polarised source) on an untilted grid.

    Parameters
    ----------
    hologram, make_medium, coherent, phase_only
        As :class:`~holoradar.imaging.point_response.PointResponse`.
    radius : float
        The cylinder's radius, metres (its echo comes from its near side: the
        polarizabilities' phase carries it).
    eps_line : complex, optional
        The cylinder's permittivity; ``None`` is a perfect conductor.
    """

    CHUNK_PAIRS = 1_000_000  # (frequency, node, element) triples interpolated per pass
    SOURCE_BAND = 0.5  # the source's table spans the whole line

    def __init__(self, hologram: Hologram, make_medium: Callable[[float], Medium], *,
                 coherent: bool, radius: float, eps_line: complex | None = None,
                 phase_only: bool = False) -> None:
        super().__init__(hologram, make_medium, coherent=coherent, phase_only=phase_only)
        if not self.vector or self.monostatic:
            raise ValueError("target='line' needs the vector model with a separate source: a "
                             "hologram with a polarization (the recorded field component) "
                             "and a polarised source (a Dipole, or a source given a "
                             "polarization)")
        if not (self.flat and hologram.pose.is_identity):
            raise ValueError("target='line' needs an untilted aperture (a tilted one is not "
                             "modelled for lines)")
        self.radius = float(radius)
        self.eps_line = eps_line
        # Nodes reach half a line beyond its centre: tables long enough for the longest.
        self.max_length = 1.5 * float(max(np.ptp(hologram.x), np.ptp(hologram.y)))
        self._rho_max += 0.5 * self.max_length
        if self._point_source:
            self._rho_max_src += 0.5 * self.max_length

    # ---------------------------------------------------------------- pieces
    def _nodes(self, xy: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Gauss-Legendre nodes along the line: positions (M, 2), weights (M,), direction."""
        x, y, phi, length = (float(v) for v in xy)
        length = max(length, 1e-4)
        m = int(np.ceil(length * 2 * float(self.ks.max()) / np.pi * 1.3)) + 6
        s, w = legendre(-(-m // 8) * 8)
        t = np.array([np.cos(phi), np.sin(phi)])
        pos = np.array([x, y]) + 0.5 * length * s[:, None] * t
        return pos, 0.5 * length * np.asarray(w), np.array([t[0], t[1], 0.0])

    # --------------------------------------------------------------- response
    def response(self, eps: float, z: float, xy: Any, *, window: Any = None) -> np.ndarray:
        """``g`` at the elements, (nf, N), for the line ``xy = (x, y, azimuth, length)``."""
        eps, z = float(eps), float(z)
        self.responses += 1
        w = window or self._window(eps, z)
        medium = w.medium
        pos, weights, t = self._nodes(xy)
        E = self._incident_vectors(medium, pos, z, w)                   # (nf, M, 3)
        km = self.ks * np.sqrt(complex(medium.eps[medium.region_of(z)]))
        tt = np.outer(t, t)
        eps_ground = complex(medium.eps[medium.region_of(z)])
        P = np.empty_like(E)
        ref = None
        for i, kmi in enumerate(km):
            along, across = cylinder_polarizabilities(kmi, self.radius, self.eps_line,
                                                      eps_ground)
            if ref is None:
                ref = along if along != 0 else 1.0
            alpha = (along * tt + across * (np.eye(3) - tt)) / ref
            P[i] = (E[i] @ alpha.T) * weights[:, None]
        # G(r_m <- e) u for every node and element, some nodes at a time (memory): the
        # table interpolated to the range once, then along the distances.
        g = np.zeros((len(self.ks), len(self.points)), complex)
        ex, ey = self.points[:, 0], self.points[:, 1]
        row = w.G.row(z)
        chunk = max(1, int(self.CHUNK_PAIRS // (len(self.ks) * len(self.points))))
        for c0 in range(0, len(pos), chunk):
            sl = slice(c0, c0 + chunk)
            off = np.stack([(pos[sl, 0, None] - ex[None, :]).ravel(),
                            (pos[sl, 1, None] - ey[None, :]).ravel()], axis=1)
            v = dyadic_times(off, w.G.along(row, np.hypot(off[:, 0], off[:, 1])), self.pol)
            v = v.reshape(len(self.ks), -1, len(self.points), 3)          # (nf, m, N, 3)
            g += np.einsum("fmni,fmi->fn", v, P[:, sl])
        return g
