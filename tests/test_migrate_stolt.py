"""``migrate(..., algorithm="stolt")``: the kz-resampling route, its error bound and
where it refuses.

Stolt's step replaces each propagating plane wave ``A_f exp(-i theta_f j)`` that every
plane needs by cubic interpolation between four nodes of a uniform phase grid
(``OVERSAMPLE`` nodes per plane, the phase referred to the middle plane); every other
term is summed exactly. Per column and plane the error is then at most
``ERROR_BOUND * sum_f |A_f|`` (Lagrange's remainder: ``max|t(t+1)(t-1)(t-2)|/4! *
(pi/OVERSAMPLE)^4``). Without padding the image is the inverse FFT of its spectrum on
the same grid, so by Parseval the image's L2 error is the spectrum's: at most
``ERROR_BOUND * sqrt(nz * sum_c (sum_f |A_f(c)|)^2)``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.fft as sfft

import holoradar as hr
from holoradar.imaging.migration.backends import kspace, stolt
from holoradar.imaging.migration.backends.terms import TermsKey

FREQS = np.linspace(8e9, 12e9, 11)
ZS = np.linspace(0.16, 0.30, 29)
HALF = hr.Medium.half_space(0.15, 2.5)


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def _hologram(mono: bool, medium: hr.Medium | None, source=None, n: int = 24
              ) -> hr.Hologram:
    ap = hr.Aperture.grid(n, 0.0062 if mono else 0.0124, monostatic=mono)
    med = medium if medium is not None else hr.Medium.free_space()
    kw = {} if mono else {"source": hr.PlaneWave() if source is None else source}
    scene = hr.Scene(med, targets=[hr.PointTarget((0.01, 0.0, 0.25)),
                                   hr.PointTarget((-0.03, 0.02, 0.21))], **kw)
    return hr.simulate(scene, ap, FREQS, include_surface=False, snr_db=20.0, seed=5)


def _bound(h: hr.Hologram, medium: hr.Medium, zs: np.ndarray) -> float:
    """``ERROR_BOUND * sqrt(nz * sum_c (sum_f |A_f|)^2)``: the resampled terms of an
    unpadded grid (the weights are 1: ``equalize=False``)."""
    grid = h.data.shape[-2:]
    dx, dy = h.pitch
    nz = zs.size
    gain, step, jmax, unfold = kspace.frequency_terms(TermsKey(
        grid, (dx, dy), tuple(h.wavenumbers), float(zs[0]), float(zs[1] - zs[0]), nz, medium,
        h.monostatic, "none" if h.monostatic else "phase", None, None,
        np.dtype(np.complex128), (True,) * h.nf))
    full = (np.abs(np.abs(step[:, unfold]) - 1) < 1e-6) & (jmax >= nz - 1)
    A = np.abs(sfft.fft2(h.data).reshape(h.nf, -1) * gain[:, unfold]) * full
    return stolt.ERROR_BOUND * float(np.sqrt(nz * np.sum(A.sum(axis=0) ** 2)))


@pytest.mark.parametrize(("mono", "medium"), [(True, None), (True, HALF), (False, None),
                                              (False, HALF)])
def test_stolt_is_within_its_bound_of_the_phase_shift_sum(mono, medium):
    h = _hologram(mono, medium)
    med = medium if medium is not None else hr.Medium.free_space()
    a = hr.migrate(h, ZS, medium=medium, algorithm="stolt", pad=False, equalize=False)
    b = hr.migrate(h, ZS, medium=medium, algorithm="kspace", pad=False, equalize=False)
    assert a.method == "stolt:coherent" and a.data.shape == b.data.shape
    # Parseval (unpadded: the image is the whole inverse FFT grid), ifft2's 1/N both sides.
    err = np.linalg.norm(a.data - b.data) * np.sqrt(a.data[0].size)
    assert err <= _bound(h, med, ZS)
    # And as the phase-shift sum's images are held: within 1e-3 here, padded too.
    assert _rel(a.data, b.data) < 1e-3
    c = hr.migrate(h, ZS, medium=medium, algorithm="stolt")
    d = hr.migrate(h, ZS, medium=medium, algorithm="kspace")
    assert _rel(c.data, d.data) < 1e-3


def test_stolt_refuses_what_it_cannot_do_and_auto_falls_back():
    h = _hologram(True, None, n=12)
    zs = ZS[::4]
    cases = [
        (dict(z=[0.2, 0.21, 0.23]), "uniformly spaced planes"),
        (dict(z=np.linspace(0.1, 0.2, 11), medium=HALF), "all planes in the deepest layer"),
        (dict(z=zs, medium=hr.Medium.half_space(0.15, 4 + 0.4j)), "no loss to compensate"),
        (dict(z=zs, combine="none"), "combine='coherent'"),
        (dict(z=zs, fov="full"), "fov='aperture'"),
    ]
    for kw, why in cases:
        z = kw.pop("z")
        with pytest.raises(ValueError, match=f"algorithm='stolt' needs .*{why}"):
            hr.migrate(h, z, algorithm="stolt", **kw)
        hr.migrate(h, z, **kw)   # "auto" does it, by the exact sum
    # A receiver array: without its source, or lit by a point source.
    bare = _hologram(False, None, n=12).replace(source=None)
    with pytest.raises(ValueError, match=r"hologram\.source"):
        hr.migrate(bare, zs, algorithm="stolt")
    horn = _hologram(False, None, source=hr.PointSource((0.0, 0.0, -0.3)), n=12)
    with pytest.raises(ValueError, match="PointSource"):
        hr.migrate(horn, zs, algorithm="stolt")
    a = hr.migrate(horn, zs)
    b = hr.migrate(horn, zs, algorithm="frequency")
    np.testing.assert_array_equal(a.data, b.data)
    # The lossy ground is allowed with the loss left uncompensated.
    lossy = hr.Medium.half_space(0.15, 4 + 0.4j)
    hr.migrate(h, zs, medium=lossy, algorithm="stolt", compensate_loss=False)
    with pytest.raises(ValueError, match="several frequencies"):
        hr.migrate(h.at_frequency(0), zs, algorithm="stolt")
