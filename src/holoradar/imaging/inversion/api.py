"""``hr.invert``: the reflectivity on the image grid, by inverting the measurement.

The migrated image is the adjoint of the measurement: its amplitude carries the
illumination, the aperture's sidelobes and the adjoint's pull towards the array.
Inverting the migration operator (docs/inversion.md) divides out the illumination
it models, deconvolves the sidelobes and has no pull: equal objects give equal values
wherever they lie.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...data.hologram import C0, Hologram, Image
from ...physics.propagation import padded_shape
from ...theory import resolution_cells
from ..migration.linear import migration_operator
from ..migration.memory import available_memory
from ..migration.settings import MigrationSettings, preset_options
from .columns import column_norms
from .noise import nearest_source, noise_std
from .solvers import FALSE_ALARM, least_squares, noise_threshold, sparse

__all__ = ["METHODS", "Reflectivity", "invert", "reflectivity"]

METHODS = ("lsqr", "sparse")
MAX_ITER = {"lsqr": 100, "sparse": 1000}


def invert(hologram: Hologram, z: Any, *, medium: Any = None, method: str = "lsqr",
           noise: float | None = None, max_iter: int | None = None,
           progress: bool | None = None, **migrate_options: Any) -> Image:
    """The reflectivity behind a hologram on the planes ``z``, by inverting the measurement.

    Parameters
    ----------
    hologram : Hologram
        One frame: a receiver array with its ``source`` (the illumination must be
        known), or a scanned transceiver; one frequency or several; level or posed
        (with ``frame="ground"``).
    z : float or sequence of float
        Ranges of the image planes, metres.
    medium : Medium, optional
        The layered ground (None: free space).
    method : {"lsqr", "sparse"}
        ``"lsqr"`` (default): damped least squares, stopped when the residual reaches
        the noise (the discrepancy principle); ``"sparse"``: L1-regularised (FISTA),
        its threshold from the noise, for scenes of a few objects (resolves what the
        least squares' smoothing joins). See :mod:`.solvers`.
    noise : float, optional
        The receiver noise's standard deviation per sample, in the data's units.
        Default: estimated from the hologram's evanescent band where its pitch is
        below half a wavelength, else 40 dB below its mean power (with a warning).
    max_iter : int, optional
        The most solver steps (default 100 for ``"lsqr"``, 1000 for ``"sparse"``).
    progress : bool, optional
        A progress bar over the steps (default: after a second of work).
    **migrate_options
        The operator's options (:func:`holoradar.migration_operator`): ``upsample``,
        ``frame``, ``x``, ``y``, ``dtype``, ``pad``, ``algorithm``... Defaults here: each
        voxel a point scatterer (``scatterer="point"``), lit by the source's field
        (``illumination="field"``), no loss compensation, unit frequency weights, the
        smooth band limit on a grid padded at least 3x, and single precision
        (``dtype=np.complex64``, as ``migrate``: the solver's steps about twice as
        fast; the paper's 16 x 16 onto 61 x 61 x 40 voxels takes the same 54 steps
        and its peak agrees with double precision to 1.3e-6; ``dtype=np.complex128``
        for double).

    Returns
    -------
    Image
        The reflectivity: the Born scattering amplitude of each voxel (a point
        target's ``amplitude``: what it sends the elements is that times the incident
        field there times the layered Green's function), complex, shape as
        ``migrate``'s; ``method`` ``"invert:lsqr"`` or ``"invert:sparse"``; ``history``
        the solver, steps, final residual and the noise's norm, the stop reason.

    Raises
    ------
    ValueError
        A misspelt method, a noise that is not positive, a receiver array without
        ``source``, several frames, a bad option.
    MemoryError
        The solver's vectors and the operator's kept transfers would not fit.

    Examples
    --------
    >>> import holoradar as hr
    >>> scene = hr.Scene(targets=[hr.PointTarget((0.004, 0.004, 0.3), 2.0)],
    ...                  source=hr.PlaneWave())
    >>> h = hr.simulate(scene, hr.Aperture.grid(24, 0.008), 9.9e9, snr_db=40, seed=0)
    >>> r = hr.invert(h, 0.3, method="sparse", progress=False)

    The point's position, and its amplitude (the sum over the voxels it is kept in):

    >>> [round(v, 3) for v in r.peak()], round(float(abs(r.data.sum())), 1)
    ([0.004, 0.004, 0.3], 2.0)
    """
    return reflectivity(hologram, z, medium=medium, method=method, noise=noise,
                        max_iter=max_iter, progress=progress, **migrate_options).image


@dataclass(frozen=True)
class Reflectivity:
    """An inversion's result with what a detector needs besides the image."""

    image: Image
    column_norms: np.ndarray   # c_j, image_shape
    sigma: float               # the noise's standard deviation per sample
    threshold: float           # |r_j| c_j above it: not noise (the sparse threshold)
    again: Any = field(default=None, repr=False, compare=False)
    """``again(sigma)``: the same inversion with another noise, its operator, column
    norms and step size kept (a noise revised after a first fit costs the steps, not
    the set-up)."""


def reflectivity(hologram: Hologram, z: Any, *, medium: Any = None, method: str = "lsqr",
                 noise: float | None = None, max_iter: int | None = None,
                 progress: bool | None = None, false_alarm: float = FALSE_ALARM,
                 need_source: bool = True, **migrate_options: Any) -> Reflectivity:
    """:func:`invert`, with the column norms, the noise and the noise threshold
    (``false_alarm``: the chance that noise alone passes it anywhere on the grid).
    ``need_source=False`` lets a receiver array without a source through, for
    ``illumination="none"`` (a uniform illumination, carried by the result)."""
    _check(hologram, method, max_iter, need_source)
    steps = MAX_ITER[method] if max_iter is None else int(max_iter)
    options = _options(hologram, z, migrate_options)
    A = migration_operator(hologram, z, medium=medium, **options)
    _check_memory(A, method)
    zs = A.plan.z
    sigma, how = noise_std(hologram, nearest_source(zs, medium), noise)
    d = A.vector(hologram).astype(A.dtype, copy=False)
    c = column_norms(A, _cell_px(A, hologram))

    def solve(sigma: float, how: str, warm: Any = None) -> Reflectivity:
        if method == "lsqr":
            sol = least_squares(A, d, sigma, c, steps, progress)
        else:
            sol = sparse(A, d, sigma, c, steps, progress, false_alarm, warm=warm)
        out = A.to_image(sol.r)
        step = {"name": "invert", "method": method, "noise_std": sigma, "noise": how,
                "iterations": sol.iterations, "residual": sol.residual,
                "noise_norm": sol.noise_norm,
                "residual_over_noise": sol.residual / sol.noise_norm,
                "stop": sol.stop, "unit": "Born scattering amplitude per voxel",
                **{k: float(v) for k, v in sol.extra.items()}}
        data = out.data if np.ndim(z) != 0 else out.data[..., 0, :, :]
        image = Image(data, out.x, out.y, zs, out.frequency, f"invert:{method}",
                      has_z_axis=np.ndim(z) != 0, history=(step,))
        return Reflectivity(image, c, sigma, noise_threshold(sigma, c.size, false_alarm),
                            lambda s, h="given": solve(float(s), h, sol.warm))

    return solve(sigma, how)


def _check(hologram: Any, method: Any, max_iter: Any, need_source: bool = True) -> None:
    if not isinstance(hologram, Hologram):
        raise ValueError(f"hologram must be a holoradar.Hologram, got {type(hologram).__name__}")
    if method not in METHODS:
        raise ValueError(f"method must be 'lsqr' or 'sparse', got {method!r}")
    if max_iter is not None and (isinstance(max_iter, bool) or not isinstance(
            max_iter, int | np.integer) or max_iter < 1):
        raise ValueError(f"max_iter must be a positive integer, got {max_iter!r}")
    if need_source and not hologram.monostatic and hologram.source is None:
        raise ValueError("hologram.source is needed: the inversion divides out the "
                         "illumination, so a receiver array's source must be known "
                         "(Hologram(..., source=...)); a scanned transceiver lights the "
                         "scene itself (monostatic=True)")
    frames = hologram.data.ndim - (3 if hologram.is_wideband else 2)
    if frames:
        raise ValueError(f"hologram must hold one frame, got data of shape "
                         f"{hologram.data.shape}: invert the frames one by one")


def _options(hologram: Hologram, z: Any, given: dict[str, Any]) -> dict[str, Any]:
    """The operator's options: the physics, and a grid padded for an accurate model."""
    opts = {**preset_options("inversion"), **given}
    opts.setdefault("dtype", np.complex64)
    if given.get("frame", "aperture") == "aperture":
        opts.setdefault("band_limit", "smooth")
        if "pad" not in given:
            # At least 3x (room for the smooth band limit), and what the transfer's
            # sampling at the deepest plane needs (padded_shape).
            lam = C0 / float(np.max(hologram.frequencies)) / (2 if hologram.monostatic else 1)
            zmax = float(np.max(np.atleast_1d(np.asarray(z, dtype=float))))
            need = padded_shape(hologram.data.shape[-2:], True, pitch=hologram.pitch,
                                wavelength=lam, z_max=zmax)
            opts["pad"] = max(3.0, *(m / n for m, n in zip(need, hologram.data.shape[-2:],
                                                           strict=True)))
    MigrationSettings.of(**opts)   # the checks, once, here
    return opts


def _cell_px(A: Any, hologram: Hologram) -> float:
    """A lateral resolution cell at the middle plane, in image pixels (lambda z / A)."""
    # The operator's ranges as they are (no apparent distance: its planes' own).
    cell = resolution_cells(hologram, None, float(np.median(A.plan.z)))[0]
    pitch = float(abs(A.x[1] - A.x[0])) if A.x.size > 1 else hologram.pitch[0]
    return max(cell / pitch, 1.0)


def _check_memory(A: Any, method: str) -> None:
    """Refuse, before any work, a problem whose vectors would not fit in memory."""
    n, m = A.shape[1], A.shape[0]
    item = np.dtype(A.dtype).itemsize
    vectors = (8 if method == "lsqr" else 10) * n * item + 4 * m * item
    probes = 8 * n * item * 2
    need = vectors + probes
    avail = available_memory()
    if need > avail:
        gib = 2.0**30
        raise MemoryError(
            f"inverting onto {A.image_shape} voxels needs about {need / gib:.2f} GiB for "
            f"the solver's vectors, more than the {avail / gib:.2f} GiB available: invert "
            "fewer planes or a smaller region (x, y with frame='ground'), or a coarser "
            "grid (upsample=1)")
    if n * item > avail / 4:
        warnings.warn(f"the inversion's vectors take {need / 2**30:.2f} GiB",
                      ResourceWarning, stacklevel=3)
