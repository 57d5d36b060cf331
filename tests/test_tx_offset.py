"""A transmitter beside the receiver (``tx_offset``): the two-leg kernel, exact.

The scan is the inverse-SAR layout of a bistatic pair: 12 x 12 positions at 18 mm, the
transmitter 12 cm beside the receiver, 5.7-8.2 GHz (an 18 mm pitch undersamples the
round trip: the kernel is sampled at the elements, aliasing included).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import holoradar as hr
from conftest import crandn
from holoradar.imaging.migration.linear import migration_operator
from holoradar.physics.green import green_at_distances

C0 = 299_792_458.0
OFFSET = (0.12, 0.0, 0.0)
F = np.linspace(5.7e9, 8.2e9, 11)


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)
        yield


def _aperture(offset=OFFSET) -> hr.Aperture:
    return hr.Aperture.grid(12, 0.018, tx_offset=offset)


def _point(position, medium=None, offset=OFFSET, f=F, **kw) -> hr.Hologram:
    scene = hr.Scene(targets=[hr.PointTarget(position)],
                     **({} if medium is None else {"medium": medium}))
    return hr.simulate(scene, _aperture(offset), f, include_surface=False, **kw)


def _peak(img: hr.Image) -> tuple[float, float, float]:
    i = np.unravel_index(np.abs(img.data).argmax(), img.data.shape)
    return float(img.x[i[2]]), float(img.y[i[1]]), float(img.z[i[0]])


@pytest.mark.parametrize("medium", [None, hr.Medium.half_space(0.05, 4 + 0.2j)])
@pytest.mark.parametrize("options", [{}, {"scatterer": "point"}, {"upsample": 2},
                                     {"combine": "none"}, {"compensate_loss": True}])
def test_forward_and_adjoint_are_a_pair(medium, options, rng):
    h = hr.Hologram(np.zeros((F.size, 12, 12), complex), *_aperture().x[None].repeat(2, 0),
                    F, tx_offset=OFFSET)
    A = migration_operator(h, np.linspace(0.1, 0.3, 7), medium=medium, **options,
                           **({"snr_db": 30} if options.get("compensate_loss") else {}))
    assert A.backend.name == "offset"
    r, d = crandn(rng, A.shape[1]), crandn(rng, A.shape[0])
    # Both sides are sums of ~1e4 products in float64 through FFTs of rounding 1e-16 x
    # log2(n): agreement to 1e-12 relative is rounding, a wrong adjoint is O(1) off.
    lhs, rhs = np.vdot(A @ r, d), np.vdot(r, A.H @ d)
    assert abs(lhs - rhs) <= 1e-12 * abs(lhs)


@pytest.mark.parametrize("upsample", [1, 2])
def test_adjoint_is_the_bistatic_matched_filter(upsample, rng):
    """``A.H h`` at every pixel equals ``sum_f sum_p h conj(g_rx g_tx)``, computed here from
    the closed form ``exp(i k R)/R`` of each leg (no FFT, no shared code)."""
    h0 = _point((0.02, -0.01, 0.17))
    h = h0.with_data(h0.data + 0.1 * np.abs(h0.data).max() * crandn(rng, h0.shape))
    z = np.array([0.12, 0.17, 0.21])
    A = migration_operator(h, z, scatterer="point", upsample=upsample)
    img = A.to_image(A.H @ A.vector(h))
    X, Y = np.meshgrid(img.x, img.y)
    PX, PY = (a.ravel()[:, None] for a in np.meshgrid(h.x, h.y))
    ks = 2 * np.pi * F / C0
    ref = np.empty(img.data.shape, complex)
    for j, zz in enumerate(z):
        r1 = np.sqrt((PX - X.ravel()) ** 2 + (PY - Y.ravel()) ** 2 + zz**2)
        r2 = np.sqrt((PX + OFFSET[0] - X.ravel()) ** 2 + (PY - Y.ravel()) ** 2 + zz**2)
        kern = np.exp(1j * ks[:, None, None] * (r1 + r2)) / (r1 * r2)
        ref[j] = np.einsum("fp,fpq->q", h.data.reshape(F.size, -1), kern.conj()).reshape(
            X.shape)
    # The same sums in another order (FFT convolution): rounding, 1e-12 of the peak.
    assert np.abs(img.data - ref).max() <= 1e-12 * np.abs(ref).max()


@pytest.mark.parametrize("medium", [None, hr.Medium.half_space(0.08, 5 + 0.3j)])
def test_forward_is_simulates_point_target(medium):
    """A voxel of amplitude 1 maps to ``simulate``'s point target on that voxel. Free
    space: the same closed form (rounding). Layered ground: ``simulate`` integrates each
    leg at every element, the operator interpolates each leg's radial profile (a
    sixteenth of the wavelength in the ground): linear interpolation of smooth
    amplitude and phase errs ~ (h k)^2 / 8 x (curvature scale) ~ 1e-3 at most."""
    h = _point((-0.009 + 0.018 * 2, 0.009, 0.16), medium)
    A = migration_operator(h, [0.12, 0.16], medium=medium, scatterer="point")
    r = np.zeros(A.image_shape, complex)
    ix = int(np.argmin(np.abs(A.x - (-0.009 + 0.036))))
    iy = int(np.argmin(np.abs(A.y - 0.009)))
    r[1, iy, ix] = 1.0
    fwd = (A @ r.ravel()).reshape(h.shape)
    err = np.linalg.norm(fwd - h.data) / np.linalg.norm(h.data)
    assert err <= (1e-12 if medium is None else 1e-3)


def test_kernel_through_the_ground_matches_the_direct_integral():
    """Each leg's interpolated profile against the Sommerfeld integral at the lags."""
    from holoradar.imaging.migration.backends.offset import _lags, kernels

    med = hr.Medium.half_space(0.08, 5 + 0.3j)
    h = _point((0.0, 0.0, 0.15), med, f=[7e9, 8e9])
    A = migration_operator(h, [0.12, 0.16], medium=med, scatterer="point")
    k = 2 * np.pi * 7e9 / C0
    r1, r2 = _lags(A.plan)
    direct = green_at_distances(k, med, 0.16, 0.0, r1) * green_at_distances(k, med, 0.16,
                                                                              0.0, r2)
    # Linear interpolation on a lambda/16 grid: relative error (2 pi / 16)^2 / 8 ~ 2e-2
    # of the phase's second difference per step, which for a curvature k/z of the phase
    # (not k^2) is ~ (h^2 / 8) k / z ~ 4e-4.
    assert np.abs(kernels(A.plan, k)[1] - direct).max() <= 1e-3 * np.abs(direct).max()


def test_image_finds_the_point_where_a_transceiver_model_does_not():
    target = (0.027, -0.009, 0.17)
    h = _point(target, snr_db=30, seed=2)
    z = np.arange(0.10, 0.25, 0.005)
    x, y, zz = _peak(hr.migrate(h, z))
    # Lateral: within a pixel (18 mm); range: the adjoint's peak within a quarter of the
    # range resolution c / (2 B) = 6 cm of the target (its amplitude 1/(R_rx R_tx)
    # pulls the adjoint's peak towards the array).
    assert abs(x - target[0]) <= 0.018 and abs(y - target[1]) <= 0.018
    assert abs(zz - target[2]) <= C0 / (2 * (F[-1] - F[0])) / 4
    # The inversion puts it on its voxel.
    x, y, zz = _peak(hr.invert(h, z))
    assert (x, y, zz) == pytest.approx(target, abs=1e-9)
    # Read as a transceiver, the same data image half the offset away.
    naive = hr.Hologram(h.data, h.x, h.y, h.frequency, monostatic=True)
    x, _, _ = _peak(hr.migrate(naive, z))
    assert abs(x - target[0]) > 0.03


def test_small_offset_tends_to_the_transceiver_image():
    """d -> 0: the two-leg kernel is g^2, whose stationary-phase form is the transceiver's
    round-trip transfer (the point unit's 1-5 % accuracy): the images correlate > 0.99."""
    target = (0.0, 0.0, 0.2)
    h = _point(target, offset=(1e-4, 0.0, 0.0))
    z = np.arange(0.15, 0.25, 0.005)
    a = hr.migrate(h, z).data
    mono = hr.simulate(hr.Scene(targets=[hr.PointTarget(target)]),
                       hr.Aperture.grid(12, 0.018, monostatic=True), F)
    b = hr.migrate(mono, z).data
    assert abs(np.vdot(a, b)) / np.linalg.norm(a) / np.linalg.norm(b) > 0.99


def test_height_offset_moves_the_transmitter_towards_the_scene():
    """dz > 0: the transmitter nearer the scene; the closed form with R_tx from z - dz."""
    target = (0.0, 0.0, 0.2)
    h = _point(target, offset=(0.05, 0.0, 0.03))
    p = h.points[0]
    r1 = np.linalg.norm(p - target)
    r2 = np.linalg.norm(p + np.array([0.05, 0, 0.03]) - target)
    k = 2 * np.pi * F[0] / C0
    assert h.data[0, 0, 0] == pytest.approx(np.exp(1j * k * (r1 + r2)) / (r1 * r2), rel=1e-12)
    # The operator's kernel holds the same height: a voxel on the target is simulate's.
    target = (float(h.x[5]), float(h.y[6]), 0.2)
    h = _point(target, offset=(0.05, 0.0, 0.03))
    A = migration_operator(h, [0.2], scatterer="point")
    r = np.zeros(A.image_shape, complex)
    r[0, 6, 5] = 1.0
    fwd = (A @ r.ravel()).reshape(h.shape)
    assert np.linalg.norm(fwd - h.data) <= 1e-12 * np.linalg.norm(h.data)


def test_offset_is_kept_by_copies_and_files(tmp_path):
    h = _point((0.0, 0.0, 0.2))
    assert h.monostatic and h.tx_offset == OFFSET
    assert h.at_frequency(2).tx_offset == OFFSET
    assert h.with_data(h.data * 2).tx_offset == OFFSET
    hr.save(h, tmp_path / "pair.nc")
    back = hr.load(tmp_path / "pair.nc")
    assert back.tx_offset == OFFSET and back.monostatic


def test_layout_gives_the_offset_in_its_length_unit():
    from holoradar.io.layout import Layout, layout_tx_offset

    lay = Layout.parse("units=mm, tx_offset=[120, 0, 5]")
    assert layout_tx_offset(lay) == pytest.approx((0.12, 0.0, 0.005))


@pytest.mark.parametrize("offset, match", [
    ((120.0, 0.0, 0.0), "longer than the aperture"),
    ((0.1,), "tx_offset must be"),
    ((0.1, np.nan, 0), "tx_offset must be"),
    ("near", "tx_offset must be"),
])
def test_bad_offsets_are_refused_by_name(offset, match):
    x = np.arange(12) * 0.018
    with pytest.raises(ValueError, match=match):
        hr.Hologram(np.zeros((12, 12)), x, x, 7e9, tx_offset=offset)


def test_what_has_no_model_of_the_offset_refuses_it():
    h = _point((0.0, 0.0, 0.2))
    x = h.x
    with pytest.raises(ValueError, match="no separate source"):
        hr.Hologram(h.data, x, x, F, tx_offset=OFFSET, source=hr.PlaneWave())
    with pytest.raises(ValueError, match="tx_offset"):
        hr.propagate(h, 0.05)
    with pytest.raises(ValueError, match="does not model a transmitter"):
        hr.migrate(h, [0.1, 0.2], algorithm="columns")
    with pytest.raises(ValueError, match="planes beyond the antennas"):
        hr.migrate(h, [0.0, 0.2])
    with pytest.raises(ValueError, match="transmitter above the ground"):
        hr.migrate(h.replace(tx_offset=(0.12, 0, 0.06)), [0.1, 0.2],
                   medium=hr.Medium.half_space(0.05, 4.0))
    with pytest.raises(ValueError, match="polarization"):
        hr.simulate(hr.Scene(targets=[hr.PointTarget((0, 0, 0.2))]),
                    hr.Aperture.grid(12, 0.018, tx_offset=OFFSET, polarization=(0, 1, 0)), F)


def test_a_bistatic_scan_in_a_matlab_struct_is_imaged_from_the_command_line(tmp_path):
    """An inverse-SAR export (a MATLAB struct, receiver positions in mm) read with a
    layout that gives the offset in the file's unit: the command line's image is the
    library's, its brightest point on the target (within a pixel laterally)."""
    from scipy.io import savemat

    from cli_helpers import run

    target = (0.027, -0.009, 0.17)
    h = _point(target)
    p = tmp_path / "tape.mat"
    savemat(p, {"data": {"measurements": np.moveaxis(h.data, 0, -1), "x": h.x * 1e3,
                         "y": h.y * 1e3, "f": F}})
    layout = ("data=data.measurements, x=data.x, y=data.y, frequency=data.f, axes=yxf, "
              "units=mm, iq_sign=I+iQ, tx_offset=[120, 0, 0]")
    loaded = hr.load(p, layout=layout)
    assert loaded.tx_offset == pytest.approx(OFFSET)
    run("image", p, "--layout", layout, "--z", "0.1:0.25:0.005", "--out", tmp_path / "i.nc")
    img = hr.load(tmp_path / "i.nc")
    up = (img.x.size - 1) // (loaded.x.size - 1)   # the command's own upsampling
    ref = hr.migrate(loaded, np.arange(0.1, 0.25 + 1e-9, 0.005), upsample=up)
    np.testing.assert_allclose(img.data, ref.data, rtol=0, atol=1e-9 * np.abs(ref.data).max())
    x, y, _ = _peak(img)
    assert abs(x - target[0]) <= 0.018 and abs(y - target[1]) <= 0.018


def test_a_raised_transmitter_through_the_ground_is_simulates_point_target():
    """The transmitter's height dz through a layered ground: a voxel on the target maps to
    simulate's field (the bound of test_forward_is_simulates_point_target: each leg's
    radial profile interpolated on a sixteenth of the wavelength, ~1e-3). A kernel that
    drops dz (the transmitter's leg from the elements' plane) is off by O(1): the leg
    is 3 cm, several wavelengths of phase, shorter."""
    med = hr.Medium.half_space(0.08, 5 + 0.3j)
    offset = (0.05, 0.0, 0.03)
    target = (-0.009 + 0.018 * 2, 0.009, 0.16)
    h = _point(target, med, offset=offset)
    A = migration_operator(h, [0.12, 0.16], medium=med, scatterer="point")
    r = np.zeros(A.image_shape, complex)
    ix = int(np.argmin(np.abs(A.x - target[0])))
    iy = int(np.argmin(np.abs(A.y - target[1])))
    r[1, iy, ix] = 1.0
    fwd = (A @ r.ravel()).reshape(h.shape)
    assert np.linalg.norm(fwd - h.data) / np.linalg.norm(h.data) <= 1e-3


def test_the_sign_check_runs_through_the_two_leg_kernel(tmp_path):
    # A transmitter beside the receiver: the check images through the offset kernel
    # (the footprint only) and answers both conventions; a file read without iq_sign
    # whose data are I - jQ is said to be so.
    h = _point((0.009, 0.0, 0.3), snr_db=30, seed=1)
    z = [0.25, 0.3, 0.35]
    assert hr.check_iq_sign(h, z).sign == "I+iQ"
    assert hr.check_iq_sign(hr.conjugate(h), z).sign == "I-iQ"
    np.savez(tmp_path / "isar.npz", data=np.conj(h.data), x=h.x * 1000, y=h.y * 1000,
             f=F / 1e9)
    with pytest.warns(hr.IQSignWarning, match="iq_sign=I-iQ"):
        hr.load(tmp_path / "isar.npz", layout="frequency=f, frequency_unit=GHz, units=mm, "
                "axes=fyx, tx_offset=[120, 0, 0]")
