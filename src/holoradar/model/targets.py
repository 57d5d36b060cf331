"""Scattering targets: point scatterers (induced dipoles), lines and planar objects.

A :class:`PointTarget` of amplitude ``a`` at r_t re-radiates ``a * E0(r_t)`` as a
point source in the medium that holds it (Born). In the vector model (a
hologram with a ``polarization`` and a polarised source) it is an induced
dipole ``p = alpha E0(r_t)``, ``alpha`` its polarizability (a scalar, or a 3 x 3
tensor), radiating ``G p`` (the dyadic Green's function of the stack, normalised
so that a dipole far away broadside gives ``|p|/R``): ``amplitude`` is ``alpha``
of an isotropic scatterer, e.g. ``(k_m a)^2 a (eps_s - eps_m)/(eps_s + 2 eps_m)``
for a small sphere of radius ``a`` (:meth:`PointTarget.sphere`). A
:class:`LineTarget` (rebar, pipe, wire) is a row of such dipoles along its axis,
with the polarizabilities per unit length of an infinite cylinder, along and
across its axis (:func:`cylinder_polarizabilities`). A :class:`PlanarTarget` at
range z with reflection coefficient ``f(x, y)`` replaces the incident field by the
reflected field ``f * E0`` just above its plane (Kirchhoff / physical optics,
the paper's Eq. 4), which then travels up to the aperture. Sign convention:
``f = +1`` is the paper's "1 on the object"; a perfect metal plate is ``f = -1``.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._validate import as_axis, as_complex_scalar, as_finite_complex, as_position, uniform_step
from . import shapes

__all__ = ["LineTarget", "PlanarTarget", "PointTarget", "cylinder_polarizabilities"]


@dataclass(frozen=True)
class PointTarget:
    """A point scatterer: isotropic (scalar model) or an induced dipole (vector model).

    Parameters
    ----------
    position : (float, float, float)
        (x, y, z) in metres, z its range from the aperture.
    amplitude : complex
        Scattering amplitude (metres): the scattered field is
        ``amplitude * E0 * exp(i*k_n*R)/R`` in the target's medium (scalar
        model); in the vector model the isotropic polarizability ``alpha``.
    polarizability : complex or array_like (3, 3), optional
        The induced dipole's polarizability (metres), ``p = polarizability @ E0``
        in the vector model: a scalar (isotropic, as a sphere) or a 3 x 3 tensor
        in the scene's axes (an elongated or oriented scatterer). Default
        ``amplitude`` times the identity. The scalar model uses ``amplitude``.

    Examples
    --------
    >>> PointTarget((0.0, 0.05, 0.4)).position
    array([0.  , 0.05, 0.4 ])
    >>> PointTarget((0, 0, 0.4), polarizability=np.diag([0, 1e-3, 0])).tensor[1, 1]
    np.complex128(0.001+0j)
    """

    position: np.ndarray
    amplitude: complex = 1.0
    polarizability: object = None

    def __post_init__(self) -> None:
        pos = as_position(self.position, "position")
        if pos[2] <= 0:
            raise ValueError(f"position z must be > 0 (range beyond the aperture), got {pos[2]}")
        object.__setattr__(self, "position", pos)
        object.__setattr__(self, "amplitude", as_complex_scalar(self.amplitude, "amplitude"))
        if self.polarizability is not None:
            try:
                a = np.array(self.polarizability, dtype=complex)
            except (TypeError, ValueError):
                a = np.empty(0, complex)
            if a.shape not in ((), (3, 3)) or not np.all(np.isfinite(a)):
                raise ValueError("polarizability must be a complex number or a 3 x 3 tensor "
                                 f"(metres), got {self.polarizability!r}")
            a.setflags(write=False)
            object.__setattr__(self, "polarizability", a)

    @property
    def tensor(self) -> np.ndarray:
        """The polarizability as a 3 x 3 tensor (metres)."""
        if self.polarizability is None:
            return self.amplitude * np.eye(3, dtype=complex)
        a = np.asarray(self.polarizability)
        return a * np.eye(3, dtype=complex) if a.ndim == 0 else a

    @classmethod
    def sphere(cls, position: object, radius: float, *, frequency: float, eps_ground: complex,
               eps_sphere: complex | None = None) -> PointTarget:
        """A small sphere: the Rayleigh polarizability of radius ``radius`` (metres).

        ``alpha = (k_m a)^2 a (eps_s - eps_m)/(eps_s + 2 eps_m)`` with ``k_m`` the
        wavenumber in the ground (``eps_ground``); a metal sphere
        (``eps_sphere=None``) has ``alpha = (k_m a)^2 a``. Valid while
        ``k_m a`` is well below 1 (a warning beyond 0.5).

        Examples
        --------
        >>> t = PointTarget.sphere((0, 0, 0.4), 0.001, frequency=9.9e9, eps_ground=2.5)
        >>> round(abs(t.amplitude) * 1e6, 2)   # micrometres
        107.63
        """
        a = float(radius)
        if not (np.isfinite(a) and a > 0):
            raise ValueError(f"radius must be a length > 0 in metres, got {radius!r}")
        em = complex(eps_ground)
        km = 2 * np.pi * float(frequency) / 299_792_458.0 * np.sqrt(em)
        if abs(km * a) > 0.5:
            warnings.warn(f"PointTarget.sphere: k_m a = {abs(km * a):.2f}; the Rayleigh "
                          "(dipole) polarizability holds for k_m a << 1", UserWarning,
                          stacklevel=2)
        cm = 1.0 if eps_sphere is None else (complex(eps_sphere) - em) / (
            complex(eps_sphere) + 2 * em)
        return cls(position, complex(km * km * a**3 * cm))


def cylinder_polarizabilities(k_m: complex, radius: float, eps_cylinder: complex | None = None,
                              eps_ground: complex = 1.0) -> tuple[complex, complex]:
    """Polarizabilities per unit length of a long cylinder, along and across its axis.

    From the exact 2-D scattering coefficients of an infinite circular cylinder
    (TM: E along the axis; TE: E across it), summed for the backscatter
    direction and written as the moment per unit length of a line of dipoles,
    whose field is ``i*pi*H0(k_m rho)`` times it:

        along  = (i/pi) sum_n (-1)^n b_n,    across = -(i/pi) sum_n (-1)^n a_n,

    with ``b_n = J_n(x)/H_n(x)``, ``a_n = J_n'(x)/H_n'(x)`` for a perfect
    conductor (``x = k_m a``), and the dielectric forms
    ``b_n = (J_n(mx) J_n'(x) - m J_n'(mx) J_n(x))/(J_n(mx) H_n'(x) - m J_n'(mx) H_n(x))``,
    ``a_n = (m J_n(mx) J_n'(x) - J_n'(mx) J_n(x))/(m J_n(mx) H_n'(x) - J_n'(mx) H_n(x))``,
    ``m = sqrt(eps_c/eps_m)``. A thin metal wire (``x << 1``) answers along its
    axis, ``(i/pi)/(1 + (2i/pi)(ln(x/2) + 0.5772))``, and hardly across it,
    ``3 x^2/4``: the thin-wire law. A bar whose radius is comparable to the
    wavelength in the ground answers both about equally in backscatter (the
    geometric-optics limit of a large cylinder). Dimensionless.

    Examples
    --------
    >>> k0 = 2 * np.pi * 10e9 / 299_792_458.0
    >>> along, across = cylinder_polarizabilities(k0 * np.sqrt(6.0), 0.0005)  # 1 mm wire
    >>> round(float(20 * np.log10(abs(along) / abs(across))), 1)   # dB weaker across
    12.9
    >>> along, across = cylinder_polarizabilities(k0 * np.sqrt(6.0), 0.006)  # 12 mm bar
    >>> round(float(20 * np.log10(abs(along) / abs(across))), 1)
    0.0
    """
    from scipy.special import h1vp, hankel1, jv, jvp

    x = complex(k_m) * float(radius)
    if not (float(radius) > 0):
        raise ValueError(f"radius must be > 0 m, got {radius!r}")
    nmax = int(abs(x) + 4 * abs(x) ** (1 / 3) + 3)
    n = np.arange(-nmax, nmax + 1)
    if eps_cylinder is None:
        b = jv(n, x) / hankel1(n, x)
        a = jvp(n, x) / h1vp(n, x)
    else:
        m = np.sqrt(complex(eps_cylinder) / complex(eps_ground))
        mx = m * x
        b = (jv(n, mx) * jvp(n, x) - m * jvp(n, mx) * jv(n, x)) / (
            jv(n, mx) * h1vp(n, x) - m * jvp(n, mx) * hankel1(n, x))
        a = (m * jv(n, mx) * jvp(n, x) - jvp(n, mx) * jv(n, x)) / (
            m * jv(n, mx) * h1vp(n, x) - jvp(n, mx) * hankel1(n, x))
    sign = (-1.0) ** np.abs(n)
    return complex(1j / np.pi * np.sum(sign * b)), complex(-1j / np.pi * np.sum(sign * a))


@dataclass(frozen=True, eq=False)
class LineTarget:
    """A long thin cylinder (rebar, pipe, wire) from ``start`` to ``end``.

    Parameters
    ----------
    start, end : (float, float, float)
        End points of its axis (x, y, z), metres, z the range from the aperture.
    radius : float
        Cylinder radius, metres.
    eps : complex, optional
        Its permittivity; ``None`` (default) is a perfect conductor (rebar, metal
        pipe). An air-filled pipe or void is ``1.0``.

    Notes
    -----
    It scatters as a row of induced dipoles along its axis, a tenth of the
    wavelength in the ground apart, each with the cylinder's polarizabilities per
    unit length (:func:`cylinder_polarizabilities`) times its share of the length:
    ``alpha = (along t t^T + across (I - t t^T)) dl`` for the axis direction
    ``t``. The scalar model sees the field along the axis. The across-axis
    strength is the backscatter of the 2-D cylinder taken in every direction: the
    row of dipoles reproduces the 2-D field of a thin wire exactly, and a thick
    bar's strength towards the array (its pattern across the axis is not kept).

    Examples
    --------
    >>> rod = LineTarget((0, -0.15, 0.4), (0, 0.15, 0.4), 0.0075)
    >>> round(rod.length, 3), rod.direction.tolist()
    (0.3, [0.0, 1.0, 0.0])
    """

    start: np.ndarray
    end: np.ndarray
    radius: float
    eps: complex | None = None

    def __post_init__(self) -> None:
        a = as_position(self.start, "start")
        b = as_position(self.end, "end")
        if np.allclose(a, b):
            raise ValueError("start and end must differ: a LineTarget needs a length (use a "
                             "PointTarget for a compact object)")
        if min(a[2], b[2]) <= 0:
            raise ValueError("start and end must lie at ranges z > 0 beyond the aperture")
        r = float(self.radius) if np.isscalar(self.radius) else np.nan
        if not (np.isfinite(r) and r > 0):
            raise ValueError(f"radius must be a radius > 0 in metres, got {self.radius!r}")
        object.__setattr__(self, "start", a)
        object.__setattr__(self, "end", b)
        object.__setattr__(self, "radius", r)
        if self.eps is not None:
            object.__setattr__(self, "eps", as_complex_scalar(self.eps, "eps"))

    @property
    def length(self) -> float:
        """Length of the axis, metres."""
        return float(np.linalg.norm(self.end - self.start))

    @property
    def direction(self) -> np.ndarray:
        """Unit vector along the axis, from ``start`` to ``end``."""
        return (self.end - self.start) / self.length

    def dipoles(self, k: float, eps_ground: complex) -> tuple[np.ndarray, np.ndarray]:
        """The row of induced dipoles: positions (M, 3) and polarizabilities (M, 3, 3).

        ``k`` is the wavenumber in air (rad/m), ``eps_ground`` the permittivity
        of the medium that holds the line.
        """
        km = k * np.sqrt(complex(eps_ground))
        lam_m = 2 * np.pi / abs(km)
        m = max(2, int(np.ceil(self.length / (lam_m / 10))))
        dl = self.length / m
        s = (np.arange(m) + 0.5) * dl
        pos = self.start + s[:, None] * self.direction
        along, across = cylinder_polarizabilities(km, self.radius, self.eps, eps_ground)
        t = self.direction
        tt = np.outer(t, t)
        alpha = (along * tt + across * (np.eye(3) - tt)) * dl
        return pos, np.broadcast_to(alpha, (m, 3, 3))


@dataclass(frozen=True, eq=False)
class PlanarTarget:
    """A planar object parallel to the aperture with a reflection coefficient map.

    Parameters
    ----------
    reflectivity : array_like, shape (ny, nx)
        Reflection coefficient f(x, y) (complex allowed; 0 off the object).
    x, y : array_like
        Uniform pixel coordinates of ``reflectivity``, metres.
    z : float
        Range of the object's plane from the aperture, metres (> 0).

    Examples
    --------
    >>> t = PlanarTarget.from_shape("letter_r", z=0.42, width=0.10, height=0.15)
    >>> t.z, round(t.pixel, 6)
    (0.42, 0.002)
    """

    reflectivity: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: float

    def __post_init__(self) -> None:
        f = as_finite_complex(self.reflectivity, "reflectivity", min_ndim=2)
        if f.ndim != 2:
            raise ValueError(f"reflectivity must be 2-D (ny, nx), got shape {f.shape}")
        x = as_axis(self.x, "x", length=f.shape[1])
        y = as_axis(self.y, "y", length=f.shape[0])
        uniform_step(x, "x")
        uniform_step(y, "y")
        try:
            z = float(self.z)
        except (TypeError, ValueError):
            z = np.nan
        if not np.isfinite(z) or z <= 0:
            raise ValueError(f"z must be a range > 0 m, got {self.z!r}")
        f = f.copy()
        for a in (f, x, y):
            a.setflags(write=False)
        object.__setattr__(self, "reflectivity", f)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "z", z)

    @property
    def pixel(self) -> float:
        """Pixel pitch along x, metres (see :attr:`pitch` for both)."""
        return float(self.x[1] - self.x[0])

    @property
    def pitch(self) -> tuple[float, float]:
        """Pixel pitch ``(dx, dy)``, metres."""
        return float(self.x[1] - self.x[0]), float(self.y[1] - self.y[0])

    @classmethod
    def from_mask(cls, mask: np.ndarray, x: np.ndarray, y: np.ndarray, z: float, *,
                  reflection: complex = 1.0) -> PlanarTarget:
        """A planar target that reflects with ``reflection`` where ``mask`` is True.

        Examples
        --------
        >>> u = np.arange(-10, 11) * 0.005
        >>> t = PlanarTarget.from_mask(np.abs(u)[None, :] < 0.03 + 0 * u[:, None], u, u, 0.4,
        ...                            reflection=-1)
        >>> int((t.reflectivity == -1).sum())
        231
        """
        m = np.asarray(mask)
        if m.dtype != bool:
            raise ValueError(f"mask must be a boolean array, got dtype {m.dtype}")
        return cls(m * complex(reflection), x, y, z)

    @classmethod
    def from_shape(cls, shape: str | Callable[..., np.ndarray], z: float, *,
                   center: tuple[float, float] = (0.0, 0.0), reflection: complex = 1.0,
                   pixel: float = 0.002, extent: float | None = None,
                   **size: float) -> PlanarTarget:
        """A planar target from a named shape or a mask function.

        Parameters
        ----------
        shape : {"letter_r", "disk", "ring", "rectangle"} or callable
            Shape name from :mod:`holoradar.model.shapes` or ``f(X, Y, **size)``.
        z : float
            Range, metres.
        center : (float, float)
            Lateral centre (x, y), metres.
        reflection : complex
            Reflection coefficient on the object (+1 paper convention, -1 metal).
        pixel : float
            Pixel pitch, metres (default 2 mm: a sixth of the wavelength in sand
            at 9.9 GHz, so the edges are resolved beyond the imaging band).
        extent : float, optional
            Side of the square grid, metres (default: fits the shape, whose size
            is taken from ``size``; 0.3 m if unknown).
        **size
            Passed to the shape function, e.g. ``diameter=0.11``.
        """
        fn = getattr(shapes, shape) if isinstance(shape, str) else shape
        if not callable(fn):
            raise ValueError(f"shape must be one of {shapes.__all__} or a callable")
        if extent is None:
            dims = [v for v in size.values() if isinstance(v, int | float)]
            extent = 1.1 * max(dims) + 4 * pixel if dims else 0.18
        n = int(np.ceil(extent / pixel)) | 1
        u = (np.arange(n) - n // 2) * pixel
        mask = fn(u[None, :], u[:, None], **size)
        return cls(mask * complex(reflection), u + center[0], u + center[1], z)
