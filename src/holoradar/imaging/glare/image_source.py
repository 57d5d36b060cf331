"""The image-source fit of the glare (``method="image_source"``).

The exact reflected field of the radiator from the layered ground, with the
ground's permittivity fitted (:func:`_fit_image_source`), and the sandwich
estimate of its uncertainty under a spatially correlated residual
(:func:`_sandwich_std`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..._lazy import lazy_module
from ...physics.medium import Medium
from ._common import _require_direct_wave
from .report import GlareFit
from .spot import MirrorSpot

# Imported on first use (holoradar._lazy): `import holoradar` should cost little more
# than numpy.
sfft = lazy_module("scipy.fft")
_opt = lazy_module("scipy.optimize")


def _sandwich_std(fun: np.ndarray, jac: np.ndarray, shape: tuple[int, int]
                  ) -> tuple[float, float]:
    """1-sigma of least-squares parameters when the residual is spatially correlated.

    What the glare model leaves is mostly the object's own field and the noise:
    smooth over the aperture, not white, so ``s^2 (J^T J)^-1`` would be far too
    optimistic. The sandwich (Huber-White / Newey-West) estimator
    ``B^-1 M B^-1``, ``B = Re(J^H J)``, ``M = Cov(Re(J^H r)) = Re(J^H S J)/2`` for a
    circular complex residual, uses the residual's covariance S, taken stationary
    and estimated from its autocorrelation over the aperture with a Bartlett lag
    window reaching half the aperture (Newey & West 1987): the raw all-lag
    estimate would give ``J^H S J ~ |J^H r|^2``, which vanishes at the fit.
    """
    n = fun.size // 2
    r = (fun[:n] + 1j * fun[n:]).reshape(shape)
    J = (jac[:n] + 1j * jac[n:]).reshape((*shape, -1))
    ny, nx = shape
    s = (2 * ny, 2 * nx)
    acf = sfft.ifft2(np.abs(sfft.fft2(r, s=s)) ** 2) / r.size  # lags in FFT order
    ly, lx = max(ny / 2, 2.0), max(nx / 2, 2.0)
    ty = np.abs(sfft.fftfreq(s[0], 1.0 / s[0]))
    tx = np.abs(sfft.fftfreq(s[1], 1.0 / s[1]))
    bartlett = np.outer(np.clip(1 - ty / ly, 0, None), np.clip(1 - tx / lx, 0, None))
    acf_spec = sfft.fft2(acf * bartlett)
    SJ = sfft.ifft2(sfft.fft2(J, s=s, axes=(0, 1)) * acf_spec[..., None], axes=(0, 1))
    SJ = SJ[:ny, :nx]
    Jf = J.reshape(-1, J.shape[-1])
    meat = 0.5 * np.real(Jf.conj().T @ SJ.reshape(-1, J.shape[-1]))
    bread = np.real(Jf.conj().T @ Jf)
    try:
        binv = np.linalg.inv(bread)
    except np.linalg.LinAlgError:
        return np.inf, np.inf
    cov = binv @ meat @ binv
    return float(np.sqrt(max(cov[0, 0], 0))), float(np.sqrt(max(cov[1, 1], 0)))


def _model_error_bound(fun: np.ndarray, jac: np.ndarray, shape: tuple[int, int]
                       ) -> tuple[float, float]:
    """Largest shift of each parameter that the residual's smooth part could cause.

    Receiver noise is white over the aperture; what the model misses (a vector field
    seen as a scalar one, a layered ground seen as a half-space, a solver's own
    dispersion) is smooth from element to element. Its energy ``E_err``
    (:func:`~holoradar.data.noise.smooth_residual_energy`), were it aligned with
    the worst direction, moves parameter j by ``sqrt(E_err [(J^T J)^-1]_jj)``
    (least squares, J the residual's Jacobian). Zero when the residual is white.
    """
    from ...data.noise import smooth_residual_energy

    n = fun.size // 2
    e_err = smooth_residual_energy((fun[:n] + 1j * fun[n:]).reshape(shape))
    if e_err == 0:
        return 0.0, 0.0
    try:
        inv = np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        return np.inf, np.inf
    d = np.sqrt(np.clip(np.diag(inv), 0, None) * e_err)
    return float(d[0]), float(d[1])


def _fit_image_source(spot: MirrorSpot, medium: Medium, ref: complex | None,
                      initial: dict[str, Any] | None):
    """Fit the ground's permittivity from the exact reflected field.

    The glare's strength relative to the radiator's fixes |V|: the radiator's
    amplitude is either fitted jointly with the direct wave (one complex amplitude
    for both, since both are its fields: the direct path is the reference) or
    given (``ref``, a calibration). Fitting it freely for the glare alone would
    leave eps to the weak angle dependence of V across the aperture.

    With ``pol`` (the recorded component) the glare is the vector field of the
    radiator reflected by the stack, its TE and TM waves each with their own
    coefficients (:func:`holoradar.physics.dyadic.reflected_dyadic`).
    """
    k, src, pts, h, D, pol = spot.k, spot.src, spot.pts, spot.h, spot.D, spot.pol

    def transform(v: np.ndarray) -> np.ndarray:
        return v.reshape(spot.shape)

    eps0 = complex(initial["eps"]) if initial and "eps" in initial else complex(medium.eps[1])

    def glare_of(e: np.ndarray) -> np.ndarray:
        eps = complex(max(e[0], 1e-3), max(e[1], 0.0))
        m = Medium(medium.z_interfaces, (1.0, eps, *medium.eps[2:]), medium.polarization)
        unit = replace(src, amplitude=1.0)
        if pol is not None:
            return unit.reflected_vector(k, m, pts) @ pol
        return unit.reflected(k, m, pts)

    th = transform(h)
    tD = None if D is None else transform(D)

    def parts(e: np.ndarray) -> tuple[complex, np.ndarray, np.ndarray]:
        G = glare_of(e)
        tG = transform(G)
        if tD is not None and ref is None:
            basis = tD + tG
            a = complex(np.vdot(basis, th) / np.vdot(basis, basis))
        else:
            a = complex(ref if ref is not None else src.amplitude)
        return a, G, tG

    def resid(e: np.ndarray) -> np.ndarray:
        a, _, tG = parts(e)
        r = (th - a * tG - (0 if tD is None else a * tD)).ravel()
        return np.concatenate([r.real, r.imag])

    e_start = np.array([eps0.real, max(eps0.imag, 0.0)])
    sol = _opt.least_squares(resid, e_start, x_scale=np.array([0.1, 0.01]) * max(e_start[0], 1.0),
                             bounds=([1e-3, 0.0], [np.inf, np.inf]), xtol=1e-12, max_nfev=200)
    a, G, _ = parts(sol.x)
    noise_std = _sandwich_std(sol.fun, sol.jac, th.shape)
    bias = _model_error_bound(sol.fun, sol.jac, th.shape)
    # The stated 1-sigma covers noise (sandwich) and, through bias/1.96, the largest shift
    # the residual's smooth part (model error) could cause: +-1.96 sigma holds both.
    std = (noise_std[0] + bias[0] / 1.96, noise_std[1] + bias[1] / 1.96)
    eps = complex(sol.x[0], sol.x[1])
    explained = 1 - np.sum(sol.fun**2) / max(np.sum(np.abs(h) ** 2), 1e-300)
    fit = {"eps": eps, "eps_std": std, "eps_noise_std": noise_std, "eps_model_bias": bias,
           "a": a,
           "converged": bool(sol.success and explained > 0.5)}
    dcoef = None if D is None else a
    return a * G, (np.zeros_like(h) if D is None else a * D), dcoef, fit


def remove_image_source(spot: MirrorSpot, medium: Medium, reference_amplitude: complex | None,
                        initial: dict[str, Any] | None) -> GlareFit:
    """The ``"image_source"`` method: the exact reflected field fitted (the ground's
    permittivity and, with the direct wave as reference, the radiator's amplitude)
    and removed.

    Examples
    --------
    Through :func:`holoradar.suppress_surface` (``method="image_source"``) or
    :func:`holoradar.estimate_permittivity`.
    """
    if spot.D is not None:
        _require_direct_wave(spot.D, spot.h)
    glare, direct_part, dcoef, fit = _fit_image_source(spot, medium, reference_amplitude,
                                                       initial)
    report = {"mirror_position": tuple(spot.src.mirror_position(medium)),
              "amplitude": fit["a"], "phase": float(np.angle(fit["a"])),
              "eps": fit["eps"], "eps_std": fit["eps_std"]}
    return GlareFit(glare, direct_part, dcoef, fit["converged"], fit, report)
