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

from .._lazy import lazy_module
from ..data.hologram import Hologram
from ..model.targets import cylinder_polarizabilities
from ..physics.dipole import Dipole
from ..physics.dyadic import dyadic_times
from ..physics.green import legendre
from ..physics.line_green import line_field
from ..physics.medium import Medium
from ..physics.sources import PlaneWave, PointSource
from .point_response import PointResponse, _Grid, require_vector_flat

_sparse = lazy_module("scipy.sparse")

__all__ = ["MAX_LENGTH", "LineRayResponse", "LineResponse", "LineSetResponse"]

#: The longest line fitted, in aperture widths: a bar across the whole aperture (a rebar
#: mat's) still shows its ends' diffraction, so its length is fitted beyond the aperture.
MAX_LENGTH = 2.0


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
        _line_setup(self, hologram, radius, eps_line)
        # Nodes reach half a line beyond its centre: tables long enough for the longest.
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
    def response_once(self, eps: float, z: float, xy: Any) -> np.ndarray:
        """:meth:`response` at one line, its tables as wide as that line needs (four
        ranges, the distances of its nodes from the elements and from the source):
        several times cheaper than a search's window, and kept nowhere."""
        pos, _, _ = self._nodes(xy)
        off = pos[:, None, :] - self.points[None, :, :2]
        rho_max = float(np.sqrt(np.max(np.sum(off * off, axis=-1))))
        dz = self.spacing(eps)
        zs = float(z) + dz * np.arange(-1.0, 3.0)
        saved = (self._rho_max, self.xy_hint, self.SOURCE_BAND)
        try:
            self._rho_max = rho_max + 0.01
            if self._point_source:
                s = self.source.position[:2]
                r = np.hypot(pos[:, 0] - s[0], pos[:, 1] - s[1])
                # The source's table is centred on the hint's distance from the source.
                self.xy_hint = s + np.array([0.5 * (r.min() + r.max()), 0.0])
                self.SOURCE_BAND = 0.5 * float(np.ptp(r)) + 0.01
            return self.response(eps, z, xy, window=self._compute(float(eps), zs))
        finally:
            self._rho_max, self.xy_hint, self.SOURCE_BAND = saved

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
            v = dyadic_times(off, _along(w.G, row, np.hypot(off[:, 0], off[:, 1])), self.pol)
            v = v.reshape(len(self.ks), -1, len(self.points), 3)          # (nf, m, N, 3)
            g += np.einsum("fmni,fmi->fn", v, P[:, sl])
        return g


def _along(G: Any, row: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """The table's radial functions at distances ``rho``, (nf, 5, len(rho)): the point
    response's 4-point Lagrange interpolation along a :meth:`row` (the same weights, the
    same result), as one sparse matrix (distances x columns, four weights a row) times
    the row's columns: nine times faster than four gathers of whole columns."""
    v = (np.asarray(rho, float) - G.r0) / G.dr
    ir = np.clip(np.floor(v).astype(int), 1, G.nr - 3)
    wr = _Grid._weights(v - ir)                                       # (P, 4)
    n, P = row.shape[-1], rho.size
    W = _sparse.csr_matrix((wr.ravel(), (ir[:, None] - 1 + np.arange(4)).ravel(),
                            np.arange(0, 4 * P + 1, 4)), shape=(P, n))
    vals = (W @ np.ascontiguousarray(row.reshape(-1, n).T)).T.reshape(*row.shape[:2], P)
    return vals[:, :5] * np.exp(1j * vals[:, 5].real)[:, None, :]


def _line_setup(pr: Any, hologram: Hologram, radius: float, eps_line: Any) -> None:
    """What both line models set up: the model's checks, the cylinder, the longest line
    (:data:`MAX_LENGTH` aperture widths)."""
    _check_line_model(pr, hologram)
    pr.radius = float(radius)
    pr.eps_line = eps_line
    pr.max_length = MAX_LENGTH * float(max(np.ptp(hologram.x), np.ptp(hologram.y)))


def _check_line_model(pr: PointResponse, hologram: Hologram) -> None:
    """What both line models need: the vector model, a separate source, a flat grid."""
    require_vector_flat(pr, hologram, "line", transceiver=False)


def polarizabilities(ks: np.ndarray, eps_ground: complex, radius: float,
                     eps_line: complex | None) -> tuple[np.ndarray, np.ndarray]:
    """A cylinder's polarizabilities along and across its axis at each frequency, both
    divided by the first frequency's along-axis one (the one unknown factor's scale).

    Parameters
    ----------
    ks : ndarray
        Air wavenumbers, rad/m.
    eps_ground : complex
        The permittivity around the cylinder.
    radius : float
        Metres.
    eps_line : complex or None
        The cylinder's permittivity; ``None`` a perfect conductor.
    """
    km = np.asarray(ks, float) * np.sqrt(complex(eps_ground))
    ab = np.array([cylinder_polarizabilities(k, radius, eps_line, eps_ground) for k in km])
    ref = ab[0, 0] if ab[0, 0] != 0 else 1.0
    return ab[:, 0] / ref, ab[:, 1] / ref


class LineRayResponse(PointResponse):
    """The matched filter of a long cylinder with its asymptotic field: the search's model.

    The field of :class:`LineResponse`'s row of induced dipoles, evaluated by rays
    through the layers and stationary phase along the line
    (:func:`~holoradar.physics.line_green.line_field`): one ray pair per element instead
    of one per node and element, and no Sommerfeld tables, so a trial line costs about
    elements x frequencies. ``xy`` as in :class:`LineResponse`; the same normalisation,
    so the two models' holograms can be compared directly.

    Parameters
    ----------
    hologram, make_medium, coherent, radius, eps_line, phase_only
        As :class:`LineResponse`. The source must be a :class:`~holoradar.Dipole`, a
        :class:`~holoradar.PointSource` with a ``polarization`` or a polarised
        :class:`~holoradar.PlaneWave`.
    """

    def __init__(self, hologram: Hologram, make_medium: Callable[[float], Medium], *,
                 coherent: bool, radius: float, eps_line: complex | None = None,
                 phase_only: bool = False) -> None:
        super().__init__(hologram, make_medium, coherent=coherent, phase_only=phase_only)
        _line_setup(self, hologram, radius, eps_line)
        self._source = ray_source(hologram.source)
        self._grounds: dict[float, tuple[Medium, dict, dict]] = {}
        self.correction: np.ndarray | None = None   # (nf, N) factors, see correct_to

    def correct_to(self, exact: LineResponse, eps: float, z: float, xy: Any) -> None:
        """Multiply the model from now on by ``exact``'s response over this one's at the
        line ``(eps, z, xy)``, one complex factor per element and frequency: there it
        becomes the exact model. Samples where this model is weak (below a hundredth of
        its rms at that frequency) are damped towards no correction (a regularised
        ratio), so a near-null of the asymptotic field cannot blow up."""
        g_exact = exact.response_once(eps, z, xy)
        self.correction = None
        g = self.response(eps, z, xy)
        power = np.abs(g) ** 2
        floor = 1e-4 * power.mean(axis=1, keepdims=True)
        self.correction = g_exact * g.conj() / (power + floor)
        self.integrals += exact.integrals

    def _ground(self, eps: float) -> tuple[Medium, dict, dict]:
        """The medium at ``eps``, its rays (by ranges) and polarizabilities (by region)."""
        if eps not in self._grounds:
            if len(self._grounds) > 64:
                self._grounds.pop(next(iter(self._grounds)))
            self._grounds[eps] = (self.make_medium(eps), {}, {})
        return self._grounds[eps]

    def response(self, eps: float, z: float, xy: Any, *, window: Any = None) -> np.ndarray:
        """``g`` at the elements, (nf, N), for the line ``xy = (x, y, azimuth, length)``."""
        eps, z = float(eps), float(z)
        self.responses += 1
        medium, fans, alphas = self._ground(eps)
        region = int(medium.region_of(z))
        if region not in alphas:
            alphas[region] = polarizabilities(self.ks, medium.eps[region], self.radius,
                                              self.eps_line)
        x, y, phi, length = (float(v) for v in xy)
        g = line_field(self.ks, medium, z, self.points, self.pol, np.array([x, y]), phi,
                       max(length, 1e-4), alphas[region], self._source, fans)
        return g if self.correction is None else g * self.correction

    def scan(self, eps: float, z_lo: float, z_hi: float, xy: Any, *, samples: int = 24,
             coherent: bool | None = None) -> tuple[float, float]:
        """Range in [z_lo, z_hi] with the best focus at ``xy``, and that focus fraction:
        sampled at :meth:`spacing`, or in ``samples`` steps when that is coarser."""
        n = int(np.ceil((z_hi - z_lo) / self.spacing(eps)))
        zs = np.linspace(z_lo, z_hi, int(np.clip(n + 1, 2, samples)))
        F = [self.match(self.response(eps, z, xy), coherent=coherent)[0] for z in zs]
        i = int(np.argmax(F))
        return float(zs[i]), float(F[i])


def ray_source(source: Any) -> dict:
    """The source as :func:`~holoradar.physics.line_green.line_field` takes it; a
    ValueError for a source it has no ray model of."""
    if isinstance(source, Dipole):
        return dict(kind="point", position=source.position,
                    moment=source.amplitude * np.asarray(source.moment, complex), pattern=None)
    if isinstance(source, PointSource) and source.polarization is not None:
        pattern = source.pattern if source.pattern_exponent else None
        return dict(kind="point", position=source.position, pattern=pattern,
                    moment=source.amplitude * np.asarray(source.polarization, complex))
    if isinstance(source, PlaneWave) and source.polarization is not None:
        return dict(kind="plane", slowness=np.array([np.sin(source.alpha), np.sin(source.beta)]),
                    polarization=np.asarray(source.polarization, complex))
    raise ValueError(f"the line's ray model takes a Dipole, a polarised PointSource or a "
                     f"polarised PlaneWave, got {type(source).__name__}")


class LineSetResponse(PointResponse):
    """Several lines fitted together (a rebar mat): one line varied at a time.

    ``response(eps, z, xy)`` is the ``active`` line's field plus every other line's at
    the parameters held for that eps' (:attr:`held`), each line with its own complex
    amplitude fitted to the data (one per line, or per line and frequency when not
    ``coherent``), scaled so that the active line's amplitude is the one
    :meth:`match` fits: the focus fraction is then the share of the data all the lines
    explain together, and the residual theirs.

    Parameters
    ----------
    hologram : Hologram
    models : list of LineRayResponse
        One model per line, on ``hologram`` (each with its own correction).
    coherent, phase_only
        As :class:`~holoradar.imaging.point_response.PointResponse`.

    Attributes
    ----------
    held : dict
        eps' -> list of ``(z, xy)`` per line (range in metres, ``(x, y, azimuth,
        length)``); an eps' not held takes the nearest one's.
    active : int
        The line :meth:`response` varies.
    """

    def __init__(self, hologram: Hologram, models: list[LineRayResponse], *, coherent: bool,
                 phase_only: bool = False) -> None:
        super().__init__(hologram, models[0].make_medium, coherent=coherent,
                         phase_only=phase_only)
        self.models = models
        self.max_length = models[0].max_length
        self.held: dict[float, list[tuple[float, np.ndarray]]] = {}
        self.active = 0
        self._fields: dict[tuple, np.ndarray] = {}
        self._others_key: tuple | None = None
        self._others: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def lines_at(self, eps: float) -> list[tuple[float, np.ndarray]]:
        """Every line's ``(z, xy)`` held at ``eps`` (or the nearest eps' held)."""
        if eps in self.held:
            return self.held[eps]
        return self.held[min(self.held, key=lambda e: abs(np.log(e / eps)))]

    def _field(self, j: int, eps: float, z: float, xy: np.ndarray) -> np.ndarray:
        key = (j, float(eps), float(z), *np.asarray(xy, float).tolist())
        if key not in self._fields:
            if len(self._fields) > 256:
                self._fields.pop(next(iter(self._fields)))
            self._fields[key] = self.models[j].response(eps, z, xy)
        return self._fields[key]

    def _held(self, eps: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The other lines' fields at ``eps`` (K - 1, nf, N), their Gram matrix and their
        products with the data (per frequency), kept while the held lines stay."""
        lines = self.lines_at(eps)
        key = (float(eps), self.active, *(float(v) for j, (z, xy) in enumerate(lines)
                                          if j != self.active for v in (z, *xy)))
        if self._others_key != key:
            others = [self._field(j, eps, *lines[j]) for j in range(len(lines))
                      if j != self.active]
            if not others:
                self._others = None
            else:
                fields = np.stack(others)
                self._others = (fields, np.einsum("jfn,kfn->fjk", fields.conj(), fields),
                                np.einsum("jfn,fn->fj", fields.conj(), self.h))
            self._others_key = key
        return self._others

    def response(self, eps: float, z: float, xy: Any, *, window: Any = None) -> np.ndarray:
        """The active line's ``g`` (nf, N) with the others' fields, each line's amplitude
        fitted, in the active line's units."""
        self.responses += 1
        g = self.models[self.active].response(eps, z, xy)
        held = self._held(eps)
        if held is None:
            return g
        fields, gram_o, rhs_o = held
        k = len(fields) + 1
        # The amplitudes by the normal equations (K x K: the lines lie apart, the Gram
        # matrix is well conditioned; a 1e-12 ridge keeps a vanishing line finite).
        g_o = np.einsum("fn,kfn->fk", g.conj(), fields)
        gram = np.empty((len(g), k, k), complex)
        gram[:, 0, 0] = np.einsum("fn,fn->f", g.conj(), g)
        gram[:, 0, 1:] = g_o
        gram[:, 1:, 0] = g_o.conj()
        gram[:, 1:, 1:] = gram_o
        rhs = np.concatenate([np.einsum("fn,fn->f", g.conj(), self.h)[:, None], rhs_o], axis=1)
        if self.coherent:
            gram, rhs = gram.sum(axis=0)[None], rhs.sum(axis=0)[None]
        ridge = 1e-12 * np.trace(gram, axis1=1, axis2=2).real[:, None, None]
        b = np.linalg.solve(gram + ridge * np.eye(k), rhs[..., None])[..., 0]
        b = np.broadcast_to(b, (len(g), k))
        lead = np.where(np.abs(b[:, 0]) > 0, b[:, 0], 1.0)
        return g + np.einsum("fk,kfn->fn", b[:, 1:] / lead[:, None], fields)

    scan = LineRayResponse.scan
