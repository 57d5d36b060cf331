"""Exact transfer through layered ground against an independent transfer-matrix solution.

The reference here is written separately from holoradar's recursion (generalised
reflection / transmission coefficients): the classical characteristic-matrix
method (Born & Wolf, sec. 1.6). The scalar field psi (tangential E) and
phi = Y (a - b), with the admittance Y = kz (TE) or eps/kz (TM), are continuous
across interfaces; over a thickness h a layer maps (psi, phi) by

    [[cos(kz h), i sin(kz h)/Y], [i Y sin(kz h), cos(kz h)]].

A source inside a layer (a plane wave of Weyl's expansion of a point source,
amplitude 1 up and down) makes phi jump by 2 Y there. Both the reflection of
the stack and the fields up and down are obtained by solving these 2 x 2
systems: nothing is shared with holoradar but numpy. The characteristic
matrices grow as exp(|Im(kz) h|), so the cases keep that below ~e^12, where
their round-off (1e-16 e^24 ~ 3e-6 at worst, far less in practice) stays
below the 1e-6 asserted.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import holoradar as hr
from conftest import F0
from holoradar.physics.medium import fresnel

K = 2 * np.pi * F0 / hr.C0

STACKS = {
    # a road: asphalt-like layer over a wet base
    "road": ([0.30, 0.38], [4.0 + 0.2j, 9.0 + 0.9j]),
    # a 2 cm wet layer on sand: strong reverberation
    "wet layer": ([0.30, 0.32], [20.0 + 2.0j, 2.5 + 0.0125j]),
    # a lossy thick layer between two others
    "lossy thick": ([0.30, 0.33, 0.48], [3.0 + 0.05j, 6.0 + 1.5j, 12.0 + 0.5j]),
}
# Propagating in air up to grazing, then evanescent in air (kappa > k).
KAPPAS = K * np.array([0.0, np.sin(np.radians(20)), np.sin(np.radians(45)),
                       np.sin(np.radians(70)), 0.999, 1.2, 1.6])


def _kz(eps: complex, kap: float) -> complex:
    v = np.sqrt(K * K * complex(eps) - kap * kap + 0j)
    return -v if v.imag < 0 else v


def _layer(kz: complex, Y: complex, h: float) -> np.ndarray:
    c, s = np.cos(kz * h), np.sin(kz * h)
    return np.array([[c, 1j * s / Y], [1j * Y * s, c]])


class _Reference:
    """Characteristic-matrix solution of one stack for one kappa and polarisation."""

    def __init__(self, z_if, eps, pol, kap):
        self.z = list(z_if)
        self.eps = [1.0, *eps]
        self.kz = [_kz(e, kap) for e in self.eps]
        self.Y = [kz if pol == "TE" else e / kz for kz, e in zip(self.kz, self.eps, strict=True)]

    def region(self, z):
        return int(np.searchsorted(self.z, z, side="right"))

    def from_below(self, z):
        """(psi, phi) at z of the solution only down-going in the bottom half-space."""
        last = len(self.eps) - 1
        st = np.array([1.0 + 0j, self.Y[last]])  # at the top of the last region
        r = self.region(z)
        if r == last:
            return _layer(self.kz[r], self.Y[r], z - self.z[r - 1]) @ st
        for j in range(last - 1, r, -1):  # up through whole layers to the bottom of r
            st = _layer(self.kz[j], self.Y[j], -(self.z[j] - self.z[j - 1])) @ st
        return _layer(self.kz[r], self.Y[r], -(self.z[r] - z)) @ st

    def from_above(self, z):
        """(psi, phi) at z of the solution only up-going in the air (amplitude 1 at z0)."""
        st = np.array([1.0 + 0j, -self.Y[0]])
        r = self.region(z)
        for j in range(1, r + 1):
            bottom = z if j == r else self.z[j]
            st = _layer(self.kz[j], self.Y[j], bottom - self.z[j - 1]) @ st
        return st

    def reflection_and_down(self, z_air, z):
        """Stack reflection at the surface, and the total field at z for amplitude 1
        travelling down at z_air."""
        s = self.from_below(self.z[0])
        a0 = 0.5 * (s[0] + s[1] / self.Y[0])
        b0 = 0.5 * (s[0] - s[1] / self.Y[0])
        air = np.exp(1j * self.kz[0] * (self.z[0] - z_air))
        return b0 / a0, self.from_below(z)[0] / a0 * air

    def up(self, z_src, z_air):
        """Up-going field at z_air of a source at z_src (primary exp(i kz |z - z_src|))."""
        A, B = self.from_above(z_src), self.from_below(z_src)
        r = self.region(z_src)
        alpha, _ = np.linalg.solve(np.array([[A[0], -B[0]], [-A[1], B[1]]]),
                                   np.array([0.0, 2 * self.Y[r]]))
        return alpha * np.exp(1j * self.kz[0] * (self.z[0] - z_air))


def _depths(z_if):
    """One range in every ground region, and one just below each interface."""
    mids = [0.5 * (a + b) for a, b in itertools.pairwise(z_if)]
    return [*mids, *(z + 1e-4 for z in z_if), z_if[-1] + 0.05]


@pytest.mark.parametrize("pol", ["TE", "TM"])
@pytest.mark.parametrize("name", list(STACKS))
def test_stack_matches_transfer_matrices(name, pol):
    # Reflection, down-going field (with the reflections from below) and the up-going
    # field of a buried source, amplitude and phase to 1e-6 (complex relative error).
    z_if, eps = STACKS[name]
    m = hr.Medium.layered(z_if, eps, polarization=pol)
    z_air = 0.02
    worst = 0.0
    for kap in KAPPAS:
        ref = _Reference(z_if, eps, pol, kap)
        k2 = np.array(kap * kap)
        for z in _depths(z_if):
            R_ref, down_ref = ref.reflection_and_down(z_air, z)
            up_ref = ref.up(z, z_air)
            R = complex(m.reflection(K, k2))
            down = complex(m.vertical_transfer(K, k2, z_air, z))
            up = complex(m.vertical_transfer(K, k2, z, z_air))
            worst = max(worst, abs(R - R_ref) / abs(R_ref), abs(down - down_ref) / abs(down_ref),
                        abs(up - up_ref) / abs(up_ref))
    assert worst < 1e-6


@pytest.mark.parametrize("pol", ["TE", "TM"])
def test_reciprocity_of_up_and_down_transfer(pol):
    # Reciprocity of the Green's function (the TE operator is symmetric; for TM, the H
    # field is, and E_t = H kz/(omega eps0 eps)): the plane-wave transfers obey
    # TE: U kz_0 = D kz_s, TM: U eps_0 kz_s = D eps_s kz_0, with kz_s, eps_s at the
    # buried end. Checked on holoradar's two recursions (up and down are computed
    # separately, without this relation).
    z_if, eps = STACKS["lossy thick"]
    m = hr.Medium.layered(z_if, eps, polarization=pol)
    for z in _depths(z_if):
        s = m.region_of(z)
        k2 = KAPPAS**2
        U = m.vertical_transfer(K, k2, z, 0.0)
        D = m.vertical_transfer(K, k2, 0.0, z)
        kz0, kzs = m.kz(K, k2, 0), m.kz(K, k2, s)
        if pol == "TE":
            lhs, rhs = U * kz0, D * kzs
        else:
            lhs, rhs = U * kzs, D * complex(m.eps[s]) * kz0
        np.testing.assert_allclose(lhs, rhs, rtol=1e-10)


def test_thick_lossy_layer_and_evanescent_waves_stay_finite():
    # 1 m of eps 20 + 10i and strongly evanescent components: exp(-Im(kz) h) ~ e^-900.
    # No overflow; the reverberation is then negligible, so the transfer is the
    # product of the interface transmissions and the phases (first order), to 1e-12.
    m = hr.Medium.layered([0.3, 1.3], [20.0 + 10.0j, 4.0])
    k2 = (K * np.array([0.0, 0.5, 3.0, 5.0])) ** 2
    with np.errstate(over="raise", invalid="raise", divide="raise"):
        U = m.vertical_transfer(K, k2, 1.5, 0.0)
    kz = [m.kz(K, k2, j) for j in range(3)]
    first = (np.exp(1j * kz[2] * 0.2) * fresnel(kz[2], kz[1], 4.0, 20 + 10j)[1]
             * np.exp(1j * kz[1] * 1.0) * fresnel(kz[1], kz[0], 20 + 10j, 1.0)[1]
             * np.exp(1j * kz[0] * 0.3))
    assert np.all(np.isfinite(U))
    np.testing.assert_allclose(U, first, rtol=1e-12, atol=0)


@pytest.mark.parametrize("theta_deg", [0, 30, 45, 60, 85])
@pytest.mark.parametrize("pol", ["TE", "TM"])
def test_tangential_field_is_continuous_and_power_is_conserved(theta_deg, pol):
    # Medium's own coefficients. The tangential E is continuous: t = 1 + r (for TM the
    # old total-field t_p broke this: t/(1 + r) = 0.885, 0.739, 0.535 at 30, 45, 60 deg
    # for eps 1 -> 6). Power across a lossless interface, with the admittance
    # Y = kz (TE) or eps/kz (TM) of S_z = |E_t|^2 Re(Y)/(2 omega mu0 ...):
    # |r|^2 + (Y2/Y1) |t|^2 = 1.
    eps1, eps2 = 1.0, 6.0
    m = hr.Medium.half_space(0.3, eps2, polarization=pol)
    k2 = np.array((K * np.sin(np.radians(theta_deg))) ** 2)
    kz1, kz2 = m.kz(K, k2, 0), m.kz(K, k2, 1)
    r = m.fresnel_reflection(kz1, kz2, eps1, eps2)
    t = m.transmission(kz1, kz2, eps1, eps2)
    np.testing.assert_allclose(t, 1 + r, rtol=1e-14)
    Y1, Y2 = (kz1, kz2) if pol == "TE" else (eps1 / kz1, eps2 / kz2)
    assert abs(abs(r) ** 2 + (Y2 / Y1).real * abs(t) ** 2 - 1) < 1e-12
    # The way back, from the ground into air below the critical angle, conserves it too.
    rb = m.fresnel_reflection(kz2, kz1, eps2, eps1)
    tb = m.transmission(kz2, kz1, eps2, eps1)
    assert abs(abs(rb) ** 2 + (Y1 / Y2).real * abs(tb) ** 2 - 1) < 1e-12
    # ... and the stack's reflection is that same coefficient.
    np.testing.assert_allclose(m.reflection(K, k2), r, rtol=1e-14)
