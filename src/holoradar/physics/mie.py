"""A perfectly conducting sphere's scattering amplitudes (Mie): :func:`pec_sphere_amplitudes`.

Bohren & Huffman's convention (time ``exp(-i omega t)``, as everywhere in holoradar):
a plane wave ``E0 exp(i k z)`` scattered by a sphere of radius ``a`` gives, far away in
the direction of scattering angle ``theta`` (from the incident direction),

    E_par  = exp(i k r) / (-i k r) * S2(theta) * E0_par
    E_perp = exp(i k r) / (-i k r) * S1(theta) * E0_perp

``par`` and ``perp`` to the scattering plane (the plane of the incident and scattered
directions), with

    S1 = sum_n (2n+1)/(n(n+1)) (a_n pi_n + b_n tau_n)
    S2 = sum_n (2n+1)/(n(n+1)) (a_n tau_n + b_n pi_n)

``pi_n = P_n^1(cos theta)/sin theta``, ``tau_n = d P_n^1(cos theta)/d theta``, and for a
perfect conductor (the limit of infinite conductivity) ``a_n = psi_n'(x)/xi_n'(x)``,
``b_n = psi_n(x)/xi_n(x)``: ``psi_n(x) = x j_n(x)``, ``xi_n(x) = x h_n^(1)(x)``, the size
parameter ``x = k a`` (``k`` the host medium's wavenumber, complex in a lossy host).
Terms to ``x + 4 x^(1/3) + 2`` (Wiscombe's rule) carry the sum to rounding.

Matching far fields, the sphere scatters as a point dipole of polarisability
``alpha = 4 pi i a^3 S / x^3`` would in that direction: what
:class:`~holoradar.imaging.sphere_response.SphereResponse` uses.
"""

from __future__ import annotations

import numpy as np

from .._lazy import lazy_module

_sp = lazy_module("scipy.special")

__all__ = ["pec_sphere_amplitudes", "pec_sphere_coefficients"]


def pec_sphere_coefficients(x: complex) -> tuple[np.ndarray, np.ndarray]:
    """Mie coefficients ``a_n, b_n`` (n = 1 .. N) of a perfectly conducting sphere.

    Parameters
    ----------
    x : complex
        Size parameter ``k a`` (host wavenumber times radius), ``Re x > 0``.

    Examples
    --------
    >>> a, b = pec_sphere_coefficients(0.01)
    >>> round(float((a[0] / (-2j / 3 * 0.01**3)).real), 4)   # the electric dipole's
    1.0
    """
    x = complex(x)
    if not (np.isfinite(x) and x.real > 0):
        raise ValueError(f"the size parameter k a must be finite with a positive real part, "
                         f"got {x!r}")
    n = np.arange(1, int(abs(x) + 4 * abs(x) ** (1 / 3) + 2) + 1)
    j, dj = _sp.spherical_jn(n, x), _sp.spherical_jn(n, x, derivative=True)
    y, dy = _sp.spherical_yn(n, x), _sp.spherical_yn(n, x, derivative=True)
    h, dh = j + 1j * y, dj + 1j * dy
    psi, dpsi = x * j, j + x * dj          # (x j_n)'
    xi, dxi = x * h, h + x * dh
    return dpsi / dxi, psi / xi


def pec_sphere_amplitudes(x: complex, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``S1(theta), S2(theta)`` of a perfectly conducting sphere of size parameter ``x``.

    Parameters
    ----------
    x : complex
        ``k a``: the host's wavenumber (rad/m, complex where it is lossy) times the
        radius (m).
    theta : array_like
        Scattering angles, radians (0: forward, pi: back towards the source).

    Returns
    -------
    S1, S2 : numpy.ndarray
        Complex, the shape of ``theta``.

    Examples
    --------
    A large sphere sends back what geometric optics says: ``|S(pi)| = x / 2``
    (backscattering cross-section ``pi a^2``).

    >>> S1, S2 = pec_sphere_amplitudes(200.0, np.array([np.pi]))
    >>> round(float(abs(S1[0]) / 100), 2), bool(np.isclose(S1[0], -S2[0]))
    (1.0, True)
    """
    a, b = pec_sphere_coefficients(x)
    mu = np.cos(np.asarray(theta, float))
    S1 = np.zeros(mu.shape, complex)
    S2 = np.zeros(mu.shape, complex)
    pi_prev, pi_n = np.zeros_like(mu), np.ones_like(mu)
    for i in range(a.size):
        n = i + 1
        tau = n * mu * pi_n - (n + 1) * pi_prev
        c = (2 * n + 1) / (n * (n + 1))
        S1 += c * (a[i] * pi_n + b[i] * tau)
        S2 += c * (a[i] * tau + b[i] * pi_n)
        pi_prev, pi_n = pi_n, ((2 * n + 1) * mu * pi_n - (n + 1) * pi_prev) / n
    return S1, S2
