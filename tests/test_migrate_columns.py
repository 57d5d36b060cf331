"""The wideband phase-shift sum by its compiled column loop, and the memory check.

``migrate(..., algorithm="auto")`` on uniform planes computes, per spectral column, the
same sum over frequencies as the NumPy recurrence (``algorithm="kspace"``): term by
term, in another order. Only rounding separates them, and the recurrence's rounding
grows by one unit per plane: relative difference below ``10 * nz * eps`` (complex128:
eps 1.1e-16; complex64: 6e-8), far inside the 1e-3 the images are held to.
"""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from conftest import migrate64
from holoradar.imaging.migration import memory
from holoradar.imaging.migration import plan as migration_plan
from holoradar.imaging.migration.backends import columns, kspace

FREQS = np.linspace(8e9, 12e9, 11)
ZS = np.linspace(0.16, 0.30, 29)
EPS = {np.complex64: 6e-8, np.complex128: 1.1e-16}
HALF = hr.Medium.half_space(0.15, 2.5)

pytestmark = pytest.mark.skipif(not columns.available(), reason="numba is not installed")


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def _hologram(mono: bool, medium: hr.Medium | None, measured: bool, dtype: type,
              n: int = 24) -> hr.Hologram:
    """Two points (simulated, exact Green's functions); ``measured``: as a device
    records them, with the ground's reflection, noise (20 dB), a phase response across
    the band, then the mean removed as one does with such data."""
    ap = hr.Aperture.grid(n, 0.0062 if mono else 0.0124, monostatic=mono)
    med = medium if medium is not None else hr.Medium.free_space()
    scene = hr.Scene(med, targets=[hr.PointTarget((0.01, 0.0, 0.25)),
                                   hr.PointTarget((-0.03, 0.02, 0.21))],
                     **({} if mono else {"source": hr.PlaneWave()}))
    h = hr.simulate(scene, ap, FREQS, include_surface=measured and medium is not None,
                    snr_db=20.0 if measured else None, seed=3)
    if measured:
        phase = 0.3 + 2e-9 * (FREQS - 8e9)
        h = hr.remove_mean(h.with_data(h.data * np.exp(1j * phase)[:, None, None]))
    return h.with_data(h.data.astype(dtype))


@pytest.mark.parametrize("dtype", [np.complex64, np.complex128])
@pytest.mark.parametrize(("mono", "medium", "measured"), [
    (True, None, False), (True, HALF, True), (False, None, True), (False, HALF, False)])
def test_auto_equals_the_phase_shift_sum(mono, medium, measured, dtype):
    h = _hologram(mono, medium, measured, dtype)
    a = migrate64(h, ZS, medium=medium, dtype=dtype)
    b = migrate64(h, ZS, medium=medium, algorithm="kspace", dtype=dtype)
    assert a.method == b.method == "kspace:coherent"
    assert a.data.dtype == b.data.dtype == dtype and a.data.shape == b.data.shape
    assert _rel(a.data, b.data) < 10 * ZS.size * EPS[dtype]


@pytest.mark.parametrize(("pad", "upsample", "z0"), [(False, 1, 0.0), (2.0, 2, 0.16),
                                                     (False, 2, 0.02)])
def test_auto_equals_the_phase_shift_sum_on_every_grid(pad, upsample, z0):
    # Unpadded (the spectra written into the output itself), a padding factor with
    # interpolation, planes from the aperture on (evanescent terms at the first
    # planes); leading axes. Same bound as above.
    h = _hologram(True, None, True, np.complex128)
    h = h.with_data(np.stack([h.data, 0.5j * h.data[::-1]]))
    zs = np.linspace(z0, z0 + 0.12, 17)
    a = migrate64(h, zs, pad=pad, upsample=upsample)
    b = migrate64(h, zs, pad=pad, upsample=upsample, algorithm="kspace")
    assert a.data.shape == b.data.shape == (2, 17, 24 * upsample - upsample + 1,
                                            24 * upsample - upsample + 1)
    assert _rel(a.data, b.data) < 10 * zs.size * EPS[np.complex128]


def test_auto_takes_the_compiled_loop_and_the_numpy_sum_without_numba(monkeypatch):
    h = _hologram(True, None, False, np.complex128)
    columns.warm()   # loaded: auto takes it whatever the size of the work
    calls = []
    real = columns.adjoint_columns
    monkeypatch.setattr(columns, "adjoint_columns",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    a = migrate64(h, ZS)
    assert calls == [1]
    monkeypatch.setattr(columns, "available", lambda: False)
    b = migrate64(h.with_data(h.data), ZS)   # a new hologram: a new plan, chosen afresh
    assert calls == [1]   # not called again: the NumPy recurrence
    assert _rel(a.data, b.data) < 10 * ZS.size * EPS[np.complex128]


def test_warm_builds_every_loop_a_migration_calls(monkeypatch):
    # warm() is what `make` runs at install so that no user's first call compiles: the
    # loops it builds must be the ones migrate calls (a plan's arrays are read-only,
    # which numba types apart: warm() built writable ones, and a fresh install compiled
    # at its first wideband call). A new dispatcher (on numba's disk cache) sees only
    # what warm() and then the migrations ask of it.
    fresh = columns._build_kernel.__wrapped__()
    monkeypatch.setattr(columns, "_kernel", lambda: fresh)
    monkeypatch.setattr(columns, "loaded", lambda: True)
    columns.warm()
    built = set(fresh.signatures)
    assert len(built) == 2
    for dtype in (np.complex64, np.complex128):
        h = _hologram(True, None, False, dtype)
        for pad in (False, True):
            migrate64(h, ZS, pad=pad)
    assert set(fresh.signatures) == built


def test_a_fresh_process_sums_small_work_in_numpy_until_loading_pays(monkeypatch):
    # Loading numba and its cached loop costs a fresh process 0.35-0.45 s, the NumPy sum
    # of COLD_LOAD_WORK multiply-adds as long: a small first migration takes NumPy; the
    # work summed so adds up, and the call that would pass the bound loads the loop.
    from holoradar.imaging.migration import choose

    monkeypatch.setattr(columns, "loaded", lambda: False)
    monkeypatch.setattr(choose, "_NUMPY_WORK", [0.0])
    h = _hologram(True, None, False, np.complex128)
    calls = []
    real = columns.adjoint_columns
    monkeypatch.setattr(columns, "adjoint_columns",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    a = migrate64(h, ZS)
    assert calls == [] and choose._NUMPY_WORK[0] > 0
    work = choose._NUMPY_WORK[0]
    monkeypatch.setattr(choose, "COLD_LOAD_WORK", 2.5 * work)
    migrate64(h.with_data(h.data), ZS)     # 2 x work: still NumPy
    b = migrate64(h.with_data(h.data), ZS)  # 3 x work passes the bound: compiled
    assert calls == [1]
    # the two sums agree to rounding (the recurrence's j eps per plane)
    assert _rel(a.data, b.data) < 10 * ZS.size * EPS[np.complex128]


def test_auto_falls_back_to_the_per_frequency_sum_where_the_phase_shift_cannot():
    # Planes not uniform, or a lossy ground to compensate: "auto" silently sums
    # frequency by frequency (the same code path as "frequency", bit for bit).
    h = _hologram(True, None, False, np.complex128, n=12)
    zs = np.array([0.2, 0.21, 0.23])
    a = migrate64(h, zs)
    b = migrate64(h, zs, algorithm="frequency")
    np.testing.assert_array_equal(a.data, b.data)
    lossy = hr.Medium.layered([0.10, 0.13], [5.0 + 0.5j, 8.0 + 0.3j])
    a = migrate64(h, ZS[::4], medium=lossy)
    b = migrate64(h, ZS[::4], medium=lossy, algorithm="frequency")
    np.testing.assert_array_equal(a.data, b.data)


def test_a_volume_that_does_not_fit_is_refused_before_any_work(monkeypatch):
    h = _hologram(True, None, False, np.complex128)
    work = []
    for mod, name in ((columns, "adjoint_columns"), (kspace, "adjoint_kspace"),
                      (migration_plan, "data_snr")):
        real = getattr(mod, name)
        monkeypatch.setattr(mod, name,
                            lambda *a, real=real, **k: work.append(1) or real(*a, **k))
    # 29 planes of 24 x 24 complex128: 0.13 MB; 1.5 x that needs more than 0.15 MB.
    monkeypatch.setattr(memory, "available_memory", lambda: 150_000)
    monkeypatch.setattr(memory, "_CHECK_ABOVE", 0)   # checked at any size
    with pytest.raises(MemoryError) as err:
        migrate64(h, ZS)
    msg = str(err.value)
    for part in ("29 planes x 24 x 24", "complex128", "0.00 GiB", "fewer planes",
                 "dtype=numpy.complex64", "survey store"):
        assert part in msg
    with pytest.raises(MemoryError, match="fewer planes"):   # the per-frequency sum
        migrate64(h, [0.2, 0.21, 0.23] * 10, algorithm="frequency")
    with pytest.raises(MemoryError, match="fewer planes"):   # one frequency
        migrate64(h.at_frequency(0), ZS)
    assert work == []
    # Enough memory: it runs (the stand-ins record the work).
    monkeypatch.setattr(memory, "available_memory", lambda: 10**9)
    migrate64(h, ZS)
    assert work and work[-1] == 1


def test_an_operator_takes_the_compiled_sum_even_before_it_is_loaded(monkeypatch):
    # An operator is applied many times (a solver's steps): the load pays for itself.
    from holoradar.imaging.migration import choose

    monkeypatch.setattr(columns, "loaded", lambda: False)
    monkeypatch.setattr(choose, "_NUMPY_WORK", [0.0])
    h = _hologram(True, None, False, np.complex128)
    A = hr.migration_operator(h, ZS)
    assert A.backend.name == "columns"
    assert choose._NUMPY_WORK[0] == 0.0
