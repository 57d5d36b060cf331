"""The paraxial Fresnel kernel against a Gaussian beam's complex-q field.

Closed form (time dependence ``exp(-i omega t)``, docs/conventions.md). A Gaussian beam
with its waist ``w0`` at some plane has, a (reduced) distance ``s`` from it along its
travel,

    u(r, s) = (q0 / q(s)) exp(i k r^2 / (2 q(s))) exp(i phi),   q(s) = s + q0,
    q0 = -i zR,   zR = k w0^2 / 2,

``phi`` the plane wave's phase, ``q0/q`` the amplitude and Gouy phase. The Fresnel
integral of such a field is exactly that law: ``int (k/(2 pi i L)) exp(i k |x - x'|^2 /
(2 L)) exp(i k x'^2 / (2 q)) dA' = (q / (q + L)) exp(i k x^2 / (2 (q + L)))`` for any
complex ``q`` and real ``L`` (of either sign). So holoradar's Fresnel kernel
``T0 (k / (2 pi i L)) exp(i k r^2 / (2 L)) dx dy`` (:class:`holoradar.Fresnel`) must
carry a Gaussian field to the beam's field with no paraxial error at all: the only
differences are the grid's (below, for each test).

Through a ground of index n at normal incidence (:meth:`Medium.half_space`): the field
is continuous across the surface (times the transmission ``t``), so its curvature is:
``exp(i k r^2/(2 q_air)) = exp(i n k r^2/(2 q_ground))``, ``q_ground = n q_air``, and
in the ground ``q_ground`` grows by the depth travelled. Written in air's terms,
``q_ground / n`` grows by depth / n: the beam keeps the air law with the distance in
the ground divided by n, the apparent distance ``L = z0 + d/n``
(:meth:`Medium.apparent_distance`, docs/imaging.md), while the phase runs with the
optical path ``z0 + n d`` and the amplitude ``q0/q`` is unchanged (``n`` cancels in
``q_ground(0) / q_ground``). ``T0`` is the normal-incidence transfer ``t exp(i k (z0 +
n d))``.

Migration (``migrate(..., method="fresnel")``) applies the adjoint: ``conj(T0)`` and
the kernel with ``-L``, i.e. back-propagation. The field that a beam travelling up from
a waist at range ``z_w`` leaves on the aperture is thereby carried back to the beam's
own field at every range in air, and to ``|t|^2`` times it in the ground (the adjoint
multiplies by ``conj(t)`` where the inverse would divide by ``t``).

These laws are the paraxial limit of the exact propagation; the last test checks that
against the exact angular spectrum, to the paraxial error.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import erf

import holoradar as hr

F0 = 9.9e9
K = 2 * np.pi * F0 / hr.C0
LAM = hr.C0 / F0
W0 = 2 * LAM                    # the waist radius (1/e of the field): k w0 = 4 pi
ZR = K * W0**2 / 2              # Rayleigh range, 0.38 m
Q0 = -1j * ZR
N, PITCH = 129, 0.006           # 0.77 m, odd: a sample on the axis; pitch < lambda/5
X = (np.arange(N) - (N - 1) / 2) * PITCH
R2 = X[None, :] ** 2 + X[:, None] ** 2
HALF = N * PITCH / 2            # the aperture's half-width (edge of the outermost cell)

FREE = hr.Medium.free_space()
N_GROUND = 2.0
GROUND = hr.Medium.half_space(0.20, N_GROUND**2)
# The transmission of the tangential field from the ground up into air at normal
# incidence (theory, independent of the propagators): 2 n / (n + 1) = 4/3.
T_UP = complex(hr.theory.fresnel_coefficients(N_GROUND**2, 1.0)["t_te"])

# (medium, the waist's range, the image planes, the transmission the way up crosses)
CASES = {
    "free space": (FREE, 0.50, np.array([0.30, 0.40, 0.50, 0.60, 0.70]), 1.0),
    # waist 40 cm deep: apparent distance 0.2 + 0.4/2 = 0.4 m; planes at L = 0.275 .. 0.525
    "half-space": (GROUND, 0.60, np.array([0.35, 0.475, 0.60, 0.725, 0.85]), T_UP),
}


def _beam(q: complex, phase: float) -> np.ndarray:
    """``(q0/q) exp(i k r^2/(2 q)) exp(i phase)`` on the grid."""
    return (Q0 / q) * np.exp(1j * K * R2 / (2 * q)) * np.exp(1j * phase)


def _transfer(medium: hr.Medium, z: float, t_up: complex) -> complex:
    """``T0`` in closed form: the transmission where z lies in the ground, and the
    optical path ``z0 + n d`` (or z in air)."""
    inside = not medium.is_free_space and z > medium.z_interfaces[0]
    path = medium.z_interfaces[0] + N_GROUND * (z - medium.z_interfaces[0]) if inside else z
    return (t_up if inside else 1.0) * np.exp(1j * K * path)


def _grid_error(q_data: complex, L: float, q_out: complex) -> float:
    """Bound on the grid's error, relative to the result's peak ``|q0/q_out|``.

    The FFT convolution on a padded grid (>= 2N - 1) is the exact discrete linear
    convolution, and the sum over samples equals the integral to terms ``exp(-(2 pi/dx -
    kappa)^2 ...)`` (Poisson) that are negligible here: the integrand is a complex
    Gaussian whose local wavenumbers stay below pi/dx. What is missing is the data the
    sum does not see: beyond the aperture (``|x| > D/2``), and beyond the kernel's cut,
    ``|x - x'| > lambda L / (2 dx)`` (where its chirp would alias), which for the
    outermost pixel removes the data beyond ``c - D/2``. Both lie outside a square of
    half-width ``rho = min(D/2, lambda L/(2 dx) - D/2)``. The data's modulus is
    ``|q0/q_data| exp(-r^2/w^2)``, ``w^2 = 2 |q_data|^2/(k zR)``, the kernel's
    ``k/(2 pi L)``, so the missing part is at most ``(k/(2 pi L)) |q0/q_data| pi w^2
    (1 - erf(rho/w)^2)``: over the peak, ``(|q_data| |q_out| / (zR L)) (1 - erf(rho/
    w)^2)``. The samples approximate the integral over the aperture by the midpoint rule,
    whose end correction (Euler-Maclaurin, ``dx^2 f'/24`` at the edges, ``f' ~ 2 (D/2)
    f / w^2``) is a share ``(dx D/2)^2 / (6 w^4)`` of that tail (~1 %): the bound is
    multiplied by one plus it. Double precision's rounding (1e-15 per FFT pass) is added
    as 1e-12.
    """
    L = abs(L)
    w = np.sqrt(2 * abs(q_data) ** 2 / (K * ZR))
    rho = min(HALF, LAM * L / (2 * PITCH) - HALF)
    assert rho > 3 * w, "the geometry must keep the data's tails out of the kernel's cut"
    tail = abs(q_data) * abs(q_out) / (ZR * L) * (1 - erf(rho / w) ** 2)
    return tail * (1 + (PITCH * HALF) ** 2 / (6 * w**4)) + 1e-12


def _compare(got: np.ndarray, want: np.ndarray, tol: float, what: str) -> None:
    """Complex field (amplitude and phase together) within ``tol`` of the peak; the phase
    on the beam's core (|want| > 1/e of its peak) within ``e * tol`` radians (a
    deviation ``tol * peak`` turns a field of at least peak/e by at most that)."""
    peak = np.max(np.abs(want))
    err = float(np.max(np.abs(got - want)) / peak)
    assert err <= tol, f"{what}: largest difference {err:.3g} of the peak (bound {tol:.3g})"
    core = np.abs(want) > peak / np.e
    dphi = float(np.max(np.abs(np.angle(got[core] / want[core]))))
    assert dphi <= np.e * tol, f"{what}: phase off by {dphi:.3g} rad on the beam's core"
    # On the axis (r = 0) the phase is the plane wave's plus the Gouy phase arg(q0/q).
    c = N // 2
    assert abs(np.angle(got[c, c] / want[c, c])) <= np.e * tol, what


@pytest.mark.parametrize("case", CASES)
def test_forward_kernel_carries_the_waist_to_the_aperture(case):
    """``Fresnel.forward`` from the waist's plane (the field ``exp(-r^2/w0^2)``, q = q0)
    up to the aperture: ``T0 (q0/(q0 + L)) exp(i k r^2/(2 (q0 + L)))``, ``L`` the waist's
    apparent distance."""
    medium, z_w, _, t_up = CASES[case]
    L = medium.apparent_distance(z_w)
    op = hr.Fresnel((N, N), PITCH, PITCH, K, [z_w], None if medium is FREE else medium,
                    True)
    got = op.forward(_beam(Q0, 0.0)[None])
    want = _transfer(medium, z_w, t_up) * _beam(Q0 + L, 0.0)
    _compare(got, want, _grid_error(Q0, L, Q0 + L), f"{case}, forward from {z_w} m")


@pytest.mark.parametrize("case", CASES)
def test_fresnel_migration_rebuilds_the_beam_around_its_waist(case):
    """A beam travelling up from its waist at ``z_w`` leaves ``T0(z_w) (q0/q_a) exp(i k
    r^2/(2 q_a))`` on the aperture, ``q_a = L_w + q0``; ``migrate(method="fresnel")`` to a
    plane at apparent distance ``L`` gives ``conj(T0(z)) T0(z_w) (q0/(q_a - L)) exp(i k
    r^2/(2 (q_a - L)))``: the beam's own field there (times ``|t|^2`` in the ground),
    narrowing to ``w0`` at the waist and widening beyond it."""
    medium, z_w, zs, t_up = CASES[case]
    Lw = medium.apparent_distance(z_w)
    qa = Lw + Q0
    h = hr.Hologram(_transfer(medium, z_w, t_up) * _beam(qa, 0.0), X, X, F0)
    img = hr.migrate(h, zs, medium=None if medium is FREE else medium, method="fresnel",
                     dtype=np.complex128)
    assert img.method.startswith("fresnel")
    for i, z in enumerate(zs):
        L = medium.apparent_distance(float(z))
        want = (np.conj(_transfer(medium, float(z), t_up)) * _transfer(medium, z_w, t_up)
                * _beam(qa - L, 0.0))
        _compare(img.data[i], want, _grid_error(qa, L, qa - L), f"{case}, plane {z} m")
    # The beam's waist is where the closed form puts it: the narrowest plane is z_w.
    widths = [np.sum(np.abs(p) ** 2 * R2) / np.sum(np.abs(p) ** 2) for p in img.data]
    assert zs[int(np.argmin(widths))] == z_w


@pytest.mark.parametrize("case", CASES)
def test_closed_form_is_the_paraxial_limit_of_the_exact_propagation(case):
    """The same forward step by the exact angular spectrum (:class:`holoradar.
    AngularSpectrum`: every plane wave with its own ``kz`` and Fresnel transmission)
    differs from the closed form by the paraxial error only.

    The waist's angular spectrum is ``exp(-kappa^2 w0^2/4)``; over it ``<kappa^2> =
    4/w0^2`` and ``<kappa^4> = 32/w0^4``. ``kz = n k - kappa^2/(2 n k) - kappa^4/(8 n^3
    k^3)``: the paraxial law keeps the first two, so each component's phase errs by
    ``kappa^4 h/(8 n^3 k^3)`` over a height h in index n, and on the peak by at most
    ``<kappa^4> sum h_j/(8 n_j^3 k^3) = 4 k (z0 + d/n^3) / (k w0)^4`` (1.7 % in free
    space over 0.5 m, 0.8 % here through the ground). In the ground the transmission
    varies with angle: ``t(kappa) = 2 kz_g/(kz_g + kz_a) = t(0) (1 + kappa^2 (n - 1)/(2
    n^2 k^2) + ...)``, at most ``<kappa^2> (n - 1)/(2 n^2 k^2) = 2 (n - 1)/(n k w0)^2``
    (0.3 %). Their sum is the tolerance (and the grid's bound, ~1e-12, besides).
    """
    medium, z_w, _, t_up = CASES[case]
    L = medium.apparent_distance(z_w)
    med = None if medium is FREE else medium
    got = hr.AngularSpectrum((N, N), PITCH, PITCH, K, [z_w], med, True).forward(
        _beam(Q0, 0.0)[None])
    want = _transfer(medium, z_w, t_up) * _beam(Q0 + L, 0.0)
    z0 = z_w if medium is FREE else medium.z_interfaces[0]
    d = 0.0 if medium is FREE else z_w - z0
    n = 1.0 if medium is FREE else N_GROUND
    quartic = 4 * K * (z0 + d / n**3) / (K * W0) ** 4
    transmission = 2 * (n - 1) / (n * K * W0) ** 2
    tol = quartic + transmission + _grid_error(Q0, L, Q0 + L)
    err = float(np.max(np.abs(got - want)) / np.max(np.abs(want)))
    assert err <= tol, f"{case}: exact against paraxial {err:.3g} (bound {tol:.3g})"
    # And it is a paraxial error, not nothing: the kernel test above is the sharper one.
    assert err > 1e-4
