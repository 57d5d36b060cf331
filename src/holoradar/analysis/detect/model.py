"""The image of a point from the hologram: exact responses, fitted positions.

With the hologram that made the image, a point (found in the inverted
reflectivity by ``detect``, or at the image's brightest pixel by
``unbiased_peak``) is refined as a point scatterer fitted to the hologram: its
exact field at the elements ``g(r)`` (the layered Green's function times the
source's incident field, :class:`~holoradar.imaging.point_response.PointResponse`,
the model ``autofocus`` fits), its position ``r`` the maximum of the normalised matched filter

    F(r) = |<h_res, g(r)>|^2 / (||g(r)||^2 ||h_res||^2)

on the residual hologram ``h_res`` (the hologram less the objects found). Unlike
the image's amplitude maximum, this is the maximum-likelihood position of one
point in white noise: it has no pull towards the array (the adjoint's ``1/r``
weighting and the long focus of one frequency do not enter). Each point fitted is
subtracted from the residual hologram before the next, and all are refitted
together at the end. The image is checked to be the hologram's migration on a
few planes, with the migration frozen on the original hologram (its frequency
weights and the loss compensation's SNR).

Position uncertainty: the Cramer-Rao bound of the fit, ``Cov = J^-1`` with
``J = (2 |a|^2 / s^2) Re[D^H P D]``, ``D`` the derivatives of ``g`` along x, y, z,
``P`` the projection orthogonal to ``g`` (the amplitude is fitted too) and ``s^2``
the noise variance per element, estimated from the final residual hologram
(anything the models leave counts as noise: the bound is then conservative).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.optimize import minimize

from ...data.hologram import Hologram
from ...imaging.migration.image import Migration
from ...imaging.migration.settings import MigrationSettings
from ...imaging.point_response import PointResponse
from ...physics.medium import Medium
from .errors import HologramFitError
from .grid import Volume

__all__ = ["CHECK_PLANES", "HologramModel"]

CHECK_PLANES = 5
"""Planes of a volume on which the image is checked to be the hologram's migration."""

SEARCH_TOL = 0.01
"""Nelder-Mead's position tolerance, in resolution cells (Gauss-Newton goes on)."""

POLISH_STEPS = 8
"""Gauss-Newton steps at most."""

STOP_STD = 0.1
"""Gauss-Newton stops once a step is below this fraction of the position's standard
deviation along every axis."""

DIFF_STEP = 1e-5
"""Central-difference step of the point response's derivatives, metres."""


class HologramModel:
    """Point responses fitted to the hologram behind an image.

    Parameters
    ----------
    hologram : Hologram
        One frame (one or several frequencies) on a level aperture (identity pose).
    volume : Volume
        The image: ``migrate(hologram, z, medium=medium, upsample=u, **options)``.
    medium : Medium, optional
        The ground the image was formed through (None: free space).
    options : dict, optional
        Further keyword arguments the image was migrated with.
    """

    def __init__(self, hologram: Hologram, volume: Volume, medium: Medium | None,
                 options: dict[str, Any] | None = None) -> None:
        if not isinstance(hologram, Hologram):
            raise HologramFitError("hologram must be a holoradar.Hologram, got "
                                   f"{type(hologram).__name__}", "type")
        shape = hologram.data.shape
        if len(shape) != (3 if hologram.is_wideband else 2):
            raise HologramFitError("hologram must hold one frame (ny, nx) or (nf, ny, nx); got "
                                   f"shape {shape}: select the frame the image was made from",
                                   "frames")
        if not np.allclose(hologram.points[:, 2], 0.0) or hologram.pose.normal[2] < 1 - 1e-12:
            raise HologramFitError("hologram must lie on a level aperture at z = 0 (identity "
                                   "pose) for detect's point fit; tilted arrays are not "
                                   "supported yet", "tilted")
        dx = hologram.pitch[0]
        u = round(dx / volume.dx)
        expect_x = hologram.x[0] + np.arange(u * (hologram.x.size - 1) + 1) * dx / u
        if u < 1 or expect_x.size != volume.x.size or not np.allclose(expect_x, volume.x,
                                                                      atol=1e-9 + 1e-6 * dx):
            raise HologramFitError(
                "hologram does not match image: the image's x grid ("
                f"{volume.x.size} pixels, {volume.x[0]:.4g} .. {volume.x[-1]:.4g} m) is not "
                f"the hologram's {hologram.x.size} elements ({hologram.x[0]:.4g} .. "
                f"{hologram.x[-1]:.4g} m) at a whole upsampling (migrate(..., upsample=u), "
                "fov='aperture')", "grid")
        dy = hologram.pitch[1]
        expect_y = hologram.y[0] + np.arange(u * (hologram.y.size - 1) + 1) * dy / u
        if expect_y.size != volume.y.size or not np.allclose(expect_y, volume.y,
                                                             atol=1e-9 + 1e-6 * dy):
            raise HologramFitError(
                "hologram does not match image: the image's y grid ("
                f"{volume.y.size} pixels, {volume.y[0]:.4g} .. {volume.y[-1]:.4g} m) is not "
                f"the hologram's {hologram.y.size} elements ({hologram.y[0]:.4g} .. "
                f"{hologram.y[-1]:.4g} m) upsampled {u}x as along x", "grid")
        self.hologram = hologram
        self.vol = volume
        self.medium = medium
        opts = dict(options or {})
        opts.setdefault("upsample", u)
        self.options = opts
        self.migration = _frozen(hologram, volume, medium, opts)
        self._subsets: dict[tuple[int, ...], Migration] = {}
        self.eps = {}
        # Free space as a "ground" of eps 1 + 1e-6 from half the image's first range (eps
        # exactly 1 puts a quadrature node on the Green integral's branch point; the
        # difference is a phase of 5e-7 k z, 5e-5 rad at 50 cm; an interface close to
        # the aperture would make the integrals slow).
        pr_medium = medium if medium is not None and not medium.is_free_space else \
            Medium.half_space(0.5 * float(volume.z[0]), 1.0 + 1e-6)
        self.z_min = pr_medium.z_interfaces[0]
        coherent = bool(hologram.monostatic or hologram.source is not None)
        self.pr = PointResponse(hologram, lambda e: pr_medium, coherent=coherent)
        self.pr_medium = pr_medium
        self.h = hologram.data.reshape(hologram.nf, -1).astype(complex)
        self.res = self.h.copy()
        self.objects: list[dict[str, Any]] = []

    # ------------------------------------------------------------------ images
    def image(self, data: np.ndarray, planes: np.ndarray | None = None) -> np.ndarray:
        """The migration of hologram data (nf, N) with the image's settings, (nz, ny, nx)
        (``planes``: only those plane indices, (len(planes), ny, nx)).

        The migration operator frozen on the original hologram (its frequency weights
        and the loss compensation's SNR), so that the image of a residual is the
        residual image: linear in the data."""
        d = data.reshape(self.hologram.data.shape)
        m = self.migration
        if planes is not None and not self.vol.planar:
            key = tuple(int(i) for i in planes)
            if key not in self._subsets:
                self._subsets[key] = Migration(self.hologram, self.vol.z[list(key)],
                                               self.medium, m.settings)
            m = self._subsets[key]
        out = m.adjoint(d)
        return out[None] if self.vol.planar else out

    def check_planes(self) -> np.ndarray:
        """Plane indices on which :meth:`start` checks the image: up to
        :data:`CHECK_PLANES` evenly spaced ones, the deepest included (it sets
        ``migrate``'s padded grid; even spacing keeps its choice of algorithm)."""
        nz = self.vol.z.size
        step = max(1, (nz - 1) // (CHECK_PLANES - 1))
        idx = nz - 1 - step * np.arange(CHECK_PLANES)
        return np.sort(idx[idx >= 0])

    def start(self) -> np.ndarray:
        """The residual image to begin with, checked against the image given.

        The check migrates the hologram onto a few of the image's planes
        (:meth:`check_planes`): each plane of a migration is computed on its own, so
        those planes equal the whole volume's, and a different hologram or other
        settings (method, weights, padding, loss compensation, dtype) change every
        plane. A whole migration would double ``detect``'s time for no more
        evidence.
        """
        planes = self.check_planes()
        img = self.image(self.res, planes)
        scale = float(np.max(np.abs(self.vol.data))) or 1.0
        ref = self.vol.data if self.vol.planar else self.vol.data[planes]
        err = float(np.max(np.abs(img - ref))) / scale
        if not err < 1e-5:
            raise HologramFitError("hologram does not match image: the image is not "
                                   "migrate(hologram, image.z, medium=medium, upsample="
                                   f"{self.options['upsample']}) (they differ by {err:.2g} of "
                                   "the peak: another source, data, ground or option); pass "
                                   "the migration's other options as migrate_options={...}, "
                                   "or leave hologram out", "mismatch", err)
        return self.vol.data.copy()

    # ----------------------------------------------------------------- the fit
    def _eps_at(self, z: float) -> float:
        m = self.pr_medium
        return float(np.real(m.eps[int(m.region_of(z))]))

    def response(self, r: np.ndarray) -> np.ndarray:
        """``g`` at the elements (nf, N) for a unit point at ``r = (x, y, z)``."""
        return self.pr.response(self._eps_at(float(r[2])), float(r[2]), (float(r[0]),
                                                                         float(r[1])))

    def focus(self, r: np.ndarray, h: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        """``F``, the fitted amplitude(s) and ``g`` at ``r`` against hologram data ``h``."""
        g = self.response(r)
        c = np.einsum("fe,fe->f", g.conj(), h)
        n = np.einsum("fe,fe->f", g.conj(), g).real
        if self.pr.coherent:
            a = np.full(len(c), c.sum() / n.sum())
            F = abs(c.sum()) ** 2 / n.sum()
        else:
            a = c / n
            F = float(np.sum(np.abs(c) ** 2 / n))
        return float(F), a, g

    def fit_position(self, start: tuple[float, float, float], h: np.ndarray,
                     cell: tuple[float, float], *, search: bool = True) -> np.ndarray:
        """The maximum of ``F`` near ``start``.

        Nelder-Mead from ``start`` finds the peak of ``F`` (its simplex spans a
        quarter of a cell: the image's peak may lie that far off the fit's), to a
        hundredth of a cell; Gauss-Newton steps then go to the maximum itself
        (:meth:`polish`). ``search=False``: the Gauss-Newton steps only (a start
        already at the maximum, e.g. a refit once the other objects are
        subtracted).
        """
        lo = self.z_min + 1e-4
        x0 = np.array([start[0], start[1], max(start[2], lo + 1e-3)])
        if search:
            steps = np.array([cell[0] / 4, cell[1] / 4, max(cell[0], cell[1]) / 2])
            e_h = self.energy(h)

            def cost(v: np.ndarray) -> float:
                if v[2] <= lo:
                    return 1e3 + (lo - v[2])
                return -self.focus(v, h)[0] / e_h

            simplex = np.vstack([x0] + [x0 + np.diag(steps)[i] for i in range(3)])
            tol = SEARCH_TOL * min(cell)
            res = minimize(cost, x0, method="Nelder-Mead",
                           options={"initial_simplex": simplex, "xatol": tol,
                                    "fatol": np.inf, "maxiter": 400})
            x0 = np.asarray(res.x, float)
        return self.polish(x0, h, lo)

    def _derivatives(self, r: np.ndarray) -> np.ndarray:
        """``dg/dr`` along x, y, z at ``r`` by central differences, (3, nf, N)."""
        out = []
        for j in range(3):
            e = np.zeros(3)
            e[j] = DIFF_STEP
            out.append((self.response(r + e) - self.response(r - e)) / (2 * DIFF_STEP))
        return np.array(out)

    def _normal(self, r: np.ndarray, a: np.ndarray, g: np.ndarray, h: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, float]:
        """Gauss-Newton's ``J = Re(M^H P M)``, ``b = Re(M^H e)`` and the noise per
        element ``s^2`` at ``r`` (``M = a dg/dr``, ``P`` the projection orthogonal to
        the amplitude's model, ``e = h - a g``)."""
        M = self._derivatives(r) * a[None, :, None]                # (3, nf, N)
        m = a[:, None] * g
        e = h - m
        if self.pr.coherent:
            mm = m.ravel()
            Mf = M.reshape(3, -1)
            Mf = Mf - np.outer(Mf @ mm.conj(), mm) / np.vdot(mm, mm).real
        else:
            nrm = np.einsum("fe,fe->f", m.conj(), m).real
            proj = np.einsum("jfe,fe->jf", M, m.conj()) / np.where(nrm > 0, nrm, np.inf)
            Mf = (M - proj[:, :, None] * m[None]).reshape(3, -1)
        J = (Mf.conj() @ Mf.T).real
        b = (Mf.conj() @ e.ravel()).real
        k = 4 * (1 if self.pr.coherent else h.shape[0])
        s2 = float(np.vdot(e, e).real) / max(h.size - k, 1)
        return J, b, s2

    def polish(self, r: np.ndarray, h: np.ndarray, lo: float) -> np.ndarray:
        """Gauss-Newton steps to the maximum of ``F`` from ``r`` near it.

        Each step solves the linearised least squares ``J delta = b`` (the
        Cramer-Rao bound's information ``J``, :meth:`uncertainty`), halved until
        ``F`` does not fall; the steps stop once smaller than a tenth of the
        position's standard deviation ``sqrt(s^2/2 diag J^-1)`` along every axis
        (:data:`STOP_STD`): what is left is a hundredth of its variance.
        """
        F, a, g = self.focus(r, h)
        for _ in range(POLISH_STEPS):
            J, b, s2 = self._normal(r, a, g, h)
            try:
                delta = np.linalg.solve(J, b)
                std = np.sqrt(np.maximum(0.5 * s2 * np.diag(np.linalg.inv(J)), 0.0))
            except np.linalg.LinAlgError:
                break
            if not np.all(np.isfinite(delta)):
                break
            step = 1.0
            while step >= 1 / 16:
                rn = r + step * delta
                if rn[2] > lo:
                    Fn, an, gn = self.focus(rn, h)
                    if Fn >= F:
                        break
                step /= 2
            else:
                break
            r, F, a, g = rn, Fn, an, gn
            if np.all(np.abs(step * delta) <= STOP_STD * std):
                break
        return r

    @staticmethod
    def energy(h: np.ndarray) -> float:
        return float(np.vdot(h, h).real) or 1.0

    def add_point(self, start: tuple[float, float, float]) -> np.ndarray:
        """Fit one point from ``start`` (x, y, range; m) to the residual hologram, add it
        to :attr:`objects` and subtract its response from the residual; its position."""
        r = self.fit_position(start, self.res, self._cell(start[2]))
        _, a, g = self.focus(r, self.res)
        self.res = self.res - a[:, None] * g
        self.objects.append({"r": r, "a": a, "g": g})
        return r

    def _cell(self, z: float) -> tuple[float, float]:
        """Lateral resolution lambda L / A at range z (the starting simplex's scale)."""
        lam = 2 * np.pi / float(self.pr.ks.max())
        L = self.pr_medium.apparent_distance(max(z, self.z_min))
        A, B = self.hologram.aperture_size
        return lam * L / A, lam * L / B

    # ------------------------------------------------------------ refinement
    def refine(self) -> None:
        """Refit every object's position on the hologram less all the others."""
        for i, ob in enumerate(self.objects):
            h_i = self.res + ob["a"][:, None] * ob["g"]
            r = self.fit_position(tuple(ob["r"]), h_i, self._cell(float(ob["r"][2])),
                                  search=False)
            _, a, g = self.focus(r, h_i)
            self.res = h_i - a[:, None] * g
            self.objects[i] = {"r": r, "a": a, "g": g}

    def uncertainty(self) -> list[np.ndarray]:
        """Standard deviations (x, y, z) of every object's position, metres (Cramer-Rao)."""
        n = self.res.size
        k = 4 * len(self.objects) * (1 if self.pr.coherent else self.res.shape[0])
        s2 = float(np.vdot(self.res, self.res).real) / max(n - k, 1)
        out = []
        for ob in self.objects:
            r, a, g = ob["r"], ob["a"], ob["g"]
            step = 1e-4
            D = []
            for j in range(3):
                e = np.zeros(3)
                e[j] = step
                D.append(((self.response(r + e) - self.response(r - e)) / (2 * step)).ravel())
            D = np.array(D).T * np.repeat(a, g.shape[1])[:, None]       # (nf N, 3)
            m = (a[:, None] * g).ravel()
            D = D - np.outer(m, m.conj() @ D) / np.vdot(m, m).real      # orthogonal to m
            J = 2 / s2 * (D.conj().T @ D).real
            try:
                cov = np.linalg.inv(J)
                out.append(np.sqrt(np.maximum(np.diag(cov), 0)))
            except np.linalg.LinAlgError:
                out.append(np.full(3, np.nan))
        return out


def _frozen(hologram: Hologram, volume: Volume, medium: Medium | None,
            options: dict[str, Any]) -> Migration:
    """The image's migration with its data-derived settings fixed to the original
    hologram's: the frequency weights (``equalize=True``: the residual's would differ)
    and the loss compensation's SNR."""
    z = volume.z if not volume.planar else float(volume.z[0])
    first = Migration(hologram, z, medium, MigrationSettings.of(**options))
    plan = first.plan
    fixed: dict[str, Any] = {}
    if hologram.is_wideband:
        fixed["equalize"] = tuple(float(w) for w in plan.weights)
    if plan.compensates:
        fixed["snr_db"] = plan.snr_db
    return Migration(hologram, z, medium, first.settings.replace(**fixed)) if fixed else first
