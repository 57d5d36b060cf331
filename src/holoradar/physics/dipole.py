"""A Hertzian electric dipole in the air: the exact vector source.

Its field is ``amplitude * G(r, r_s) @ moment`` with ``G`` the dyadic Green's
function of the stack (:mod:`holoradar.physics.dyadic`): near and far field,
the TE and TM halves of every plane wave crossing the ground with their own
coefficients. Normalisation: in the air, broadside and far away,
``|E| = |amplitude * moment| / R`` (``4*pi*eps0/k^2`` times the physical field of
a dipole moment; a gprMax ``hertzian_dipole`` of current I and length dl has the
moment ``i*I*dl/omega``, the same up to one complex constant that a fit or a
calibration takes). Positions in metres, z the range from the aperture plane;
time dependence ``exp(-i*omega*t)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_complex_scalar, as_position
from .dyadic import free_space_dyadic, reflected_dyadic, transmitted_dyadic
from .medium import Medium

__all__ = ["Dipole"]


@dataclass(frozen=True, eq=False)
class Dipole:
    """A Hertzian (short) electric dipole in the air.

    Parameters
    ----------
    position : (float, float, float)
        (x, y, z) in metres, z its range from the aperture plane (negative:
        behind it); it must lie above the ground surface.
    moment : (complex, complex, complex)
        Dipole moment (px, py, pz) in the scene's axes; its direction is the
        dipole's axis. A gprMax ``hertzian_dipole`` along y is ``(0, 1, 0)``.
    amplitude : complex, optional
        Complex factor of the whole field (a calibration, or the current's phase).

    Notes
    -----
    :meth:`field_vector` and :meth:`reflected_vector` give the vector field
    (N, 3). The scalar :meth:`field` and :meth:`reflected`, used by the scalar
    model (a hologram without a ``polarization``), give its component along the
    dipole's axis.

    Data across a band are taken to be the field of one fixed moment at every
    frequency, in these units (``4 pi eps0 / k^2`` times the SI field). Which
    normalisation a file holds cannot be told from the data alone (it is a smooth
    amplitude slope across the band, which a fit reads as a wrong permittivity or
    depth); convert before building the hologram, ``f`` in Hz:

    ==================================================  =============================
    what the solver or the instrument gives             divide the field by
    ==================================================  =============================
    SI field of a fixed moment p (SMUTHI, an analytic   ``f**2`` (``k^2``, up to one
    dipole, a MoM code's point source)                  constant)
    field per unit source current, E/I (gprMax's        ``f`` (``p = i I dl / omega``)
    ``hertzian_dipole``, FDTD transfer functions)
    field per unit source voltage through an antenna    the antenna's calibration
    (a VNA's S21 between real antennas)                 (``holoradar.calibrate``)
    already a fixed moment in these units               nothing
    ==================================================  =============================

    One constant factor over the band (the current's phase, ``dl``, ``4 pi eps0``) is
    the object's amplitude and needs no conversion.

    Examples
    --------
    >>> d = Dipole((-0.2, 0.0, 0.2), moment=(0, 1, 0))
    >>> E = d.field_vector(207.0, Medium.free_space(), np.array([[-0.2, 0.0, 1.2]]))
    >>> np.round(np.abs(E[0]), 4)   # broadside, 1 m away: |E| = |p|/R along p
    array([0., 1., 0.])
    """

    position: np.ndarray
    moment: np.ndarray
    amplitude: complex = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", as_position(self.position, "position"))
        try:
            p = np.array(self.moment, dtype=complex)
        except (TypeError, ValueError):
            p = np.empty(0, complex)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValueError("moment must be three finite components (px, py, pz) of the "
                             f"dipole moment, e.g. (0, 1, 0) for a dipole along y, got "
                             f"{self.moment!r}")
        if not np.any(p):
            raise ValueError("moment must not be zero: a dipole without a moment radiates "
                             "nothing (give its direction, e.g. (0, 1, 0))")
        p.setflags(write=False)
        object.__setattr__(self, "moment", p)
        object.__setattr__(self, "amplitude", as_complex_scalar(self.amplitude, "amplitude"))

    @property
    def polarization(self) -> np.ndarray:
        """Unit vector along the dipole's axis (real when the moment's components share a
        phase; otherwise the direction of its real part, or of its imaginary part)."""
        p = self.moment * np.exp(-1j * np.angle(self.moment[np.argmax(np.abs(self.moment))]))
        v = p.real if np.any(p.real) else p.imag
        return v / np.linalg.norm(v)

    # What the scalar glare methods ask of a radiator: it has a pattern (:meth:`pattern`).
    has_pattern = True

    def _check_air(self, medium: Medium) -> None:
        if not medium.is_free_space and self.position[2] >= medium.z_interfaces[0]:
            raise ValueError(f"Dipole position z={self.position[2]} m must lie above the "
                             f"ground surface at z={medium.z_interfaces[0]} m")

    def field_vector(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """Incident (down-going) field (N, 3) at ``points`` (N, 3): the direct wave in the
        air, the wave transmitted through the stack in the ground."""
        self._check_air(medium)
        pts = np.atleast_2d(np.asarray(points, float))
        out = np.empty((len(pts), 3), complex)
        below = pts[:, 2] >= self.position[2]
        buried = below & (np.asarray(medium.region_of(pts[:, 2])) > 0)
        direct = ~buried
        if np.any(direct):
            out[direct] = free_space_dyadic(k, self.position, pts[direct]) @ self.moment
        if np.any(buried):
            out[buried] = transmitted_dyadic(k, medium, self.position, pts[buried]) @ self.moment
        return self.amplitude * out

    def reflected_vector(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """The ground's reflection of the dipole's field (N, 3) at air ``points`` (the glare)."""
        self._check_air(medium)
        pts = np.atleast_2d(np.asarray(points, float))
        if medium.is_free_space:
            return np.zeros((len(pts), 3), complex)
        return self.amplitude * (reflected_dyadic(k, medium, self.position, pts) @ self.moment)

    def field(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """The scalar model's incident field: :meth:`field_vector` along the dipole's axis."""
        return self.field_vector(k, medium, points) @ self.polarization

    def reflected(self, k: float, medium: Medium, points: np.ndarray) -> np.ndarray:
        """The scalar model's glare: :meth:`reflected_vector` along the dipole's axis."""
        return self.reflected_vector(k, medium, points) @ self.polarization

    def mirror_position(self, medium: Medium) -> np.ndarray:
        """The mirror image in the surface: range ``2*z0 - z_s``.

        Examples
        --------
        >>> Dipole((0, 0, 0.1), moment=(0, 1, 0)).mirror_position(Medium.half_space(0.3, 4.0))
        array([0. , 0. , 0.5])
        """
        self._check_air(medium)
        if medium.is_free_space:
            raise ValueError("a free-space medium has no surface and no mirror image")
        z0 = medium.z_interfaces[0]
        return np.array([self.position[0], self.position[1], 2 * z0 - self.position[2]])

    def pattern(self, directions: np.ndarray) -> np.ndarray:
        """Far-field amplitude along unit ``directions`` (N, 3): ``|p x d|/|p|`` (the scalar
        glare methods' view of the dipole)."""
        p = self.polarization
        return np.linalg.norm(np.cross(np.asarray(directions, float), p), axis=1)
