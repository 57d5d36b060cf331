"""The migration operator: every backend is a linear map with its exact adjoint, every
backend computes the same operator, ``migrate`` is its adjoint, and its forward map is
simulate's Kirchhoff model of a reflecting plane.

Tolerances
----------
Dot test ``<A x, y> = <x, A^H y>`` in complex128: both sides are the same bilinear
form summed in another order. Each term passes through O(log2 M) butterflies per FFT,
``nz`` plane sums and ``nf`` frequency sums: at most ~200 roundings of 1.1e-16 each.
For random vectors the terms' magnitudes sum to ~sqrt(n) times the result (n ~ 1e4
voxels), so the relative difference stays below 200 * 1.1e-16 * 100 ~ 2e-12: bound
1e-11. The finufft backend's sums are accurate to a relative l2 error EPS (1e-6 in
complex128) on each side; an error e of the vector ``A x`` changes ``<A x, y>`` by at
most ``|e| |y|``, ~sqrt(M) times ``EPS |<A x, y>|`` for random y (M samples): bound
``4 EPS sqrt(M)``. A wrong conjugate, a missing transfer or a transposed axis makes the
two sides differ by O(1).

Backends against the reference (plane by plane, or the direct ground sums): the same
exact operator evaluated differently (the phase-shift recurrence adds one rounding per
plane, ~nz eps); bound 1e-10 of the largest value. finufft: 4 EPS.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from holoradar.imaging.migration.backends.oblique_nufft import EPS

F0 = 9.9e9
BAND = np.linspace(8e9, 12e9, 5)
LOSSY = hr.Medium.half_space(0.2, 4.0 + 0.2j)
SAND = hr.Medium.half_space(0.2, 2.5)
ZS = np.linspace(0.24, 0.32, 5)


def _holo(kind: str) -> hr.Hologram:
    """Small holograms of each measurement geometry (random data: any data will do)."""
    rng = np.random.default_rng(abs(hash(kind)) % 2**32)
    x = (np.arange(12) - 5.5) * 0.01
    y = (np.arange(10) - 4.5) * 0.01

    def data(*shape: int) -> np.ndarray:
        return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)

    if kind == "array":         # a receiver array lit by a normal plane wave
        return hr.Hologram(data(10, 12), x, y, F0, source=hr.PlaneWave())
    if kind == "horn":          # lit by a horn beside it: the field varies per pixel
        return hr.Hologram(data(10, 12), x, y, F0, source=hr.PointSource((0.0, -0.2, -0.05)))
    if kind == "transceiver":   # a scanned transceiver, a band
        return hr.Hologram(data(5, 10, 12), x * 0.5, y * 0.5, BAND, monostatic=True)
    if kind == "horn-band":
        return hr.Hologram(data(5, 10, 12), x, y, BAND, source=hr.PointSource((0.0, -0.2, -0.05)))
    if kind == "pw-band":       # a receiver array's band lit by a normal plane wave
        return hr.Hologram(data(5, 10, 12), x, y, BAND, source=hr.PlaneWave())
    if kind == "pw-band-vector":   # the vector model: elements record E_y
        return hr.Hologram(data(5, 10, 12), x, y, BAND,
                           source=hr.PlaneWave(polarization=(0, 1, 0)), polarization=(0, 1, 0))
    if kind == "raised":        # a level array 5 cm above the reference plane z = 0
        return hr.Hologram(data(10, 12), x, y, F0, source=hr.PlaneWave(),
                           pose=hr.Pose((0.0, 0.0, 0.05)))
    if kind == "tilted":
        return hr.Hologram(data(10, 12), x, y, F0, source=hr.PointSource((0.0, -0.3, 0.0)),
                           pose=hr.Pose((0.0, 0.0, 0.0), tilt=np.radians(35),
                                        azimuth=np.radians(90)))
    if kind == "tilted-rows":   # y' along y: the sums factor by grid rows
        return hr.Hologram(data(10, 12), x, y, F0, monostatic=True,
                           pose=hr.Pose((0.0, 0.0, 0.0), tilt=np.radians(35)))
    if kind == "tilted-band":
        return hr.Hologram(data(2, 10, 12), x * 0.5, y * 0.5, BAND[:2], monostatic=True,
                           pose=hr.Pose((0.0, 0.0, 0.0), tilt=np.radians(30),
                                        azimuth=np.radians(20)))
    raise KeyError(kind)


# (geometry, medium, backend, options): every backend on the geometries it computes.
CASES = [
    ("array", None, "frequency", {}),
    ("array", None, "frequency", {"upsample": 2}),
    ("array", None, "frequency", {"fov": "full", "upsample": 2}),
    ("array", None, "kspace", {}),
    ("array", None, "fresnel", {"method": "fresnel"}),
    ("array", LOSSY, "frequency", {"compensate_loss": True}),
    ("array", LOSSY, "kspace", {"upsample": 3}),
    ("horn", LOSSY, "frequency", {}),
    ("horn", LOSSY, "frequency", {"illumination": "phase", "upsample": 2}),
    ("raised", LOSSY, "frequency", {}),
    ("transceiver", None, "frequency", {}),
    ("transceiver", SAND, "frequency", {"equalize": True, "upsample": 2}),
    ("transceiver", SAND, "kspace", {"equalize": True}),
    ("transceiver", SAND, "columns", {"upsample": 2}),
    ("transceiver", None, "stolt", {}),
    ("transceiver", LOSSY, "frequency", {"combine": "none", "compensate_loss": True}),
    ("horn-band", LOSSY, "frequency", {}),
    ("horn-band", SAND, "frequency", {"combine": "none", "illumination": "phase"}),
    ("horn", LOSSY, "frequency", {"scatterer": "point", "band_limit": "smooth", "pad": 3.0}),
    ("horn-band", SAND, "frequency", {"scatterer": "point", "upsample": 2}),
    ("pw-band", SAND, "kspace", {"scatterer": "point"}),
    ("pw-band-vector", SAND, "columns", {"scatterer": "point"}),
    ("pw-band-vector", SAND, "frequency", {"scatterer": "point", "band_limit": "smooth"}),
    ("pw-band", SAND, "columns", {"scatterer": "point", "upsample": 2}),
    ("transceiver", SAND, "frequency", {"scatterer": "point", "band_limit": "smooth"}),
    ("transceiver", SAND, "kspace", {"scatterer": "point", "equalize": True}),
    ("transceiver", SAND, "stolt", {"scatterer": "point"}),
    ("tilted", SAND, "ground-direct", {"frame": "ground"}),
    ("tilted", LOSSY, "ground-direct", {"frame": "ground", "compensate_loss": True}),
    ("tilted", SAND, "ground-nufft", {"frame": "ground", "scatterer": "point"}),
    ("tilted", SAND, "ground-nufft", {"frame": "ground"}),
    ("tilted-rows", SAND, "ground-direct", {"frame": "ground"}),
    ("tilted-rows", SAND, "ground-nufft", {"frame": "ground"}),
    ("tilted-band", SAND, "ground-direct", {"frame": "ground", "upsample": 2}),
    ("tilted-band", SAND, "ground-nufft", {"frame": "ground", "combine": "none"}),
]


def _operator(kind: str, medium, backend: str, options: dict) -> hr.MigrationOperator:
    zs = ZS + (0.1 if options.get("frame") == "ground" else 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # aliasing of the coarse test grids: irrelevant
        return hr.migration_operator(_holo(kind), zs, medium=medium, algorithm=backend,
                                     **options)


def _random(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.standard_normal(n) + 1j * rng.standard_normal(n)


@pytest.mark.parametrize(("kind", "medium", "backend", "options"), CASES,
                         ids=[f"{c[0]}-{c[2]}-{i}" for i, c in enumerate(CASES)])
def test_dot_test(kind, medium, backend, options):
    A = _operator(kind, medium, backend, options)
    assert A.backend.name == backend
    x, y = _random(A.shape[1], 1), _random(A.shape[0], 2)
    lhs, rhs = np.vdot(A @ x, y), np.vdot(x, A.H @ y)
    bound = 4 * EPS[np.dtype(complex)] * np.sqrt(A.shape[0]) if "nufft" in backend else 1e-11
    assert abs(lhs - rhs) <= bound * abs(lhs), (lhs, rhs)


# Each faster backend against the reference of its frame, adjoint and forward.
SAME = [
    ("array", None, "kspace", "frequency", {}),
    ("array", LOSSY, "kspace", "frequency", {"upsample": 3}),
    ("transceiver", SAND, "kspace", "frequency", {"equalize": True, "upsample": 2}),
    ("transceiver", SAND, "columns", "frequency", {"equalize": True, "upsample": 2}),
    ("transceiver", None, "columns", "frequency", {}),
    ("pw-band", SAND, "columns", "frequency", {"scatterer": "point", "upsample": 2}),
    ("transceiver", SAND, "kspace", "frequency", {"scatterer": "point"}),
    ("pw-band-vector", SAND, "kspace", "frequency", {"scatterer": "point"}),
    ("tilted", SAND, "ground-nufft", "ground-direct", {"frame": "ground"}),
    ("tilted-band", SAND, "ground-nufft", "ground-direct", {"frame": "ground"}),
    ("tilted-rows", SAND, "ground-nufft", "ground-direct", {"frame": "ground"}),
]


@pytest.mark.parametrize(("kind", "medium", "backend", "reference", "options"), SAME,
                         ids=[f"{c[0]}-{c[2]}" for c in SAME])
def test_every_backend_equals_the_reference(kind, medium, backend, reference, options):
    A = _operator(kind, medium, backend, options)
    R = _operator(kind, medium, reference, options)
    assert A.shape == R.shape
    np.testing.assert_array_equal(A.x, R.x)
    x, y = _random(A.shape[1], 3), _random(A.shape[0], 4)
    bound = 4 * EPS[np.dtype(complex)] if "nufft" in backend else 1e-10
    for got, ref in ((A @ x, R @ x), (A.H @ y, R.H @ y)):
        assert np.max(np.abs(got - ref)) <= bound * np.max(np.abs(ref))


def test_stolt_is_its_own_exact_adjoint_pair_but_not_the_exact_operator():
    # Stolt's resampling errs by up to 0.9 % per plane wave (its own tests bound it):
    # its forward map is the transpose of its adjoint, not the exact forward.
    A = _operator("transceiver", None, "stolt", {})
    R = _operator("transceiver", None, "frequency", {})
    y = _random(A.shape[0], 5)
    diff = np.linalg.norm(A.H @ y - R.H @ y) / np.linalg.norm(R.H @ y)
    assert 1e-6 < diff < 0.05


@pytest.mark.parametrize("kind", ["array", "transceiver", "horn-band", "tilted"])
def test_migrate_is_the_operators_adjoint(kind):
    # With migrate's own settings the operator's adjoint is migrate's image, bit for bit
    # (the same backend and plan).
    h = _holo(kind)
    medium = SAND if kind != "array" else LOSSY
    ground = kind == "tilted"
    zs = ZS + (0.1 if ground else 0.0)
    opts = {"frame": "ground"} if ground else {"upsample": 2}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        img = hr.migrate(h, zs, medium=medium, dtype=np.complex128, **opts)
        A = hr.migration_operator(h, zs, medium=medium, compensate_loss=True, equalize=True,
                                  illumination=None, **opts)
    np.testing.assert_array_equal(A.H @ A.vector(h), img.data.ravel())
    np.testing.assert_array_equal(A.x, img.x)
    np.testing.assert_array_equal(A.y, img.y)
    out = A.to_image(A.H @ A.vector(h))
    assert out.data.shape == img.data.shape and np.array_equal(out.z, img.z)


@pytest.mark.parametrize("kind", ["array", "transceiver"])
def test_the_imaging_preset_makes_migrate_the_adjoint(kind):
    # One word instead of three options: preset="imaging" is migrate's defaults, so the
    # adjoint is migrate's image bit for bit; the default preset ("forward") is not (a
    # lossy ground's compensation and the frequencies' weights differ).
    h = _holo(kind)
    medium = SAND if kind != "array" else LOSSY
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        img = hr.migrate(h, ZS, medium=medium, dtype=np.complex128, upsample=2)
        A = hr.migration_operator(h, ZS, medium=medium, upsample=2, preset="imaging")
        F = hr.migration_operator(h, ZS, medium=medium, upsample=2)
    np.testing.assert_array_equal(A.H @ A.vector(h), img.data.ravel())
    assert not np.allclose(F.H @ F.vector(h), img.data.ravel())


def test_one_table_of_defaults():
    # migrate's keyword defaults are MigrationSettings' own (the "imaging" preset adds
    # nothing), and an unknown preset is refused by name.
    import inspect

    from holoradar.imaging.migration.settings import PRESETS

    settings = hr.MigrationSettings()
    for name, p in inspect.signature(hr.migrate).parameters.items():
        if p.kind is p.KEYWORD_ONLY and hasattr(settings, name):
            assert getattr(settings, name) == p.default or \
                (p.default is None and getattr(settings, name) is None), name
    assert PRESETS["imaging"] == {}
    with pytest.raises(ValueError, match="preset must be"):
        hr.migration_operator(_holo("array"), ZS, preset="migrate")


@pytest.mark.parametrize(("medium", "source"), [
    (None, hr.PlaneWave()),
    (hr.Medium.half_space(0.2, 4 + 0.2j), hr.PlaneWave()),
    (hr.Medium.half_space(0.2, 4 + 0.2j), hr.PointSource((0.0, -0.05, -0.05))),
])
def test_forward_is_simulates_kirchhoff_model_of_a_plane(medium, source):
    # simulate's planar target is an independent evaluation of the same model (the
    # reflected field f E0 on the plane, carried up through the layers by a direct
    # non-uniform Fourier sum with its own spectral sampling, ~0.1 % of the
    # Rayleigh-Sommerfeld sum). The operator's periodic FFT grid with its sharp band
    # limit rings into the kernel: measured 1.9-2.5 % at the default padding for this
    # sharp-edged disk, 0.14 % at 8x. At 8x the bound 1 % holds both discretisations'
    # errors; a conjugated transfer, a missing or conjugated illumination or a mirrored
    # axis is an O(1) error.
    med = medium if medium is not None else hr.Medium.free_space()
    ap = hr.Aperture.grid(24, 0.01)
    empty = hr.simulate(hr.Scene(med, source, []), ap, F0, include_surface=False)
    A = hr.migration_operator(empty, 0.3, medium=medium, pad=8.0)
    X, Y = np.meshgrid(A.x, A.y)
    f = (np.hypot(X - 0.01, Y + 0.02) < 0.05) * (0.5 + 0.2j)
    plate = hr.PlanarTarget(f, A.x, A.y, 0.3)
    h = hr.simulate(hr.Scene(med, source, [plate]), ap, F0, include_surface=False)
    got = A @ f.ravel()
    assert np.linalg.norm(got - h.data.ravel()) < 0.01 * np.linalg.norm(h.data)


@pytest.mark.parametrize(("medium", "mono", "frame"), [
    (None, False, "aperture"),
    (hr.Medium.half_space(0.2, 4 + 0.2j), False, "aperture"),
    (hr.Medium.half_space(0.2, 4.0), True, "aperture"),
    (hr.Medium.half_space(0.25, 4.0), False, "ground"),
    (hr.Medium.half_space(0.25, 4.0), False, "ground-coarse"),   # pixels of 2 cm
])
def test_point_unit_is_a_point_targets_amplitude(medium, mono, frame):
    # scatterer="point": a voxel of reflectivity 1 sends the elements what simulate's
    # PointTarget of amplitude 1 does (its exact Sommerfeld field), as plane waves
    # weighted by Weyl's 2 pi i/(kz dA) (a transceiver: the round trip's stationary
    # phase, 2 pi i/(2 k n L dA)). The smooth band limit on a grid padded 3x leaves
    # the angular spectrum within 2 % of the exact field here (the sharp cut: 13 %);
    # the round trip's paraxial spreading adds up to 5 % in the ground (measured 5.3 %);
    # the tilted array's ground frame 4 %. Bound 8 %: a missing 1/kz, a wrong area, a
    # conjugated transfer or a wrong index in the spreading is 20 % to O(1).
    med = medium if medium is not None else hr.Medium.free_space()
    ground = frame.startswith("ground")
    pose = hr.Pose((0.0, 0.0, 0.0), tilt=np.radians(30), azimuth=np.radians(90)) \
        if ground else None
    ap = hr.Aperture.grid(48, 0.006, monostatic=mono, pose=pose)
    z = 0.4 if ground else 0.3
    empty = hr.simulate(hr.Scene(med, hr.PlaneWave(), []), ap, F0, include_surface=False)
    where = {"frame": "ground"} if ground else {"band_limit": "smooth", "pad": 3.0}
    if frame == "ground-coarse":   # coarser than the spectrum needs: every m-th sample
        where.update(x=np.arange(-0.2, 0.2001, 0.02), y=np.arange(-0.1, 0.3001, 0.02))
    A = hr.migration_operator(empty, [z], medium=medium, scatterer="point", **where)
    ix, iy = A.x.size // 2 + 3, A.y.size // 2 - 2
    point = hr.PointTarget((A.x[ix], A.y[iy], z), 1.0)
    h = hr.simulate(hr.Scene(med, hr.PlaneWave(), [point]), ap, F0, include_surface=False)
    r = np.zeros(A.image_shape, complex)
    r[0, iy, ix] = 1.0
    got = A @ r.ravel()
    assert np.linalg.norm(got - h.data.ravel()) < 0.08 * np.linalg.norm(h.data)


def test_scipy_and_pylops_solvers_take_it():
    from scipy.sparse.linalg import lsqr

    pylops = pytest.importorskip("pylops")
    A = _operator("array", None, "frequency", {})
    truth = np.zeros(A.image_shape, complex)
    truth[2, 5, 6] = 1.0
    d = A @ truth.ravel()
    x, _, _, r1norm = lsqr(A, d, atol=1e-10, btol=1e-10, iter_lim=200)[:4]
    # The data lie in the operator's range (a consistent system): LSQR's residual
    # falls (by two orders within 200 steps here; the evanescent components make the
    # system ill-conditioned), and the residual it tracks through matvec and rmatvec
    # is the true one.
    res = np.linalg.norm(A @ x - d)
    assert res < 0.01 * np.linalg.norm(d)
    assert abs(r1norm - res) < 1e-6 * np.linalg.norm(d)
    Op = pylops.aslinearoperator(A)
    assert pylops.utils.dottest(Op, *Op.shape, complexflag=3, rtol=1e-11)


def test_bad_input_names_the_argument_and_shape():
    A = _operator("array", None, "frequency", {})
    with pytest.raises(ValueError, match=r"x must be a vector of 600 values \(shape \(5, 10"):
        A.matvec(np.zeros(599))
    with pytest.raises(ValueError, match=r"x must be a vector of 120 values \(shape \(10, 12\)"):
        A.rmatvec(np.zeros(600))
    with pytest.raises(ValueError, match="x must be a numeric vector"):
        A.matvec(np.array(["a"] * 600))
    h = _holo("array")
    with pytest.raises(ValueError, match=r"algorithm='kspace' needs .*uniformly spaced planes"):
        hr.migration_operator(h, [0.2, 0.25, 0.4], algorithm="kspace")
    with pytest.raises(ValueError, match="combine='incoherent' is not linear"):
        hr.migration_operator(_holo("transceiver"), ZS, combine="incoherent")
    with pytest.raises(ValueError, match="unknown migration option"):
        hr.migration_operator(h, ZS, upsampling=2)
    with pytest.raises(ValueError, match=r"hologram must be a holoradar\.Hologram"):
        hr.migration_operator(h.data, ZS)
    with pytest.raises(ValueError, match=r"vector must be a vector of 600 values"):
        A.to_image(np.zeros(12))


def test_array_sampling_is_the_fine_field_at_the_elements_with_its_exact_adjoint():
    # sampling="array" on the paper's 2.5 cm pitch (lambda/2 = 1.5 cm at 9.9 GHz): the
    # field computed at 1.25 cm and every other sample kept. Its adjoint is exact (dot
    # test to rounding), and a point's samples match simulate's closer than the
    # band-limited model's: the aliased waves are in the model (measured 5-11 % against
    # 17-29 %; the bound is the band-limited model's own error on this point).
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    empty = hr.simulate(hr.Scene(sand, hr.PlaneWave(), []), hr.Aperture.paper(), 9.9e9,
                        include_surface=False)
    opts = {"scatterer": "point", "band_limit": "smooth", "pad": 3.0}
    A = hr.migration_operator(empty, [0.42], medium=sand, **opts)
    B = hr.migration_operator(empty, [0.42], medium=sand, sampling="band", upsample=2, **opts)
    assert A.oversampling == 2 and B.oversampling == 1 and A.image_shape == B.image_shape
    rng = np.random.default_rng(3)
    r = rng.standard_normal(A.shape[1]) + 1j * rng.standard_normal(A.shape[1])
    d = rng.standard_normal(A.shape[0]) + 1j * rng.standard_normal(A.shape[0])
    assert np.vdot(A @ r, d) == pytest.approx(np.vdot(r, A.H @ d), rel=1e-12)
    iy, ix = A.y.size // 2 + 2, A.x.size // 2 - 5
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget((A.x[ix], A.y[iy], 0.42))]),
                    hr.Aperture.paper(), 9.9e9, include_surface=False)
    unit = np.zeros(A.image_shape, complex)
    unit[0, iy, ix] = 1.0
    err = [np.linalg.norm((M @ unit.ravel()).reshape(h.data.shape) - h.data)
           / np.linalg.norm(h.data) for M in (A, B)]
    assert err[0] < err[1] and err[0] < 0.12, err
    with pytest.raises(ValueError, match="sampling must be"):
        hr.migration_operator(empty, [0.42], sampling="fine")
