"""The migration operator as a ``scipy.sparse.linalg.LinearOperator``.

``A = migration_operator(hologram, z, medium=...)`` maps a reflectivity ``r`` on the
image grid (planes ``z``, the image's pixels) to the hologram's samples,

    h_f = w_f sum_z U_f(z) [ psi_f(., z) r(., z) ],

``U_f(z)`` the exact propagation from plane z to the aperture through the layers
(the round trip for a scanned transceiver), ``psi_f`` the source's incident field
(``illumination``), ``w_f`` the frequency weights: the Kirchhoff/Born model of a
reflecting plane in :func:`holoradar.simulate` (its planar targets). ``A.H`` is its
exact adjoint: with ``migrate``'s settings (``compensate_loss=True``,
``equalize=True``, ``illumination=None``) ``A.H @ h`` is ``migrate(h, z)``. scipy's
``lsqr``, ``lsmr`` and ``cg`` take ``A`` as it is, PyLops's solvers through
``pylops.aslinearoperator(A)``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.sparse.linalg import LinearOperator

from ...data.hologram import Hologram, Image
from ...data.samples import SampledHologram
from .backends.base import Backend
from .choose import choose
from .plan import MigrationPlan, make_plan, without_data
from .sampling import decimate, fine_hologram, oversampling, zero_insert
from .settings import MigrationSettings, preset_options

__all__ = ["MigrationOperator", "migration_operator"]

#: What the operator models unless told otherwise: the physics, not migrate's filter.


def migration_operator(hologram: Hologram, z: Any, *, medium: Any = None,
                       settings: MigrationSettings | None = None, sampling: str = "auto",
                       preset: str = "forward", **options: Any) -> MigrationOperator:
    """The linear map from a reflectivity on the image grid to ``hologram``'s samples.

    Parameters
    ----------
    hologram : Hologram
        The measurement's geometry: grid, frequencies, source, pose, polarisation,
        transceiver or receiver array (its data set the weights ``equalize=True``
        and the SNR of the loss compensation, once; otherwise they are not used).
    z : float or sequence of float
        Ranges of the image planes, metres (``frame="ground"``: world ranges).
    medium : Medium, optional
        The layered ground (None: free space).
    settings : MigrationSettings, optional
        All options at once (``options`` then replace some of its fields).
    sampling : {"auto", "band", "array"}
        How the field meets the elements. ``"band"``: the field inside the hologram's
        Nyquist band ``|k| < pi / pitch`` (band-limited; ``migrate``'s adjoint).
        ``"array"``: the field computed on a grid ``u`` times finer than the pitch
        (``pitch / u`` at most half the shortest wavelength, a transceiver's
        ``lambda / 4``) and sampled at the elements, the aliasing of an undersampled
        array included; the image's pixels are then at most ``pitch / u``.
        ``"auto"``: ``"array"`` for ``scatterer="point"`` on an undersampled array in
        its own frame, else ``"band"``. The ground frame always samples the elements
        exactly.
    **options
        :func:`holoradar.migrate`'s options (``method``, ``pad``, ``upsample``,
        ``fov``, ``frame``, ``x``, ``y``, ``dtype``, ``combine`` ("coherent" or "none"),
        ``algorithm``, ``snr_db``), and ``illumination`` ("field", "phase" or
        "none"), ``compensate_loss``, ``equalize``, over the ``preset``'s.
    preset : {"forward", "imaging", "inversion"}
        The defaults the options replace (one table for every part that images):
        ``"forward"`` (default) the physics a hologram holds:
        ``illumination="field"`` (the source's incident field), no loss
        compensation, unit frequency weights; ``"imaging"`` :func:`holoradar.migrate`'s
        own, so that ``A.H @ h`` is ``migrate``'s image; ``"inversion"`` the forward
        model with point scatterers (:func:`holoradar.invert`'s). Ignored where
        ``settings`` is given (they are complete).

    Returns
    -------
    MigrationOperator
        Shape ``(hologram samples, image voxels)``; ``.image_shape``, ``.coords``,
        ``.to_image(vector)``.

    Raises
    ------
    ValueError
        A bad option, a grid the chosen backend cannot represent (e.g.
        ``algorithm="kspace"`` on non-uniform planes), ``combine="incoherent"``
        (not linear).

    Examples
    --------
    >>> import numpy as np, holoradar as hr
    >>> scene = hr.Scene(targets=[hr.PointTarget((0.0, 0.0, 0.3))], source=hr.PlaneWave())
    >>> h = hr.simulate(scene, hr.Aperture.grid(16, 0.01), 9.9e9)
    >>> A = hr.migration_operator(h, [0.25, 0.3])
    >>> A.shape, A.image_shape
    ((256, 512), (2, 16, 16))
    >>> rng = np.random.default_rng(0)
    >>> r = rng.standard_normal(512) + 1j * rng.standard_normal(512)
    >>> d = rng.standard_normal(256) + 1j * rng.standard_normal(256)
    >>> bool(np.isclose(np.vdot(A @ r, d), np.vdot(r, A.H @ d), rtol=1e-12))
    True
    """
    if isinstance(hologram, SampledHologram):   # scattered samples: imaging/samples.py
        return _of_samples(hologram, z, medium, settings, sampling, preset, options)
    given = dict(options)
    if settings is None:
        given = {**preset_options(preset), **given}
    s = MigrationSettings.of(settings, **given)
    if s.combine == "incoherent":
        raise ValueError("combine='incoherent' is not linear (the root sum of squares of "
                         "the frequencies' images): give combine='coherent' or 'none'")
    if sampling not in ("auto", "band", "array"):
        raise ValueError(f"sampling must be 'auto', 'band' or 'array', got {sampling!r}")
    u = oversampling(hologram) if s.frame == "aperture" and isinstance(hologram, Hologram) \
        else 1
    if sampling == "band" or (sampling == "auto" and s.scatterer != "point") \
            or getattr(hologram, "tx_offset", None) is not None:
        u = 1   # (the two-leg kernel samples the elements exactly: offset.py)
    if u > 1:
        if s.compensate_loss:
            raise ValueError("sampling='array' models the field, not migrate's filter: give "
                             "compensate_loss=False (or sampling='band')")
        s = s.replace(upsample=max(1, round(s.upsample / u)))
        plan = make_plan(fine_hologram(hologram, u), z, medium, s)
    else:
        plan = make_plan(hologram, z, medium, s)
    plan.snr_db  # noqa: B018  (estimated now, from the data given: the map is then fixed)
    return MigrationOperator(plan, choose(plan, repeated=True),
                             sampled=(u, without_data(hologram)))


class MigrationOperator(LinearOperator):
    """One geometry's migration operator (:func:`migration_operator` makes it).

    Parameters
    ----------
    plan : MigrationPlan
        The geometry and settings, fixed.
    backend : Backend
        What computes it.
    sampled : (int, Hologram), optional
        ``(u, geometry)``: the plan is ``u`` times finer than the hologram ``geometry``,
        whose elements are every ``u``-th of its samples (``sampling="array"``).

    Attributes
    ----------
    plan : MigrationPlan
    backend : Backend
    image_shape : tuple of int
        ``(nz, ny', nx')``, or ``(nf, nz, ny', nx')`` with ``combine="none"``.
    data_shape : tuple of int
        One frame's samples: ``(nf, ny, nx)`` for a band, ``(ny, nx)`` for one frequency.
    oversampling : int
        ``u``: the field is computed ``u`` times finer than the pitch and sampled at the
        elements (``sampling="array"``; 1: on the hologram's own grid).
    geometry : Hologram
        The hologram's geometry (without its data).
    x, y : ndarray
        The image's pixel coordinates, metres.
    """

    def __init__(self, plan: MigrationPlan, backend: Backend,
                 sampled: tuple[int, Hologram] | None = None) -> None:
        self.plan = plan
        self.backend = backend
        self.oversampling, self.geometry = sampled if sampled else (1, plan.geometry)
        self.x, self.y = backend.axes(plan)
        nz = plan.z.size
        self.image_shape = ((plan.nf,) if plan.separate else ()) + (nz, self.y.size,
                                                                    self.x.size)
        self.data_shape = plan.data_shape[:-2] + self.geometry.data.shape[-2:]
        super().__init__(dtype=plan.work, shape=(math.prod(self.data_shape),
                                                 math.prod(self.image_shape)))

    # ------------------------------------------------------------------ checked entry
    def matvec(self, x: Any) -> np.ndarray:
        """Forward: a reflectivity (``image_shape`` voxels, flat) -> the samples (flat)."""
        return super().matvec(self._checked(x, "x", self.shape[1], self.image_shape))

    def rmatvec(self, x: Any) -> np.ndarray:
        """Adjoint: samples (flat) -> the back-propagated image (flat)."""
        return super().rmatvec(self._checked(x, "x", self.shape[0], self.data_shape))

    def _checked(self, x: Any, name: str, n: int, shape: tuple[int, ...]) -> np.ndarray:
        arr = np.asanyarray(x)
        if arr.dtype.kind not in "biufc":
            raise ValueError(f"{name} must be a numeric vector of {n} values (shape {shape} "
                             f"flattened), got dtype {arr.dtype}")
        if arr.shape not in ((n,), (n, 1)):
            raise ValueError(f"{name} must be a vector of {n} values (shape {shape} "
                             f"flattened, C order), got shape {arr.shape}")
        return arr

    # ------------------------------------------------------------------ the maps
    def _apply_forward(self, X: np.ndarray) -> np.ndarray:
        """Columns of reflectivities ``(N, k)`` -> columns of samples ``(M, k)``."""
        k = X.shape[1]
        img = np.ascontiguousarray(X.T).astype(self.plan.work, copy=False)
        out = self.backend.forward(self.plan, img.reshape((k, *self.image_shape)))
        if self.oversampling > 1:
            out = decimate(out, self.oversampling)
        return out.reshape(k, -1).T

    def _apply_adjoint(self, Y: np.ndarray) -> np.ndarray:
        k = Y.shape[1]
        data = np.ascontiguousarray(Y.T).astype(self.plan.work, copy=False)
        data = data.reshape((k, self.plan.nf, *self.geometry.data.shape[-2:]))
        if self.oversampling > 1:
            data = zero_insert(data, self.oversampling, self.plan.grid)
        out = self.backend.adjoint(self.plan, data)
        return out.reshape(k, -1).T

    def _matvec(self, x: np.ndarray) -> np.ndarray:
        return self._apply_forward(x.reshape(-1, 1))[:, 0]

    def _rmatvec(self, x: np.ndarray) -> np.ndarray:
        return self._apply_adjoint(x.reshape(-1, 1))[:, 0]

    def _matmat(self, X: np.ndarray) -> np.ndarray:
        return self._apply_forward(X)

    def _rmatmat(self, X: np.ndarray) -> np.ndarray:
        return self._apply_adjoint(X)

    # ------------------------------------------------------------------ conveniences
    @property
    def coords(self) -> dict[str, np.ndarray]:
        """The image's axes, metres (and ``frequency``, Hz, with ``combine="none"``)."""
        out = {"z": self.plan.z.copy(), "y": self.y.copy(), "x": self.x.copy()}
        if self.plan.separate:
            out = {"frequency": self.plan.geometry.frequencies.copy(), **out}
        return out

    def to_image(self, vector: Any) -> Image:
        """A vector of ``image_shape`` voxels (a reflectivity, or ``A.H @ h``) as an Image."""
        v = self._checked(vector, "vector", self.shape[1], self.image_shape)
        g = self.plan.geometry
        data = np.asarray(v).reshape(self.image_shape)
        freq = g.frequencies.copy() if g.is_wideband else g.frequency
        return Image(data, self.x, self.y, self.plan.z, freq, f"operator:{self.backend.name}")

    def to_hologram(self, vector: Any) -> Hologram:
        """A vector of samples (``A @ r``) as a Hologram of this geometry."""
        v = self._checked(vector, "vector", self.shape[0], self.data_shape)
        g = self.geometry
        return Hologram(np.asarray(v).reshape(self.data_shape), g.x, g.y, g.frequency,
                        source=g.source, monostatic=g.monostatic, pose=g.pose,
                        polarization=g.polarization, tx_offset=g.tx_offset)

    def vector(self, hologram: Hologram) -> np.ndarray:
        """A hologram of this geometry (one frame) as the flat vector ``A.H`` takes."""
        if not isinstance(hologram, Hologram) or hologram.data.shape != self.data_shape:
            raise ValueError(f"hologram must be a holoradar.Hologram of one frame of shape "
                             f"{self.data_shape}, got "
                             f"{getattr(getattr(hologram, 'data', None), 'shape', hologram)!r}")
        return hologram.data.reshape(-1)

    def __repr__(self) -> str:
        return (f"<MigrationOperator {self.shape[0]} samples x {self.shape[1]} voxels, "
                f"image {self.image_shape}, backend {self.backend.name!r}, "
                f"{'' if self.oversampling == 1 else f'sampled 1 in {self.oversampling}, '}"
                f"{self.dtype}>")


def _of_samples(samples: SampledHologram, z: Any, medium: Any, settings: Any, sampling: str,
                preset: str, options: dict[str, Any]) -> Any:
    """``migration_operator`` of scattered samples (:func:`..samples.samples_operator`)."""
    from ..samples import samples_operator

    if settings is not None or sampling != "auto":
        raise ValueError("scattered samples take options by name (no settings=, sampling=)")
    return samples_operator(samples, z, medium=medium, **{**preset_options(preset), **options})
