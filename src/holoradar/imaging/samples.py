"""Imaging samples at scattered positions through the grid's machinery, by non-uniform FFTs.

A :class:`~holoradar.data.samples.SampledHologram` is imaged onto a uniform grid of
pitch ``(dx, dy)`` (the image's) held inside a periodic box of ``My x Mx`` points,
twice the extent of the image and the samples together (the padding a grid gets). Two
maps join the samples to that box:

* sampling ``P``: the box's band-limited field read at the positions,
  ``d_n = (1/M) sum_k G(k) exp(+i k.(r_n - r_0))``, ``G = fft2(g)``, ``M = My Mx``: a
  type-2 non-uniform FFT (finufft) of the field's spectrum;
* its adjoint ``P^H``: ``g = ifft2(D)``, ``D(k) = sum_n d_n exp(-i k.(r_n - r_0))``: a
  type-1 non-uniform FFT, the samples' spectrum on the box's wavenumbers.

Samples that lie on the box's points make ``P^H`` the zero-padded grid itself (then the
image is the grid's ``migrate``, to the non-uniform FFT's precision). The box's field
``P^H d`` is migrated as any grid is (free space, a layered ground, a transceiver's
round trip or a source's field, one frequency or a band): :func:`migrate_samples` is
``migrate`` of it, cropped to the image grid, and :func:`samples_operator` the forward
map ``P G E`` (``G`` the grid's migration operator, ``E`` the image grid placed in the
box) with its exact adjoint ``E^H G^H P^H``. The adjoint is the matched filter with the
grid's kernel (the band-limited plane-wave expansion of the Green's function sampled on
the box's wavenumbers), written out as a sum over samples and pixels in
``tests/test_samples.py``.

Cost: one type-1 (or type-2) transform of ``n`` samples per frequency onto the box, then
what the grid costs; a direct matched filter costs ``n x pixels x planes x nf``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.sparse.linalg import LinearOperator

from .._lazy import lazy_module
from ..data.hologram import C0, Hologram, Image
from ..data.samples import SampledHologram

sfft = lazy_module("scipy.fft")

__all__ = ["Coverage", "SamplesBox", "coverage", "image_axes", "migrate_samples",
           "samples_operator"]

#: Precision asked of the non-uniform FFTs (relative, finufft's ``eps``).
NUFFT_EPS = 1e-9


def image_axes(samples: SampledHologram, x: Any = None, y: Any = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """The image grid: ``x``, ``y`` as given (uniform, increasing, metres), else the
    samples' extent at a pitch of ``lambda_min / 4`` for a transceiver's round trip,
    ``lambda_min / 2`` otherwise (the Nyquist spacing of the image's band)."""
    lam = C0 / float(samples.frequencies.max())
    pitch = lam / 4 if samples.monostatic else lam / 2
    axes = []
    for name, given, col in (("x", x, 0), ("y", y, 1)):
        if given is None:
            lo, hi = samples.positions[:, col].min(), samples.positions[:, col].max()
            n = math.floor((hi - lo) / pitch + 1e-9) + 1
            c = lo + np.arange(n) * pitch + ((hi - lo) - (n - 1) * pitch) / 2
        else:
            c = np.atleast_1d(np.asarray(given, dtype=float))
            step = np.diff(c)
            if c.ndim != 1 or c.size < 2 or not np.all(np.isfinite(c)) or \
                    not np.all(step > 0) or np.ptp(step) > 1e-6 * step.mean():
                raise ValueError(f"{name} must be uniform increasing pixel positions (at "
                                 f"least 2, metres), got {given!r}")
        axes.append(c)
    return axes[0], axes[1]


@dataclass(frozen=True)
class SamplesBox:
    """The periodic box the samples are carried onto: ``(my, mx)`` points of pitch
    ``(dx, dy)`` from ``(x0, y0)``; the image grid starts at box index ``(iy, ix)``."""

    x0: float
    y0: float
    dx: float
    dy: float
    mx: int
    my: int
    ix: int
    iy: int
    nx: int
    ny: int

    @classmethod
    def of(cls, samples: SampledHologram, x: np.ndarray, y: np.ndarray) -> SamplesBox:
        """The box for these samples and this image grid: the extent of both, twice."""
        p = samples.positions
        return cls.spanning(x, y, (float(p[:, 0].min()), float(p[:, 1].min())),
                            (float(p[:, 0].max()), float(p[:, 1].max())))

    @classmethod
    def spanning(cls, x: np.ndarray, y: np.ndarray, lo: tuple[float, float] | None = None,
                 hi: tuple[float, float] | None = None) -> SamplesBox:
        """The box of the image grid ``x``, ``y`` and the extent ``lo`` .. ``hi`` (x, y,
        metres; default the grid's own): twice their joint extent."""
        vals = []
        for i, c in enumerate((x, y)):
            d = float(c[1] - c[0])
            a = float(c[0]) if lo is None else min(float(c[0]), lo[i])
            b = float(c[-1]) if hi is None else max(float(c[-1]), hi[i])
            below = math.ceil((float(c[0]) - a) / d - 1e-9)   # box points before c[0]
            span = math.ceil((b - a) / d - 1e-9) + 2
            m = int(sfft.next_fast_len(2 * span))
            start = below + (m - span) // 2    # the image grid's first index in the box
            vals.append((float(c[0]) - start * d, d, m, start, c.size))
        (x0, dx, mx, ix, nx), (y0, dy, my, iy, ny) = vals
        return cls(x0, y0, dx, dy, mx, my, ix, iy, nx, ny)

    def holds(self, positions: np.ndarray) -> np.ndarray:
        """Which positions ``(n, >=2)`` lie inside the box (else they would fold)."""
        u = (positions[:, 0] - self.x0) / (self.mx * self.dx)
        v = (positions[:, 1] - self.y0) / (self.my * self.dy)
        return (u >= 0) & (u < 1) & (v >= 0) & (v < 1)

    @property
    def x(self) -> np.ndarray:
        return self.x0 + np.arange(self.mx) * self.dx

    @property
    def y(self) -> np.ndarray:
        return self.y0 + np.arange(self.my) * self.dy

    def phases(self, samples: Any) -> tuple[np.ndarray, np.ndarray]:
        """The positions (of a SampledHologram, or an ``(n, >=2)`` array) as finufft's
        angles, ``2 pi (r - r0) / L`` in ``[-pi, pi)``."""
        p = samples.positions if isinstance(samples, SampledHologram) else samples
        ax = 2 * np.pi * (p[:, 0] - self.x0) / (self.mx * self.dx)
        ay = 2 * np.pi * (p[:, 1] - self.y0) / (self.my * self.dy)
        return (np.mod(ay + np.pi, 2 * np.pi) - np.pi, np.mod(ax + np.pi, 2 * np.pi) - np.pi)

    def spectrum(self, samples: Any, data: np.ndarray) -> np.ndarray:
        """``D(k) = sum_n d_n exp(-i k.(r_n - r_0))`` of samples ``(nf, n)`` (positions
        as :meth:`phases` takes them) on the box's wavenumbers, ``(nf, my, mx)``."""
        import finufft

        ay, ax = self.phases(samples)
        D = finufft.nufft2d1(ay, ax, np.ascontiguousarray(data, dtype=complex),
                             (self.my, self.mx), eps=NUFFT_EPS, isign=-1, modeord=1)
        return D.reshape(-1, self.my, self.mx)

    def to_box(self, samples: Any, data: np.ndarray) -> np.ndarray:
        """``P^H``: samples ``(nf, n)`` to the box's field ``(nf, my, mx)``."""
        return sfft.ifft2(self.spectrum(samples, data), workers=-1)

    def from_box(self, samples: SampledHologram, field: np.ndarray) -> np.ndarray:
        """``P``: the box's field ``(nf, my, mx)`` read at the positions, ``(nf, n)``."""
        import finufft

        ay, ax = self.phases(samples)
        G = sfft.fft2(np.asarray(field, dtype=complex), workers=-1) / (self.my * self.mx)
        out = finufft.nufft2d2(ay, ax, np.ascontiguousarray(G), eps=NUFFT_EPS, isign=1,
                               modeord=1)
        return out.reshape(-1, samples.n)

    def crop(self, volume: np.ndarray) -> np.ndarray:
        """The image grid's part of a box image (last two axes)."""
        return volume[..., self.iy:self.iy + self.ny, self.ix:self.ix + self.nx]

    def embed(self, image: np.ndarray) -> np.ndarray:
        """An image on the image grid placed in the box, zero elsewhere."""
        out = np.zeros((*image.shape[:-2], self.my, self.mx), dtype=image.dtype)
        out[..., self.iy:self.iy + self.ny, self.ix:self.ix + self.nx] = image
        return out


def _box_hologram(samples: SampledHologram, box: SamplesBox, field: np.ndarray) -> Hologram:
    data = field if samples.is_wideband else field[0]
    return Hologram(data, box.x, box.y, samples.frequency, source=samples.source,
                    monostatic=samples.monostatic, polarization=samples.polarization)


def _weights(samples: SampledHologram, equalize: Any) -> Any:
    """``equalize=True`` weighs each frequency by 1 / its samples' RMS (as a grid's own
    RMS weighs it); weights given or False pass as they are."""
    if equalize is True and samples.is_wideband:
        rms = np.sqrt(np.mean(np.abs(samples.data) ** 2, axis=1))
        return np.divide(1.0, rms, out=np.zeros_like(rms), where=rms > 0)
    return equalize


def _check_options(options: dict[str, Any]) -> None:
    for k, bad in (("pad", None), ("fov", None), ("frame", "aperture"), ("upsample", 1)):
        if k in options and (bad is None or options[k] != bad):
            raise ValueError(f"{k}: scattered samples are imaged on the grid x, y (a box "
                             "twice the extent, in the aperture's frame); leave it out")


def migrate_samples(samples: SampledHologram, z: Any, *, x: Any = None, y: Any = None,
                    equalize: Any = True, **options: Any) -> Image:
    """``holoradar.migrate`` of samples at scattered positions (see the module text).

    Parameters
    ----------
    samples : SampledHologram
    z : float or sequence of float
        Ranges of the image planes, metres.
    x, y : array_like, optional
        The image grid (uniform pixel positions, metres); default :func:`image_axes`.
    equalize : bool or sequence of float
        As for grids; ``True`` weighs each frequency by 1 / its samples' RMS.
    **options
        ``migrate``'s others (``medium``, ``method``, ``dtype``, ``combine``,
        ``compensate_loss``, ``snr_db``, ``progress``, ``algorithm``).

    Returns
    -------
    Image
        On ``x``, ``y``; ``method`` as the grid's, with ``:samples`` added.

    Examples
    --------
    >>> import numpy as np
    >>> import holoradar as hr
    >>> rng = np.random.default_rng(1)
    >>> p = rng.uniform(-0.06, 0.06, (3000, 2))
    >>> f = np.linspace(8e9, 12e9, 8)
    >>> k = 2 * np.pi * f[:, None] / 299792458.0
    >>> R = np.sqrt((p[:, 0] - 0.01) ** 2 + p[:, 1] ** 2 + 0.1 ** 2)
    >>> s = hr.Hologram.from_samples(np.exp(2j * k * R) / R**2, p, f, monostatic=True)
    >>> img = migrate_samples(s, np.linspace(0.06, 0.14, 17))
    >>> [round(v, 2) + 0.0 for v in img.peak()]    # the point: 1 cm off, 10 cm away
    [0.01, 0.0, 0.1]
    """
    from .migrate import migrate

    if not isinstance(samples, SampledHologram):
        raise ValueError(f"samples must be a SampledHologram (Hologram.from_samples), got "
                         f"{type(samples).__name__}")
    _check_options(options)
    xs, ys = image_axes(samples, x, y)
    box = SamplesBox.of(samples, xs, ys)
    field = box.to_box(samples, samples.data.reshape(samples.nf, samples.n))
    img = migrate(_box_hologram(samples, box, field), z, pad=False, fov="aperture",
                  equalize=_weights(samples, equalize), **options)
    data = box.crop(img.data)
    return Image(data, xs, ys, img.z, img.frequency, f"{img.method}:samples",
                 has_z_axis=img.has_z_axis)


class SamplesOperator(LinearOperator):
    """The forward map from a reflectivity on the image grid to the samples, ``P G E``,
    and its exact adjoint (see the module text). ``image_shape`` is ``(nz, ny, nx)``
    (``(ny, nx)`` for one plane); vectors are flattened, data ``(nf, n)`` row-major."""

    def __init__(self, samples: SampledHologram, grid_operator: Any, box: SamplesBox,
                 x: np.ndarray, y: np.ndarray) -> None:
        self.samples, self.grid, self.box, self.x, self.y = samples, grid_operator, box, x, y
        lead = grid_operator.image_shape[:-2]
        self.image_shape = (*lead, box.ny, box.nx)
        self.data_shape = (samples.nf, samples.n)
        super().__init__(dtype=np.dtype(grid_operator.dtype),
                         shape=(samples.nf * samples.n, math.prod(self.image_shape)))

    def _matvec(self, v: np.ndarray) -> np.ndarray:
        img = np.asarray(v).reshape(self.image_shape)
        field = self.grid.matvec(self.box.embed(img).ravel())
        field = field.reshape(self.samples.nf, self.box.my, self.box.mx)
        return self.box.from_box(self.samples, field).astype(self.dtype).ravel()

    def _rmatvec(self, u: np.ndarray) -> np.ndarray:
        d = np.asarray(u).reshape(self.data_shape)
        field = self.box.to_box(self.samples, d).astype(self.dtype)
        img = self.grid.rmatvec(field.ravel()).reshape(self.grid.image_shape)
        return self.box.crop(img).ravel()


def samples_operator(samples: SampledHologram, z: Any, *, x: Any = None, y: Any = None,
                     equalize: Any = False, **options: Any) -> SamplesOperator:
    """``holoradar.migration_operator`` of samples at scattered positions: the forward map
    from a reflectivity on ``x``, ``y`` (default :func:`image_axes`) at ranges ``z`` to
    the samples, with its exact adjoint; ``options`` as ``migration_operator``'s.

    Examples
    --------
    >>> import numpy as np
    >>> import holoradar as hr
    >>> rng = np.random.default_rng(2)
    >>> s = hr.Hologram.from_samples(np.ones((2, 400)), rng.uniform(0, 0.08, (400, 2)),
    ...                              [9e9, 11e9], monostatic=True)
    >>> A = samples_operator(s, [0.1, 0.12])
    >>> a = rng.standard_normal(A.shape[1]) + 1j * rng.standard_normal(A.shape[1])
    >>> b = rng.standard_normal(A.shape[0]) + 1j * rng.standard_normal(A.shape[0])
    >>> bool(abs(np.vdot(b, A @ a) - np.vdot(A.H @ b, a)) < 1e-9 * abs(np.vdot(b, A @ a)))
    True
    """
    from .migration.linear import migration_operator

    _check_options(options)
    xs, ys = image_axes(samples, x, y)
    box = SamplesBox.of(samples, xs, ys)
    # The grid's geometry only (its data set equalize=True's weights: given here).
    proxy = _box_hologram(samples, box, np.zeros((samples.nf, box.my, box.mx), complex))
    options.setdefault("dtype", np.complex128)
    G = migration_operator(proxy, z, pad=False, fov="aperture",
                           equalize=_weights(samples, equalize), **options)
    return SamplesOperator(samples, G, box, xs, ys)


@dataclass(frozen=True)
class Coverage:
    """Where samples are dense enough for the image's band: ``distance`` (ny, nx), metres,
    from each pixel of ``x``, ``y`` to its nearest sample; ``spacing`` the band's Nyquist
    spacing (``lambda_min / 4`` for a transceiver, ``lambda_min / 2`` otherwise);
    ``covered`` where ``distance <= spacing / sqrt(2)`` (a grid at that spacing covers
    every pixel: its farthest point, a cell's centre, is that far)."""

    x: np.ndarray
    y: np.ndarray
    distance: np.ndarray
    spacing: float

    @property
    def covered(self) -> np.ndarray:
        return self.distance <= self.spacing / math.sqrt(2) * (1 + 1e-9)

    @property
    def fraction(self) -> float:
        """The share of the pixels covered."""
        return float(np.mean(self.covered))


def coverage(samples: SampledHologram, x: Any = None, y: Any = None) -> Coverage:
    """The samples' coverage of the image grid (default :func:`image_axes`): the holes
    a freehand scan left, where the image holds only what reaches them from afar.

    Examples
    --------
    >>> import numpy as np
    >>> import holoradar as hr
    >>> g = np.arange(0, 0.1, 0.006)
    >>> X, Y = np.meshgrid(g, g)
    >>> p = np.column_stack([X.ravel(), Y.ravel()])
    >>> p = p[np.hypot(p[:, 0] - 0.05, p[:, 1] - 0.05) > 0.02]     # a hole of 2 cm
    >>> s = hr.Hologram.from_samples(np.ones(len(p)), p, 12e9, monostatic=True)
    >>> c = coverage(s)
    >>> round(c.spacing * 1000, 2), c.covered[c.y.size // 2, c.x.size // 2]
    (6.25, np.False_)
    """
    from scipy.spatial import cKDTree

    xs, ys = image_axes(samples, x, y)
    lam = C0 / float(samples.frequencies.max())
    spacing = lam / 4 if samples.monostatic else lam / 2
    X, Y = np.meshgrid(xs, ys)
    dist, _ = cKDTree(samples.positions[:, :2]).query(np.column_stack([X.ravel(), Y.ravel()]))
    return Coverage(xs, ys, dist.reshape(X.shape), spacing)
