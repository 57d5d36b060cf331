"""Parabolic-equation propagation through a smoothly stratified ground (split-step Fourier).

Below the surface the field is ``E = u(x, y, z) exp(i k int n dz)`` with a slowly
varying amplitude ``u`` that obeys the paraxial (parabolic) wave equation of a
medium whose index ``n(z)`` changes with depth,

    i k (2 n du/dz + n' u) + d2u/dx2 + d2u/dy2 = 0,

and the scattered waves going up obey its complex conjugate. For each plane-wave
component ``(p, q)``, ``kappa^2 = p^2 + q^2``, it is an ordinary differential
equation in z whose solution carries the component from ``z_a`` to ``z_b`` as

    exp(i k int n dz) * sqrt(n(z_a)/n(z_b)) * exp(-i kappa^2/(2k) int dz/n),

the square root being the amplitude factor from ``n'`` (the energy flux of a wave
whose speed changes). The split-step solution takes steps ``dz`` through the
profile, each with the index at its middle (the midpoint rule: the phase error
falls as ``dz^2``, measured by the tests); in a stratified ground the diffraction
step of each slab is one multiplication of the angular spectrum, so the whole
stack costs one forward and one inverse FFT.

``wide_angle=True`` replaces the paraxial phase ``k n - kappa^2/(2 k n)`` of each
slab by the exact one-way phase ``kz = sqrt(k^2 n^2 - kappa^2)`` and the amplitude
factor by ``sqrt(kz_a/kz_b)`` (the WKB form of the transverse-electric
transmission through many thin layers): for a stratified medium this is the
limit of the wide-angle (Pade) expansions of the square-root operator, exact in
angle; what it leaves out, like the paraxial form, is the weak reflection of
the gradient itself.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._lazy import lazy_module
from .medium import Medium

sfft = lazy_module("scipy.fft")  # imported on first use: see holoradar._lazy

__all__ = ["ParabolicEquation"]


class ParabolicEquation:
    """Split-step propagation of a field between two depths of a stratified ground.

    Parameters
    ----------
    shape : (int, int)
        Field shape (ny, nx).
    pitch : (float, float)
        Sample spacing (dx, dy), metres.
    k : float
        Wavenumber in air, rad/m.
    medium : Medium
        The ground (e.g. :meth:`Medium.graded`); its index at each step's middle
        is used.
    z_from, z_to : float
        Ranges from the aperture, metres, both at or below the surface,
        ``z_to > z_from``.
    step : float, optional
        Step, metres (> 0, at most ``z_to - z_from``), the index taken at each
        step's middle (second order in the step); the last step is shortened to
        end at ``z_to``. Default: the medium's own layers (each step one layer,
        whose index it then takes exactly: for :meth:`Medium.graded`, the
        profile as sampled).
    wide_angle : bool
        Exact one-way phase per slab instead of the paraxial one (module text).

    Notes
    -----
    ``forward`` carries a field at ``z_from`` down to ``z_to``; ``adjoint`` is its
    adjoint (back-propagation with the complex-conjugate equation), ``<A x, y> =
    <x, A^H y>`` (dot test in the tests). The field is periodic over the grid (pad
    it for a field that reaches the edges). Evanescent components
    (``kappa > k n``) are dropped in the wide-angle form.

    Examples
    --------
    >>> wet = Medium.graded(0.30, lambda d: 3.0 + 20.0 * d, 0.30)
    >>> pe = ParabolicEquation((64, 64), (0.005, 0.005), 2 * np.pi / 0.0303, wet, 0.30,
    ...                        0.50, step=0.002)
    >>> u = np.zeros((64, 64), complex); u[32, 32] = 1.0
    >>> v = pe.forward(u)
    >>> round(float(np.vdot(pe.forward(u), v).real / np.vdot(u, pe.adjoint(v)).real), 12)
    1.0
    """

    def __init__(self, shape: tuple[int, int], pitch: tuple[float, float], k: float,
                 medium: Medium, z_from: float, z_to: float, *, step: float | None = None,
                 wide_angle: bool = False) -> None:
        ny, nx = (int(s) for s in shape)
        dx, dy = (float(p) for p in pitch)
        if ny < 1 or nx < 1 or not (dx > 0 and dy > 0):
            raise ValueError(f"shape must be positive and pitch > 0 m, got {shape}, {pitch}")
        if not isinstance(medium, Medium) or medium.is_free_space:
            raise ValueError("medium must be a holoradar.Medium with a ground")
        z0 = medium.z_interfaces[0]
        za, zb = float(z_from), float(z_to)
        if not (np.isfinite(za) and np.isfinite(zb) and z0 <= za < zb):
            raise ValueError(f"z_from, z_to must satisfy surface ({z0} m) <= z_from < z_to, got "
                             f"{z_from!r}, {z_to!r}")
        h = (zb - za) if step is None else float(step)
        if not (np.isfinite(h) and 0 < h <= zb - za):
            raise ValueError(f"step must be > 0 and at most z_to - z_from ({zb - za} m), got "
                             f"{step!r}")
        self.shape, self.k, self.medium = (ny, nx), float(k), medium
        self.z_from, self.z_to, self.wide_angle = za, zb, bool(wide_angle)
        self.step = None if step is None else h
        p = 2 * np.pi * sfft.fftfreq(nx, dx)
        q = 2 * np.pi * sfft.fftfreq(ny, dy)
        self.kappa2 = q[:, None] ** 2 + p[None, :] ** 2
        self.transfer = self._transfer()

    def index(self, z: np.ndarray) -> np.ndarray:
        """The ground's refractive index ``sqrt(eps)`` at ranges ``z`` (Im >= 0)."""
        edges = np.asarray(self.medium.z_interfaces)
        region = np.searchsorted(edges, np.asarray(z, float), side="right")
        n = np.sqrt(np.asarray(self.medium.eps, complex)[region])
        return np.where(n.imag < 0, -n, n)

    def _transfer(self) -> np.ndarray:
        """The product of the split steps: one multiplier per angular component."""
        k = self.k
        if self.step is None:  # the medium's own layers: one step each
            inner = [z for z in self.medium.z_interfaces if self.z_from < z < self.z_to]
            bounds = np.array([self.z_from, *inner, self.z_to])
        else:
            h = self.step
            bounds = np.append(np.arange(self.z_from, self.z_to - 1e-9 * h, h), self.z_to)
        mids = 0.5 * (bounds[1:] + bounds[:-1])
        dz = np.diff(bounds)
        n = self.index(mids)
        # the amplitude factor sqrt(n(z_a)/n(z_b)) at the ends themselves (taking it at
        # the first and last steps' middles would cost an error of first order in h)
        n_a = self.index(np.array([self.z_from]))[0]
        n_b = self.index(np.array([self.z_to - 1e-12]))[0]
        kap2 = self.kappa2
        if not self.wide_angle:
            phase = k * np.sum(n * dz) - kap2 / (2 * k) * np.sum(dz / n)
            amp = np.sqrt(n_a / n_b)
            return amp * np.exp(1j * phase)
        # The phase depends on kappa^2 only: sum the slabs once per distinct value (a
        # square grid holds about an eighth as many) and spread the result.
        values, where = np.unique(kap2, return_inverse=True)
        total = np.zeros(values.shape, complex)
        for nj, dj in zip(n, dz, strict=True):
            total += np.sqrt(k * k * nj * nj - values + 0j) * dj
        kz_a = np.sqrt(k * k * n_a**2 - values + 0j)
        kz_b = np.sqrt(k * k * n_b**2 - values + 0j)
        keep = values < (k * min(n.real)) ** 2
        amp = np.sqrt(np.where(keep, kz_a, 1) / np.where(keep, kz_b, 1))
        return np.where(keep, amp * np.exp(1j * total), 0)[where].reshape(kap2.shape)

    def _apply(self, u: Any, mult: np.ndarray) -> np.ndarray:
        a = np.asarray(u, complex)
        if a.shape[-2:] != self.shape:
            raise ValueError(f"field must have shape (..., {self.shape[0]}, {self.shape[1]}), "
                             f"got {a.shape}")
        return sfft.ifft2(sfft.fft2(a) * mult)

    def forward(self, u: Any) -> np.ndarray:
        """The field at ``z_to`` of the field ``u`` at ``z_from`` (..., ny, nx)."""
        return self._apply(u, self.transfer)

    def adjoint(self, v: Any) -> np.ndarray:
        """The adjoint: back-propagation from ``z_to`` to ``z_from`` with the conjugate
        equation (the FFT pair is unitary up to the factor it cancels)."""
        return self._apply(v, np.conj(self.transfer))
