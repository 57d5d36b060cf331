"""Propagators between the aperture plane (z = 0) and image planes at range z.

Two families, each a linear operator with a forward and an adjoint:

* :class:`AngularSpectrum` — exact, non-paraxial: every plane-wave component
  ``(p, q)`` is carried by the stack transfer ``U(p, q; z)`` of
  :meth:`Medium.vertical_transfer` (``exp(i*kz*z)`` in free space). Forward maps
  an up-going field at range z to the aperture; the adjoint multiplies by
  ``conj(U)``, which is migration (docs/imaging.md): exact inverse on the
  propagating band in a lossless medium, decaying (stable) on evanescent waves.
* :class:`Fresnel` — the paper's paraxial Eq. 3 as a sampled convolution with
  the Fresnel kernel ``(k/(2*pi*i*L)) * exp(i*k*(x^2 + y^2)/(2*L))`` times the
  normal-incidence stack transfer; ``L`` is the apparent distance
  (docs/imaging.md). Its adjoint convolves with the conjugate kernel.

Fourier convention: ``F(p, q) = sum f(x, y) exp(-i*(p*x + q*y))`` (numpy's
forward FFT); the pair of FFTs is exactly unitary up to the usual 1/N, so
forward and adjoint are exact adjoints of each other, padding and cropping
included (zero-padding's adjoint is cropping). Zero padding (``pad=True``:
at least twice each size) keeps the periodic FFT from wrapping the image.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._lazy import lazy_module
from .._threads import fft_workers
from ..caches import clear_caches, named_cache
from .medium import FREE_SPACE, Medium
from .spectra import fft2_padded, ifft2_cropped

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

__all__ = [
    "DEFAULT_SNR_DB",
    "TRANSFER_CACHE",
    "AngularSpectrum",
    "Fresnel",
    "absorption_gain",
    "band_taper",
    "basis_of",
    "clear_transfer_cache",
    "ifft2_cropped",
    "inverse_kz",
    "lateral_travel",
    "loss_exponent",
    "make_angular_transfer",
    "padded_shape",
    "spectral_axes",
    "spectral_quadrant",
    "spectral_step",
    "transfer_cache_bytes",
    "two_way_transfer",
]


def padded_shape(shape: tuple[int, int], pad: bool | float, *, pitch: tuple[float, float]
                 | None = None, wavelength: float | None = None,
                 z_max: float = 0.0) -> tuple[int, int]:
    """FFT grid for an ``(ny, nx)`` field.

    ``pad=False``: no padding (periodic). A float: that factor. An axis of one sample
    (a line scan's row) is never padded. ``pad=True``: at least twice each size,
    and at least ``lambda*z_max/(dx*dx_edge)`` samples,
    ``dx_edge = max(dx, lambda/2)``: the angular spectrum samples its transfer
    phase ``kz*z`` every ``dp = 2*pi/(M*dx)``, and at the highest travelling
    component ``p_edge = pi/dx_edge`` (the grid's band edge ``pi/dx``, or ``k``
    when the data are sampled finer than lambda/2: beyond it the components are
    evanescent and have no phase to sample) that phase turns by
    ``z*p_edge*dp/k`` per sample, which stays below pi only when
    ``M >= lambda*z/(dx*dx_edge)`` (for ``dx = lambda/2`` the critical distance
    ``z_c = M*dx^2/lambda`` of Voelz & Roggemann 2009). Beyond it the transfer
    function aliases; the steeper components that still would are dropped by the
    band limit. ``wavelength`` is the one the phase runs at (half the free-space
    wavelength for a transceiver's round trip).
    """
    if pad is True:
        dims = []
        for n, d in zip(shape, pitch[::-1] if pitch else (None, None), strict=True):
            if n == 1:   # a line scan's one row: its field does not vary along it
                dims.append(1)
                continue
            m = 2 * n
            if d is not None and wavelength is not None:
                edge = max(d, wavelength / 2)
                m = max(m, int(np.ceil(wavelength * z_max / (d * edge))))
            dims.append(sfft.next_fast_len(m, real=False))
        return tuple(dims)
    factor = 1.0 if pad is False else float(pad)
    if not np.isfinite(factor) or factor < 1:
        raise ValueError(f"pad must be True, False or a factor >= 1, got {pad!r}")
    if factor == 1:
        return tuple(shape)
    return tuple(1 if n == 1 else sfft.next_fast_len(int(np.ceil(factor * n)), real=False)
                 for n in shape)


def spectral_axes(shape: tuple[int, int], dx: float, dy: float) -> tuple[np.ndarray, np.ndarray]:
    """Transverse wavenumbers ``(p, q)`` in rad/m of an FFT grid of ``shape = (ny, nx)``."""
    ny, nx = shape
    return (2 * np.pi * sfft.fftfreq(nx, dx), 2 * np.pi * sfft.fftfreq(ny, dy))


def spectral_step(p: np.ndarray, q: np.ndarray) -> float:
    """The larger of a grid's two wavenumber steps, rad/m (from its axes)."""
    steps = [abs(float(a[1] - a[0])) for a in (p, q) if np.size(a) > 1]
    return max(steps, default=1e-9)


def inverse_kz(km: complex, kappa: np.ndarray, step: float) -> np.ndarray:
    """A point source's weight ``1/kz`` per plane wave, ``kz = sqrt(km^2 - kappa^2)``
    (Weyl's identity), as a grid of spectral ``step`` samples it.

    ``1/kz`` is singular where the waves turn evanescent (``kappa = km``): each sample
    takes its mean over ``kappa +- step/2``, ``(F(kappa + h) - F(kappa - h)) / 2h`` with
    ``F = arcsin(kappa / km)`` (whose derivative is ``1/kz`` on both sides of the
    circle; ``km`` nudged off the real axis so that the branch is ``kz``'s, Im >= 0).
    The waves evanescent at the source (``kappa > Re(km)``) are left out: a source
    wavelengths away sends nothing measurable through them except next to the
    circle, where a periodic grid cannot hold their long-range field.

    Examples
    --------
    >>> w = inverse_kz(200.0, np.array([0.0, 100.0, 300.0]), 1.0)
    >>> np.round((w * 200).real, 4)
    array([1.    , 1.1547, 0.    ])
    """
    h = 0.5 * float(step)
    kmt = complex(km) + 1e-9j * abs(km)
    mean = (np.arcsin((kappa + h) / kmt) - np.arcsin((kappa - h) / kmt)) / (2 * h)
    return np.where(kappa < complex(km).real, mean, 0)


def spectral_quadrant(shape: tuple[int, int], dx: float, dy: float
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """One quadrant of an FFT grid's wavenumbers and the map back to the grid.

    Returns ``(p, q, kappa2, unfold)``: ``|p|`` and ``|q|`` (rad/m, from 0 to the
    grid's band edge), ``kappa2 = q^2 + p^2`` of shape (len(q), len(p)), and the
    flat quadrant index of every grid component (``values.ravel()[unfold]``
    reshaped to ``shape`` unfolds a quadrant array). Whatever depends on ``|p|``
    and ``|q|`` only costs a quarter on the quadrant.
    """
    My, Mx = shape
    ix, iy = np.arange(Mx), np.arange(My)
    ix, iy = np.minimum(ix, Mx - ix), np.minimum(iy, My - iy)
    p = 2 * np.pi * np.arange(ix.max() + 1) / (Mx * dx)
    q = 2 * np.pi * np.arange(iy.max() + 1) / (My * dy)
    unfold = (iy[:, None] * p.size + ix[None, :]).ravel()
    return p, q, q[:, None] ** 2 + p[None, :] ** 2, unfold


def lateral_travel(k: float, medium: Medium, kappa2: np.ndarray, z: float, *,
                   below_surface: bool = False) -> np.ndarray:
    """Lateral distance per unit transverse wavenumber, ``sum_j h_j / Re(kz_j)`` (m^2/rad).

    A component (p, q) travelling from range ``z`` to the aperture shifts laterally
    by ``p * travel`` along x and ``q * travel`` along y (the group delay of its
    phase, ``d(phase)/dp``). Evanescent components get ``inf``.
    ``below_surface=True`` sums the ground's layers only (the air path left out).
    """
    kappa2 = np.asarray(kappa2, dtype=float)
    travel = np.zeros(np.shape(kappa2))
    for m, h in medium.crossings(z):
        if below_surface and m == 0:
            continue
        kz = medium.kz(k, kappa2, m).real
        travel = travel + np.where(kz > 0, h / np.where(kz > 0, kz, 1), np.inf)
    return travel


def loss_exponent(k: float, medium: Medium, kappa2: np.ndarray, z: float) -> np.ndarray:
    """``sum_j Im(kz_j) * h_j`` over the layers a component crosses from range ``z`` to 0.

    Counted in each layer where the component travels (``kappa^2 < k^2 Re(eps_j)``),
    not where it is evanescent: it is the absorption of a travelling wave, not the
    decay of an evanescent one (a component evanescent across the air gap but
    travelling in the ground is absorbed there all the same).
    ``exp(-loss_exponent)`` is its one-way amplitude loss.
    """
    kappa2 = np.asarray(kappa2, dtype=float)
    total = np.zeros(np.shape(kappa2))
    for m, h in medium.crossings(z):
        travels = kappa2 < k * k * complex(medium.eps[m]).real
        total += np.where(travels, medium.kz(k, kappa2, m).imag * h, 0.0)
    return total


DEFAULT_SNR_DB = 40.0


_MAX_LOSS_NEPER = 600.0  # beyond exp(-600) nothing returns from a plane: not undone


def absorption_gain(k: float, medium: Medium, kappa2: np.ndarray, z: float,
                    snr_db: float = DEFAULT_SNR_DB, *, monostatic: bool = False) -> np.ndarray:
    """Gain that undoes the absorption of the back-propagation to range ``z`` (loss compensation).

    The adjoint ``conj(U)`` carries each travelling component's one-way absorption
    ``a = exp(-sum_j Im(kz_j) h_j)`` once more (:func:`loss_exponent`). That extra
    factor falls with depth and tilts the image's depth profile towards the
    surface (the plain adjoint's focus is biased shallow). The gain is

        g = (1/a0) * (1 + e) / (a/a0 + e),    e = 10^(-snr_db/20),

    with ``a0`` the absorption of the vertical component (the least absorbed
    one in horizontally layered ground). So ``conj(U) g`` is

    * ``conj(U)/a``, phase and transmissions only, for every component absorbed
      within the data's dynamic range of the vertical one (``a/a0 >> e``): the
      depth profile is not tilted, at any depth (no cap: a cap would let the
      bias return beyond it);
    * ``conj(U) (1 + e)/(a0 e)`` for components absorbed below the noise relative
      to it: weighted by their amplitude, as in the matched filter (best SNR).

    Consequences: the compensated image's noise is never above that of a
    lossless back-propagation (``a g <= 1 + e``; the plain adjoint's noise falls
    with depth as ``a``); within a plane, the weights differ from the matched
    filter's only by the spread of ``g`` over the components that carry the
    signal, so the image SNR there stays within the Kantorovich bound
    ``2 sqrt(K)/(1 + K)`` of the matched filter's, ``K`` that spread. Lossless
    components get gain 1; evanescent ones (``loss_exponent`` 0) at most 1 + e.

    Parameters
    ----------
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
    kappa2 : ndarray
        ``p^2 + q^2``, rad^2/m^2.
    z : float
        Range of the image plane, metres.
    snr_db : float
        Signal-to-noise ratio of the data, dB (default 40).
    monostatic : bool
        Round trip of a scanned transceiver: both legs absorb, each with kappa/2
        (:func:`two_way_transfer`).

    Examples
    --------
    >>> clay = Medium.half_space(0.3, 12 + 3j)
    >>> kappa2 = np.array([0.0, 150.0**2])
    >>> a = np.exp(-loss_exponent(200.0, clay, kappa2, 0.4))   # 75 dB absorbed
    >>> (absorption_gain(200.0, clay, kappa2, 0.4) * a).round(4)   # undone: phase only
    array([1.    , 0.9978])
    """
    e = 10.0 ** (-float(snr_db) / 20)
    legs, k2 = (2.0, np.asarray(kappa2, dtype=float) / 4) if monostatic else (1.0, kappa2)
    loss = legs * loss_exponent(k, medium, k2, z)
    loss0 = min(legs * float(loss_exponent(k, medium, np.array(0.0), z)), _MAX_LOSS_NEPER)
    rel = np.exp(-np.clip(loss - loss0, 0.0, None))
    return np.exp(loss0) * (1 + e) / (rel + e)


#: Transfer functions, spectral bases and the plans built from them, shared by every
#: propagator and migration backend (least recently used out beyond 256 MiB).
TRANSFER_CACHE = named_cache("transfer functions", max_bytes=256 * 2**20)


def clear_transfer_cache() -> None:
    """Free what is kept between calls: the transfer functions (at most 256 MiB), the
    wideband sum's plans and every other named cache (:func:`holoradar.caches.clear_caches`)."""
    clear_caches()


def transfer_cache_bytes() -> int:
    """The most bytes of transfer functions kept between calls (256 MiB)."""
    return TRANSFER_CACHE.max_bytes


def _angular_transfer(shape: tuple[int, int], dx: float, dy: float, k: float, z: float,
                      medium: Medium, band_limit: bool | tuple, dtype: np.dtype,
                      conjugate: bool, compensate_loss: float | None = None,
                      monostatic: bool = False) -> np.ndarray:
    key = (shape, dx, dy, k, z, medium, band_limit, np.dtype(dtype).str, conjugate,
           compensate_loss, monostatic)
    return TRANSFER_CACHE.get(key, lambda: make_angular_transfer(*key[:7], np.dtype(dtype),
                                                          conjugate, compensate_loss,
                                                          monostatic))


def two_way_transfer(k: float, medium: Medium, kappa2: np.ndarray, z: float) -> np.ndarray:
    """Round-trip transfer of a scanned transceiver's component ``(p, q)`` to range ``z``.

    A monostatic sample records the wave sent down from the transceiver and
    scattered back up to it; at stationary phase both legs carry half the
    transverse wavenumber. So the component of transverse wavenumber kappa
    travels down and up with ``kappa/2``:
    ``U_mono = U_down(kappa^2/4) * U_up(kappa^2/4)``, i.e. ``exp(i*sqrt(4 k^2 - kappa^2) z)``
    in free space (the round-trip wavenumber 2k) and, in every layer, the
    round-trip ``kz`` with both legs' transmissions.

    Examples
    --------
    >>> k = 200.0
    >>> u = two_way_transfer(k, Medium.free_space(), np.array([0.0, 100.0**2]), 0.3)
    >>> np.allclose(u, np.exp(1j * np.sqrt(4 * k**2 - np.array([0.0, 100.0**2])) * 0.3))
    True
    """
    half = np.asarray(kappa2, dtype=float) / 4
    return medium.vertical_transfer(k, half, z, 0.0) * medium.vertical_transfer(k, half, 0.0, z)


@dataclass(frozen=True)
class _Basis:
    """What every plane of one grid, wavenumber and medium shares (cached).

    Everything depends on ``|p|`` and ``|q|`` only, so it lives on one quadrant of
    the spectrum (``unfold`` maps the grid onto it): a quarter of the work. In the
    deepest region, which has no layer below, the transfer from range ``z`` is the
    one from the region's top times ``exp(i kz (z - top))`` (the round trip:
    ``2 kz(kappa/2)``), and the lateral travel grows linearly: one exponential per
    plane instead of the whole layered recursion.
    """

    p: np.ndarray           # quadrant |p|, rad/m
    q: np.ndarray           # quadrant |q|, rad/m
    kappa2: np.ndarray      # (nq, np) p^2 + q^2
    unfold: np.ndarray      # (My*Mx,) flat quadrant index of each grid component
    top: float              # top of the deepest region, m
    base: np.ndarray        # transfer from the top of the deepest region to the aperture
    kz: np.ndarray          # vertical wavenumber of the phase in the deepest region
    t_top: np.ndarray       # lateral travel from the top of the deepest region
    rate: np.ndarray        # its growth per metre below it
    evanescent: np.ndarray  # no phase to sample (kept by the band limit)

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in (self.p, self.q, self.kappa2, self.unfold, self.base,
                                      self.kz, self.t_top, self.rate, self.evanescent))

    @classmethod
    def build(cls, shape: tuple[int, int], dx: float, dy: float, k: float, medium: Medium,
              monostatic: bool) -> _Basis:
        p, q, kappa2, unfold = spectral_quadrant(shape, dx, dy)
        last = medium.n_regions - 1
        top = medium.top_of(last)
        if last == 0:                       # free space: nothing above the planes
            kz = 2 * medium.kz(k, kappa2 / 4, 0) if monostatic else medium.kz(k, kappa2, 0)
            base, t_top = np.ones(kappa2.shape, complex), np.zeros(kappa2.shape)
        elif monostatic:
            base = two_way_transfer(k, medium, kappa2, top)
            kz = 2 * medium.kz(k, kappa2 / 4, last)
            t_top = 0.5 * lateral_travel(k, medium, kappa2 / 4, top)
        else:
            base = medium.vertical_transfer(k, kappa2, top, 0.0)
            kz = medium.kz(k, kappa2, last)
            t_top = lateral_travel(k, medium, kappa2, top)
        evanescent = kappa2 > (4 * k * k if monostatic else k * k)
        # Lateral travel per metre in the deepest region, 1/Re(kz) (the round trip:
        # (1/2)/Re(kz_j(kappa/2)) = 1/Re(2 kz_j(kappa/2)), the same form).
        rate = np.where(kz.real > 0, 1 / np.where(kz.real > 0, kz.real, 1), np.inf)
        basis = cls(p, q, kappa2, unfold, top, base, kz, t_top, rate, evanescent)
        for arr in (p, q, kappa2, unfold, base, kz, t_top, rate, evanescent):
            arr.setflags(write=False)
        return basis


def basis_of(shape: tuple[int, int], dx: float, dy: float, k: float, medium: Medium,
           monostatic: bool) -> _Basis:
    """What every plane of one FFT grid, wavenumber and medium shares (cached)."""
    key = ("basis", shape, dx, dy, k, medium, monostatic)
    return TRANSFER_CACHE.get(key, lambda: _Basis.build(shape, dx, dy, k, medium, monostatic))


def band_taper(low: np.ndarray, high: np.ndarray, needed: float, limit: float) -> np.ndarray:
    """Weight of components whose shift is ``low`` to the lowest element and
    ``high`` to the highest: 1 while a pixel-element pair may need them
    (``low <= needed``), 0 once their periodic alias could reach a pixel
    (``high >= limit``), a raised cosine between. The components it tapers are
    used by no pair; the smooth edge keeps the kernel from ringing back into the
    pairs that are (a sharp cut does, by a few percent).

    Examples
    --------
    >>> band_taper(np.array([0.1, 0.3, 0.5]), np.array([0.1, 0.3, 0.5]), 0.2, 0.8).round(3)
    array([1.   , 0.933, 0.5  ])
    """
    room = limit - (high - low) - needed
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(room > 0, (low - needed) / np.where(room > 0, room, 1.0),
                     np.where(low <= needed, 0.0, 1.0))
    f = np.nan_to_num(np.clip(f, 0.0, 1.0), nan=1.0)
    w = 0.5 * (1 + np.cos(np.pi * f))
    return np.where(np.isfinite(high) & (high < limit) | (low <= needed) & (high < limit),
                    w, 0.0)


def make_angular_transfer(shape: tuple[int, int], dx: float, dy: float, k: float, z: float,
                           medium: Medium, band_limit: bool | tuple, dtype: np.dtype,
                           conjugate: bool, compensate_loss: float | None,
                           monostatic: bool = False) -> np.ndarray:
    """The transfer from range ``z`` to the aperture on an FFT grid ``shape`` (FFT
    order, ``dtype``, read-only): band limited (``band_limit``: True the sharp cut,
    ``("smooth", reach_x, reach_y)`` the raised cosine of :func:`band_taper` for
    element-pixel distances up to those reaches, metres), conjugated with the
    loss compensation's gain (``conjugate``, ``compensate_loss`` the SNR in dB or None),
    a transceiver's round trip (``monostatic``). Not cached: see :class:`AngularSpectrum`."""
    b = basis_of(shape, dx, dy, k, medium, monostatic)
    deepest = medium.region_of(z) == medium.n_regions - 1
    if deepest:
        U = np.exp(1j * (z - b.top) * b.kz)
        if b.top > 0:
            U *= b.base
    elif monostatic:
        U = two_way_transfer(k, medium, b.kappa2, z)
    else:
        U = medium.vertical_transfer(k, b.kappa2, z, 0.0)
    if isinstance(band_limit, tuple):
        # The smooth band limit: 1 while a component's lateral shift may join an element
        # and a pixel (reach), 0 once its periodic alias could, a raised cosine between
        # (no ringing of a sharp cut back into the kernel).
        ny, nx = shape
        _, reach_x, reach_y = band_limit
        t = _travel(b, k, medium, z, deepest, monostatic)
        with np.errstate(invalid="ignore"):
            wx = band_taper(b.p[None, :] * t, b.p[None, :] * t, reach_x, nx * dx - reach_x)
            wy = band_taper(b.q[:, None] * t, b.q[:, None] * t, reach_y, ny * dy - reach_y)
        U = U * np.where(b.evanescent, 1.0, wx * wy)
    elif band_limit:
        # Band-limited angular spectrum (Matsushima & Shimobaba 2009): the phase of U
        # is sampled every dp = 2*pi/(M*dx); a component whose lateral shift p*travel
        # exceeds half the FFT grid, M*dx/2, is aliased (it would wrap around), and
        # it cannot join a pixel and an element inside the grid anyway. Drop it.
        # Round trip: the phase 2 sum kz_j(kappa/2) h_j shifts by (p/2) travel(kappa/2).
        ny, nx = shape
        t = _travel(b, k, medium, z, deepest, monostatic)
        with np.errstate(invalid="ignore"):  # 0 * inf at p = 0 for evanescent rows
            ok = (b.p[None, :] * t <= nx * dx / 2) & (b.q[:, None] * t <= ny * dy / 2)
        U = np.where(ok | b.evanescent, U, 0)
    if conjugate and compensate_loss is not None and not medium.is_lossless:
        # Undo the absorption of the back-propagation where the component stands above
        # the noise (the adjoint's extra exp(-Im(kz) h) favours shallow planes).
        U = U * absorption_gain(k, medium, b.kappa2, z, compensate_loss,
                                monostatic=monostatic)
    U = (U.conj() if conjugate else U).astype(dtype, copy=False)
    U = U.ravel()[b.unfold].reshape(shape)
    U.setflags(write=False)
    return U


def _travel(b: _Basis, k: float, medium: Medium, z: float, deepest: bool,
            monostatic: bool) -> np.ndarray:
    """Lateral travel per unit transverse wavenumber from range ``z`` to the aperture on
    the basis' quadrant (the round trip's: half of each leg's at half the wavenumber)."""
    with np.errstate(invalid="ignore"):  # 0 * inf at p = 0 for evanescent rows
        if deepest:
            return b.t_top + (b.rate * (z - b.top) if z > b.top else 0.0)
        if monostatic:
            return 0.5 * lateral_travel(k, medium, b.kappa2 / 4, z)
        return lateral_travel(k, medium, b.kappa2, z)


class PlaneOperator(ABC):
    """Shared pad / FFT / crop machinery of the propagators."""

    def __init__(self, shape: tuple[int, int], dx: float, dy: float, k: float,
                 z: float | Sequence[float], medium: Medium | None = None,
                 pad: bool | float = True, dtype: type = np.complex128, *,
                 band_limit: bool | str = True, compensate_loss: bool = False,
                 snr_db: float = DEFAULT_SNR_DB, monostatic: bool = False) -> None:
        self.shape = (int(shape[0]), int(shape[1]))
        self.dx, self.dy, self.k = float(dx), float(dy), float(k)
        self.z = np.atleast_1d(np.asarray(z, dtype=float))
        self.medium = medium if medium is not None else FREE_SPACE
        self.monostatic = bool(monostatic)
        # The round trip halves the effective wavelength (wavenumber 2k).
        lam = (np.pi if self.monostatic else 2 * np.pi) / self.k
        self.fft_shape = padded_shape(self.shape, pad, pitch=(self.dx, self.dy),
                                      wavelength=lam, z_max=float(self.z.max(initial=0.0)))
        self.dtype = np.dtype(dtype)
        if band_limit == "smooth":
            # Element-pixel distances reach across the aperture: (n - 1) pitches.
            self.band_limit: bool | tuple = ("smooth", (self.shape[1] - 1) * self.dx,
                                             (self.shape[0] - 1) * self.dy)
        else:
            self.band_limit = bool(band_limit)
        self.compensate_loss = bool(compensate_loss)
        self.snr_db = float(snr_db)
        # The cache key of the adjoint's absorption gain: None when not compensated.
        self._gain_key = self.snr_db if self.compensate_loss else None
        self._transfers: list[np.ndarray] | None = None
        self._adjoint: list[np.ndarray] | None = None

    @property
    def transfers(self) -> list[np.ndarray]:
        """Forward transfer function of each plane on the FFT grid (working dtype)."""
        if self._transfers is None:
            self._transfers = [self._transfer(float(z)) for z in self.z]
        return self._transfers

    @property
    def adjoint_transfers(self) -> list[np.ndarray]:
        """Their complex conjugates (cached, so that migration does not conjugate)."""
        if self._adjoint is None:
            self._adjoint = [self._transfer(float(z), conjugate=True) for z in self.z]
        return self._adjoint

    @abstractmethod
    def _transfer(self, z: float, conjugate: bool = False) -> np.ndarray:
        """(Conjugated) transfer function of the plane at range ``z``, working dtype."""

    @property
    def workers(self) -> int:
        """FFT threads: all cores, except for small grids where threads cost more."""
        return fft_workers(self.fft_shape[0] * self.fft_shape[1])

    def _fft(self, a: np.ndarray, own: bool = False) -> np.ndarray:
        """Padded 2-D FFT of ``a``; ``own``: ``a`` may be overwritten (a fresh copy)."""
        return fft2_padded(a, self.fft_shape, self.dtype, self.workers, own)

    def _ifft_crop(self, A: np.ndarray) -> np.ndarray:
        return ifft2_cropped(A, self.shape, self.workers)

    def spectrum(self, data: np.ndarray) -> np.ndarray:
        """Padded 2-D FFT of ``data`` (..., ny, nx) in the working dtype."""
        data = np.asarray(data)
        if data.shape[-2:] != self.shape:
            raise ValueError(f"data must end in shape {self.shape}, got {data.shape}")
        work = data.astype(self.dtype, copy=False)
        return self._fft(work, own=work is not data)

    def forward(self, field: np.ndarray) -> np.ndarray:
        """Fields at the planes ``z`` (..., nz, ny, nx) -> field at the aperture (..., ny, nx).

        The contributions of all planes add (a volume of sources radiating up).
        """
        field = np.asarray(field)
        if field.ndim < 3 or field.shape[-3] != self.z.size:
            raise ValueError(f"field must have shape (..., {self.z.size}, ny, nx)")
        F = self.spectrum(field)
        acc = np.zeros(F.shape[:-3] + self.fft_shape, dtype=F.dtype)
        for i, U in enumerate(self.transfers):
            acc += F[..., i, :, :] * U
        return self._ifft_crop(acc)

    def adjoint(self, hologram: np.ndarray) -> np.ndarray:
        """Aperture field (..., ny, nx) -> back-propagated fields (..., nz, ny, nx)."""
        H = self.spectrum(hologram)
        out = np.empty((*H.shape[:-2], self.z.size, *self.shape), dtype=self.dtype)
        for i, Uc in enumerate(self.adjoint_transfers):
            out[..., i, :, :] = self._ifft_crop(H * Uc)
        return out


class AngularSpectrum(PlaneOperator):
    """Exact angular-spectrum propagator through a layered medium.

    Parameters
    ----------
    shape : (int, int)
        ``(ny, nx)`` of the sampled fields.
    dx, dy : float
        Sample pitch, metres.
    k : float
        Wavenumber in air, rad/m.
    z : float or sequence of float
        Ranges of the image planes, metres (>= 0).
    medium : Medium, optional
        Layered medium (default free space).
    pad : bool or float
        Zero padding (:func:`padded_shape`): ``True`` at least doubles each size
        and keeps the transfer function sampled; a float is the factor.
    dtype : numpy dtype
        ``complex128`` (default) or ``complex64`` for speed.
    band_limit : bool or "smooth"
        Drop the components whose lateral shift exceeds half the FFT grid
        (band-limited angular spectrum, default True): they would wrap around.
        Evanescent components are kept (they decay). ``"smooth"``: keep every
        component an element-pixel pair of the aperture may need, drop those whose
        periodic alias could reach one, with a raised cosine between
        (:func:`band_taper`): no ringing of a sharp cut into the kernel (a point's
        field within 2 % of the exact Green's function with the grid padded 3x or
        more, against 10-13 % with the sharp cut); needs room between the two, a
        grid padded beyond twice the aperture.
    compensate_loss : bool
        Adjoint only: undo the absorption ``exp(-Im(kz)*h)`` of each propagating
        component in lossy layers where it stays above the noise, keeping phase
        and transmissions (:func:`absorption_gain`). Default False: the exact
        adjoint.
    snr_db : float
        Signal-to-noise ratio of the data that limits that gain, dB (default 40).
    monostatic : bool
        A scanned transceiver's round trip (:func:`two_way_transfer`) instead of
        the one-way transfer (default False).

    Examples
    --------
    >>> op = AngularSpectrum((32, 32), 0.01, 0.01, 2 * np.pi / 0.03, 0.2)
    >>> img = op.adjoint(np.ones((32, 32)))
    >>> img.shape
    (1, 32, 32)
    """

    def _transfer(self, z: float, conjugate: bool = False) -> np.ndarray:
        return _angular_transfer(self.fft_shape, self.dx, self.dy, self.k, z, self.medium,
                                 self.band_limit, self.dtype, conjugate, self._gain_key,
                                 self.monostatic)


class Fresnel(PlaneOperator):
    """Paraxial Fresnel-Kirchhoff propagator (the paper's Eq. 3), sampled convolution.

    Same parameters as :class:`AngularSpectrum`. The kernel is sampled on the
    grid, ``K = T0 * (k/(2*pi*i*L)) * exp(i*k*r^2/(2*L)) * dx*dy``, with ``L`` the
    apparent distance of the plane and ``T0`` the normal-incidence stack transfer
    (``exp(i*k*z)`` in free space). Use ``pad=True`` for a linear convolution.
    The kernel is cut where its local frequency ``k*|x|/L`` exceeds the grid's
    Nyquist ``pi/dx`` (beyond, the sampled chirp would alias).
    """

    def _transfer(self, z: float, conjugate: bool = False) -> np.ndarray:
        if z <= 0:
            raise ValueError("the Fresnel kernel needs z > 0")
        My, Mx = self.fft_shape
        # Sample offsets in FFT order so that the circular convolution is linear
        # on the cropped output when the grid is padded to >= 2n - 1.
        ox = np.fft.fftfreq(Mx, 1.0 / Mx) * self.dx
        oy = np.fft.fftfreq(My, 1.0 / My) * self.dy
        L = self.medium.apparent_distance(z)
        zero = np.array(0.0)
        if self.monostatic:  # round trip: wavenumber 2k, both legs' transmissions
            T0 = complex(two_way_transfer(self.k, self.medium, zero, z))
            k = 2 * self.k
        else:
            T0 = complex(self.medium.vertical_transfer(self.k, zero, z, 0.0))
            k = self.k
        if conjugate and self.compensate_loss:
            T0 *= float(absorption_gain(self.k, self.medium, zero, z, self.snr_db,
                                        monostatic=self.monostatic))
        r2 = oy[:, None] ** 2 + ox[None, :] ** 2
        kern = (T0 * k / (2j * np.pi * L) * np.exp(1j * k * r2 / (2 * L))
                * self.dx * self.dy)
        # The chirp's local frequency k*|x|/L must stay below the grid's Nyquist
        # pi/dx; beyond it the sampled kernel aliases, so it is cut there (the
        # sampling limit of the impulse-response method).
        kern = np.where((np.abs(ox[None, :]) * k / L <= np.pi / self.dx)
                        & (np.abs(oy[:, None]) * k / L <= np.pi / self.dy), kern, 0)
        U = sfft.fft2(kern, workers=fft_workers(kern.shape[-2] * kern.shape[-1]))
        return (U.conj() if conjugate else U).astype(self.dtype, copy=False)
