"""Oblique sounding: poses, a tilted aperture imaged onto horizontal ground planes.

Independent checks: the exact layered Green's function (Sommerfeld integral, a
different code path from the FFT grid), SMUTHI's tilted-array fixture S7, and
the frontal migration (which the ground frame must reproduce for a level
aperture).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import holoradar as hr
from holoradar.imaging.migration.backends.oblique_sum import sum_to_plane
from holoradar.physics.green import layered_green
from holoradar.theory import range_resolution

F0 = 9.9e9


def _spectrum_on_plane(h: hr.Hologram, grid, pitch, origin, work, *, gap: float,
                       route: str = "auto") -> np.ndarray:
    """The ground frame's spectrum sum of every frame of ``h`` (its own wavenumber, the
    round trip's for a transceiver), shaped (..., My, Mx)."""
    kk = 2 * h.k if h.monostatic else h.k
    d = h.data.reshape(-1, *h.data.shape[-2:])
    H = sum_to_plane(h, d, kk, grid, pitch, origin, np.dtype(work), gap, route)
    return H.reshape((*h.data.shape[:-2], *grid))
K0 = 2 * np.pi * F0 / hr.C0
DATA = Path(__file__).parent / "data"


# ----------------------------------------------------------------------------- Pose
def test_pose_axes_follow_the_documented_rotation():
    """R = Rz(phi) Ry(theta) Rz(-phi): normal (sin t cos p, sin t sin p, cos t); for
    phi = 0 the x' axis is (cos t, 0, -sin t) and y' = +y; for phi = 90 deg x' = +x."""
    t = np.radians(35)
    p0 = hr.Pose(tilt=t, azimuth=0.0)
    np.testing.assert_allclose(p0.normal, [np.sin(t), 0, np.cos(t)], atol=1e-15)
    np.testing.assert_allclose(p0.u, [np.cos(t), 0, -np.sin(t)], atol=1e-15)
    np.testing.assert_allclose(p0.v, [0, 1, 0], atol=1e-15)
    p90 = hr.Pose(tilt=t, azimuth=np.pi / 2)
    np.testing.assert_allclose(p90.u, [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(p90.v, [0, np.cos(t), -np.sin(t)], atol=1e-15)
    for p in (p0, p90, hr.Pose(tilt=0.3, azimuth=2.1)):
        R = p.rotation
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-15)
        assert np.linalg.det(R) == pytest.approx(1.0)


@pytest.mark.parametrize("kw, match", [
    ({"tilt": np.pi / 2}, "tilt"), ({"tilt": -0.1}, "tilt"), ({"tilt": float("nan")}, "tilt"),
    ({"center": (0, 0)}, "center"), ({"center": (0, 0, np.inf)}, "center"),
    ({"azimuth": "north"}, "azimuth"),
])
def test_pose_refuses_bad_input(kw, match):
    with pytest.raises(ValueError, match=match):
        hr.Pose(**kw)


def test_posed_points_and_identity():
    ap = hr.Aperture.grid(4, 0.01)
    np.testing.assert_array_equal(ap.points[:, 2], 0.0)
    pose = hr.Pose((0.1, -0.2, 0.05), tilt=np.radians(40), azimuth=np.radians(90))
    posed = hr.Aperture.grid(4, 0.01, pose=pose)
    expect = pose.center + ap.points[:, :1] * pose.u + ap.points[:, 1:2] * pose.v
    np.testing.assert_allclose(posed.points, expect, atol=1e-15)
    h = hr.Hologram(np.zeros((4, 4)), ap.x, ap.y, F0, pose=pose)
    np.testing.assert_allclose(h.points, posed.points)
    assert h.with_data(np.ones((4, 4))).pose == pose
    with pytest.raises(ValueError, match="pose"):
        hr.Hologram(np.zeros((4, 4)), ap.x, ap.y, F0, pose="tilted")


def test_elements_below_the_surface_are_refused():
    med = hr.Medium.half_space(0.1, 2.5)
    pose = hr.Pose((0.0, 0.0, 0.08), tilt=np.radians(40))   # one edge dips 0.16*0.64 m
    ap = hr.Aperture.grid(16, 0.02, pose=pose)
    scene = hr.Scene(med, hr.PlaneWave(), [hr.PointTarget((0, 0, 0.3))])
    with pytest.raises(ValueError, match="above the ground surface"):
        hr.simulate(scene, ap, F0)
    h = hr.Hologram(np.ones((16, 16)), ap.x, ap.y, F0, pose=pose)
    with pytest.raises(ValueError, match="pose"):
        hr.migrate(h, 0.3, medium=med, frame="ground")


def test_migrate_frame_errors():
    pose = hr.Pose((0.0, 0.0, 0.05), tilt=0.5)
    x = np.arange(8) * 0.01
    h = hr.Hologram(np.ones((8, 8)), x, x, F0, pose=pose)
    with pytest.raises(ValueError, match="frame"):
        hr.migrate(h, 0.3, frame="world")
    with pytest.raises(ValueError, match="frame='ground'"):
        hr.migrate(h, 0.3, medium=hr.Medium.half_space(0.2, 2.5))
    with pytest.raises(ValueError, match="z must lie below"):
        hr.migrate(h, 0.04, frame="ground")
    with pytest.raises(ValueError, match="x and y"):
        hr.migrate(h, 0.3, x=x)


# ------------------------------------------------------------------- the ground frame
def test_level_aperture_spectrum_is_the_fft_of_the_data():
    """The exact spectral remap, for a level aperture whose elements sit on the
    world grid, is the zero-padded FFT of the data (what the frontal migration
    transforms): equal to rounding, 1e-12 of the largest value; everything after
    it is the frontal pipeline (same transfer functions)."""
    rng = np.random.default_rng(3)
    x = (np.arange(12) - 5.5) * 0.015
    y = (np.arange(10) - 4.5) * 0.015
    data = rng.standard_normal((10, 12)) + 1j * rng.standard_normal((10, 12))
    h = hr.Hologram(data, x, y, F0, pose=hr.Pose((0.0, 0.0, 0.04)))
    grid = (32, 36)
    H = _spectrum_on_plane(h, grid, (0.015, 0.015), (x[0], y[0], 0.04),
                           np.dtype(complex), gap=1.0)
    ref = np.fft.fft2(data, s=grid)
    kept = H != 0          # air-evanescent components damped below 1e-8 are left out
    np.testing.assert_allclose(H[kept], ref[kept], rtol=0, atol=1e-12 * np.abs(ref).max())
    p, q = np.meshgrid(2 * np.pi * np.fft.fftfreq(36, 0.015),
                       2 * np.pi * np.fft.fftfreq(32, 0.015))
    assert np.all(kept[p**2 + q**2 <= K0**2])


def _kernel_error(pose, medium, pad, z=0.40, n=20, pitch=0.012, step=3):
    """RMS of (ground-frame image - exact adjoint) / RMS of the exact adjoint.

    The exact adjoint of the field at the elements: the image of a plane is
    sum_e d_e conj(K(r_e, r)), K the field at r_e of a unit *plane* sample at r,
    which by Weyl's expansion is -(dx dy / 2 pi) dG/dz_s (the z-derivative of the
    point-source Green's function at the source r): computed here by the
    Sommerfeld integral, independently of the FFT grid.
    """
    ap = hr.Aperture.grid(n, pitch, pose=pose)
    scene = hr.Scene(medium, hr.PlaneWave(), [hr.PointTarget((0.01, 0.0, z))])
    h = hr.simulate(scene, ap, F0, include_surface=False)
    img = hr.migrate(h, z, medium=medium, frame="ground", compensate_loss=False, pad=pad)
    dxy = (img.x[1] - img.x[0]) * (img.y[1] - img.y[0])
    pts, d = h.points, h.data.ravel()
    ours, ref = [], []
    for iy in range(0, img.y.size, step):
        for ix in range(0, img.x.size, step):
            r = np.array([img.x[ix], img.y[iy], z])
            dz = np.array([0.0, 0.0, 1e-5])
            dG = (layered_green(K0, medium, r + dz, pts)
                  - layered_green(K0, medium, r - dz, pts)) / (2 * dz[2])
            ref.append(np.sum(d * np.conj(-dxy / (2 * np.pi) * dG)))
            ours.append(img.data[iy, ix])
    ours, ref = np.array(ours), np.array(ref)
    return np.linalg.norm(ours - ref) / np.linalg.norm(ref)


def test_tilted_aperture_matches_the_exact_layered_adjoint():
    """A 35-degree aperture over lossy sand. The FFT grid is periodic and its band
    limit tapered; the taper touches only components no pixel-element pair needs,
    so the error is the taper's ringing, which has no closed form and falls as the
    grid grows. Measured: 0.77% RMS on the default grid (M d >= 4x the largest
    element-pixel offset), 0.25% with 8x padding; a level aperture at the same
    height: 0.23%. Bound: 2% (0.5% level); that a larger grid converges, which shows the remap
    itself exact, is the slow test below. A wrong sign of the air term fails it (and
    the focusing tests)."""
    sand = hr.Medium.half_space(0.3, 2.5 + 0.05j)
    tilted = hr.Pose((0.0, -0.12, 0.08), tilt=np.radians(35), azimuth=np.radians(90))
    assert _kernel_error(tilted, sand, True) < 0.02
    assert _kernel_error(hr.Pose((0.0, 0.0, 0.08)), sand, True) < 0.005


@pytest.mark.slow
def test_tilted_aperture_adjoint_converges_as_the_grid_grows():
    """The same case on a grid padded 8x: at least twice closer (0.25% measured against
    0.77%), and within 1%: the convergence shows the remap itself exact (slow: the
    padded grid is 64x larger)."""
    sand = hr.Medium.half_space(0.3, 2.5 + 0.05j)
    tilted = hr.Pose((0.0, -0.12, 0.08), tilt=np.radians(35), azimuth=np.radians(90))
    e_default = _kernel_error(tilted, sand, True)
    e_big = _kernel_error(tilted, sand, 8.0)
    assert e_big < 0.01 and e_big < e_default / 2


@pytest.mark.parametrize("eps", [2.5, 6.0])
def test_point_seen_from_a_tilted_aperture_focuses_in_3d(eps):
    """9 frequencies (8-12 GHz), a 32 x 32 array at 12 mm tilted 35 degrees, point
    0.12 m under the surface. Bounds from the issue: lateral lambda_m/2 (centre
    frequency), range a quarter of the depth response 2 pi/dKz, dKz = (2 pi B/c)
    Re(n) (1 + cos theta_r) for normal illumination and the receive direction
    theta_r refracted from the array's 35 degrees (range_resolution with that
    incidence). Pixels 3 mm, planes 2 mm: both below the bounds. Migrated without
    the medium the point lands far off (reported in the note)."""
    med = hr.Medium.half_space(0.3, eps)
    target = np.array([0.02, -0.01, 0.42])
    scene = hr.Scene(med, hr.PlaneWave(), [hr.PointTarget(tuple(target))])
    freqs = np.linspace(8e9, 12e9, 9)
    pose = hr.Pose((0.0, -0.15, 0.05), tilt=np.radians(35), azimuth=np.radians(90))
    h = hr.simulate(scene, hr.Aperture.grid(32, 0.012, pose=pose), freqs,
                    include_surface=False)
    zs = np.arange(0.39, 0.45, 0.002)
    x = np.arange(-0.04, 0.08, 0.003)
    y = np.arange(-0.07, 0.05, 0.003)
    img = hr.migrate(h, zs, medium=med, frame="ground", x=x, y=y)
    px, py, pz = img.peak()
    lam_m = hr.C0 / 10e9 / np.sqrt(eps)
    theta_r = np.arcsin(np.sin(np.radians(35)) / np.sqrt(eps))
    depth_cell = range_resolution(4e9, eps, monostatic=False, incidence=theta_r)
    assert np.hypot(px - target[0], py - target[1]) <= lam_m / 2
    assert abs(pz - target[2]) <= depth_cell / 4
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        wrong = hr.migrate(h, np.arange(0.2, 0.46, 0.01), frame="ground", x=x, y=y).peak()
    miss = np.linalg.norm(np.array(wrong) - target)
    assert miss > 4 * depth_cell


def test_smuthi_tilted_array_sphere():
    """SMUTHI S7: a metal sphere (r = 12 mm, centre 12 cm deep in sand 2.5+0.0125i)
    seen by a 24 x 24 array tilted 40 degrees; one frequency. Frames: SMUTHI has z
    up and the surface at 0; here z is the range, so z = 0.4 - z_smuthi with the
    surface at 0.4 m, and the array's axes u = +x, v = (0, cos 40, -sin 40) are the
    pose tilt = 40 deg, azimuth = 90 deg (the element positions must match the
    fixture's to 1e-12). A sphere images at its bright point, the surface point
    facing the array: centre - r * (refracted viewing direction). One frequency
    does not fix the depth along the line of sight, so the check is on the plane
    of that point: the peak within lambda_m/2 of it laterally. Without the medium
    it lands several centimetres away."""
    d = np.load(DATA / "S7_tilted_array_sphere.npz")
    surf = 0.4
    c = d["centre_m"]
    pose = hr.Pose((c[0], c[1], surf - c[2]), tilt=np.radians(40), azimuth=np.radians(90))
    h = hr.Hologram(d["E_scat"][0], d["x_local_m"], d["y_local_m"], F0, pose=pose)
    fixture_points = d["points_m"].copy()
    fixture_points[..., 2] = surf - fixture_points[..., 2]
    np.testing.assert_allclose(h.points.reshape(24, 24, 3), fixture_points, atol=1e-12)
    eps = 2.5 + 0.0125j
    med = hr.Medium.half_space(surf, eps)
    sin_t = np.sin(np.radians(40)) / np.sqrt(eps.real)
    view = np.array([0.0, sin_t, np.sqrt(1 - sin_t**2)])
    bright = np.array([-0.03, 0.02, surf + 0.12]) - 0.012 * view
    lam_m = hr.C0 / F0 / np.sqrt(eps.real)
    errors = {}
    for name, medium in (("sand", med), ("none", None)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            img = hr.migrate(h, bright[2], medium=medium, frame="ground", upsample=3)
        a = np.abs(img.data)
        iy, ix = np.unravel_index(a.argmax(), a.shape)
        errors[name] = np.hypot(img.x[ix] - bright[0], img.y[iy] - bright[1])
    assert errors["sand"] <= lam_m / 2
    assert errors["none"] > 2 * lam_m


@pytest.mark.parametrize("azimuth_deg", [0.0, 90.0, 30.0])
def test_spectrum_on_the_reference_plane_is_the_direct_sum(azimuth_deg):
    """The factored non-uniform Fourier sum (by grid rows, by grid columns, or in
    full, depending on the pose) equals the direct sum over the elements,
    H(k) = sum_e d_e exp(-i [p (x_e - x0) + q (y_e - y0) + conj(kz) (z_ref - z_e)]),
    to rounding (1e-12 of the largest value)."""
    rng = np.random.default_rng(1)
    x = (np.arange(10) - 4.5) * 0.015
    y = (np.arange(8) - 3.5) * 0.015
    d = rng.standard_normal((8, 10)) + 1j * rng.standard_normal((8, 10))
    pose = hr.Pose((0.01, -0.02, 0.05), tilt=np.radians(35), azimuth=np.radians(azimuth_deg))
    h = hr.Hologram(d, x, y, F0, pose=pose)
    origin = (-0.1, -0.1, 0.2)
    H = _spectrum_on_plane(h, (40, 44), (0.01, 0.012), origin, np.dtype(complex), gap=0.2)
    P, Q = np.meshgrid(2 * np.pi * np.fft.fftfreq(44, 0.01), 2 * np.pi * np.fft.fftfreq(40, 0.012))
    kz = np.sqrt((K0**2 - P**2 - Q**2).astype(complex))
    kz = np.where(kz.imag < 0, -kz, kz)
    ref = np.zeros_like(H)
    for de, (px, py, pz) in zip(d.ravel(), h.points, strict=True):
        ref += de * np.exp(-1j * (P * (px - origin[0]) + Q * (py - origin[1])
                                  + np.conj(kz) * (origin[2] - pz)))
    kept = H != 0
    assert np.all(kept[P**2 + Q**2 <= K0**2])
    np.testing.assert_allclose(H[kept], ref[kept], rtol=0, atol=1e-12 * np.abs(ref).max())


# ----------------------------------------------------------------------------- planner
def _layouts(m: float, horn_height: float = 0.05):
    """The paper's two layouts over sand (surface 0.30 m), a target at 0.42 m, the
    horn aimed at it: frontal (array level at z = 0, horn beside it in its plane)
    and oblique (array tilted 35 degrees, horn low in front of it)."""
    target = np.array([0.0, 0.05, 0.42])
    front_ap = hr.Aperture.grid(16, 0.025)
    front_pos = np.array([0.0, 0.25, 0.0])
    pose = hr.Pose((0.0, -0.15, 0.05), tilt=np.radians(35), azimuth=np.radians(90))
    obl_ap = hr.Aperture.grid(16, 0.025, pose=pose)
    obl_pos = np.array([0.0, -0.08, 0.30 - horn_height])
    horn = {name: hr.PointSource(tuple(pos), pattern_exponent=m, axis=tuple(target - pos))
            for name, pos in (("frontal", front_pos), ("oblique", obl_pos))}
    return target, {"frontal": (front_ap, horn["frontal"]), "oblique": (obl_ap, horn["oblique"])}


SAND_LOSSY = hr.Medium.half_space(0.30, 2.5 + 0.0125j)


@pytest.mark.parametrize("m", [4, 20])
def test_planner_glare_fraction_agrees_with_the_simulated_field(m):
    """The planner's glare fraction is geometric optics (rays from the horn's
    mirror image, weighted by the pattern and |r(theta)|^2, counted where they
    cross the elements' rectangle). The simulation gives the power crossing the
    elements from the exact reflected field, sum |E_r|^2 A cos(psi), over the same
    total. They differ by the near-field terms of the spherical wave (order
    1/(k R)^2 ~ 3e-4 at R = 0.3 m) and the variation of |r| and the pattern
    across one element (a few hundredths of a dB): bound 0.3 dB."""
    target, layouts = _layouts(m)
    for aperture, horn in layouts.values():
        plan = hr.plan_oblique(aperture, horn, SAND_LOSSY, target)
        g = hr.simulate(hr.Scene(SAND_LOSSY, horn, []), aperture, F0).data.ravel()
        mirror = np.array([*horn.position[:2], 0.6 - horn.position[2]])
        rays = aperture.points - mirror
        cos = np.abs(rays @ aperture.pose.normal) / np.linalg.norm(rays, axis=1)
        area = aperture.size[0] / 16 * aperture.size[1] / 16
        th = np.linspace(0, np.pi / 2, 721)[1:-1]
        ph = np.linspace(0, 2 * np.pi, 721)[:-1]
        T, P = np.meshgrid(th, ph, indexing="ij")
        d = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
        pat = np.abs(horn.pattern(d.reshape(-1, 3))).reshape(T.shape) ** 2
        r2 = np.abs(SAND_LOSSY.reflection(K0, (K0 * np.sin(T)) ** 2)) ** 2
        total = np.sum(r2 * pat * np.sin(T)) * (th[1] - th[0]) * (ph[1] - ph[0])
        simulated = np.sum(np.abs(g) ** 2 * cos) * area / total
        assert abs(10 * np.log10(plan.glare_fraction / simulated)) < 0.3


def test_oblique_layout_keeps_the_glare_out():
    """A horn of 20 degrees half-power beamwidth (cos^20), 5 cm above the sand: the
    reflection misses the tilted array (planner: positive miss distance) and the
    simulated glare power at its elements is at least 20 dB below the frontal
    layout's (paper Sec. 3.4); the frontal reflection lands on its array."""
    target, layouts = _layouts(20, horn_height=0.05)
    power = {}
    for name, (aperture, horn) in layouts.items():
        plan = hr.plan_oblique(aperture, horn, SAND_LOSSY, target)
        assert (plan.miss_distance > 0) == (name == "oblique")
        g = hr.simulate(hr.Scene(SAND_LOSSY, horn, []), aperture, F0).data
        power[name] = np.sum(np.abs(g) ** 2)
    assert 10 * np.log10(power["frontal"] / power["oblique"]) >= 20


def test_planner_refuses_bad_layouts():
    target, layouts = _layouts(20)
    aperture, horn = layouts["oblique"]
    with pytest.raises(ValueError, match="source"):
        hr.plan_oblique(aperture, hr.PointSource((0, 0, 0.35)), SAND_LOSSY, target)
    with pytest.raises(ValueError, match="source"):
        hr.plan_oblique(aperture, hr.PlaneWave(), SAND_LOSSY, target)
    with pytest.raises(ValueError, match="target"):
        hr.plan_oblique(aperture, horn, SAND_LOSSY, (0.0, 0.0, 0.2))
    with pytest.raises(ValueError, match="field of view"):
        hr.plan_oblique(aperture, horn, SAND_LOSSY, (0.0, -0.9, 0.35))
    low = hr.Aperture.grid(16, 0.025, pose=hr.Pose((0, 0, 0.28), tilt=np.radians(40)))
    with pytest.raises(ValueError, match="aperture"):
        hr.plan_oblique(low, horn, SAND_LOSSY, target)


def test_views_of_a_tilted_array_synthesize_on_ground_planes():
    """Five horn positions along the ground, one tilted array: each view's incident
    field is removed on the ground plane (world frame), the views add coherently
    and the point sits at the peak (within a 3 mm pixel); views need one pose,
    tilted views need frame='ground'."""
    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    target = np.array([0.0, 0.0, 0.41])
    normal = np.array([0.0, np.sin(np.radians(35)), np.cos(np.radians(35))])
    pose = hr.Pose(tuple(target - 0.35 * normal), tilt=np.radians(35), azimuth=np.radians(90))
    ap = hr.Aperture.grid(16, 0.025, pose=pose)
    views = []
    for x0 in np.linspace(-0.15, 0.15, 5):
        pos = np.array([x0, -0.12, 0.25])
        horn = hr.PointSource(tuple(pos), pattern_exponent=4, axis=tuple(target - pos))
        views.append(hr.simulate(hr.Scene(sand, horn, [hr.PointTarget(tuple(target))]), ap, F0,
                                 include_surface=False))
    x = y = np.arange(-0.06, 0.0601, 0.003)
    img, each = hr.synthesize(views, target[2], medium=sand, frame="ground", x=x, y=y,
                              return_views=True)
    px, py, _ = img.peak()
    assert np.hypot(px - target[0], py - target[1]) <= 0.003
    # In phase: at the point every view is a |E0_k| PSF(0) with the incident phase
    # removed, so |sum| = sum |.| but for the phase slope across the one pixel
    # between the grid point and the target: > 0.95 (random phases: ~1/sqrt(5)).
    iy, ix = np.unravel_index(np.abs(img.data).argmax(), img.data.shape)
    assert abs(img.data[iy, ix]) > 0.95 * np.abs(each[:, iy, ix]).sum()
    with pytest.raises(ValueError, match="frame='ground'"):
        hr.synthesize(views, target[2], medium=sand)
    other = views[1].replace(pose=hr.Pose(pose.center, tilt=np.radians(30),
                                          azimuth=np.radians(90)))
    with pytest.raises(ValueError, match="pose"):
        hr.synthesize([views[0], other], target[2], medium=sand, frame="ground")


def test_horn_positions_summed_recover_a_disk():
    """Paper Figs. 21-22, simulated: an 18 cm metal disk 11 cm under sand, a 16 x 16
    array tilted 35 degrees, a cos^4 horn 5 cm above the sand moved to 8 positions
    (two sides, Y0 = -15 ... +15 cm). One view images one edge spot; the amplitude
    sum draws the rim. A circle through the pixels above half the maximum
    (``circle_fit``) recovers the diameter within 20% and the centre within 2 cm
    (the issue's bounds); for a single view it does not. Measured (14 positions,
    examples/oblique_disk.py): 17.3 cm and 5 mm; a single view 3.0 cm and 9 cm."""
    from holoradar.analysis.metrics import circle_fit

    sand = hr.Medium.half_space(0.30, 2.5 + 0.0125j)
    depth, diameter = 0.41, 0.18
    disk = hr.PlanarTarget.from_shape("disk", depth, diameter=diameter, reflection=-1.0,
                                      pixel=0.004)
    normal = np.array([0.0, np.sin(np.radians(35)), np.cos(np.radians(35))])
    pose = hr.Pose(tuple(np.array([0, 0, depth]) - 0.35 * normal), tilt=np.radians(35),
                   azimuth=np.radians(90))
    ap = hr.Aperture.grid(16, 0.025, pose=pose)
    views = []
    for y0 in np.linspace(-0.15, 0.15, 4):
        for side in (-0.25, 0.25):
            pos = np.array([side, y0, 0.25])
            horn = hr.PointSource(tuple(pos), pattern_exponent=4,
                                  axis=tuple(np.array([0.0, 0.0, depth]) - pos))
            views.append(hr.simulate(hr.Scene(sand, horn, [disk]), ap, F0,
                                     include_surface=False))
    x = y = np.arange(-0.2, 0.2, 0.005)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)   # the paper's 2.5 cm pitch
        total = hr.synthesize(views, depth, medium=sand, mode="amplitude", frame="ground",
                              x=x, y=y)
        single = hr.migrate(views[0], depth, medium=sand, frame="ground", x=x, y=y)
    d, cx, cy = circle_fit(total.data, x, y)
    assert abs(d / diameter - 1) <= 0.2 and np.hypot(cx, cy) <= 0.02
    d1, cx1, cy1 = circle_fit(single.data, x, y)
    assert abs(d1 / diameter - 1) > 0.2 or np.hypot(cx1, cy1) > 0.02


@pytest.mark.parametrize("target", [(0.0, 0.05, 0.42), (0.0, 0.0, 0.45)])
def test_effective_distance_is_where_a_free_space_sweep_focuses(target):
    """The paper's depth sweep: planes parallel to the tilted array, no medium. A
    point in sand focuses (one frequency, peak of |image|) at the planner's
    effective distance along the ray, projected on the normal, nearer by the
    finite-aperture focal shift (theory.focal_shift; 1.4-1.5 cm here). Bound: a
    quarter of the longitudinal resolution (12.7 cm for this 40 cm array at
    0.37 m). Measured: 1.1 and 1.5 cm off."""
    from holoradar import theory

    sand = hr.Medium.half_space(0.30, 2.5)
    pose = hr.Pose((0.0, -0.15, 0.05), tilt=np.radians(35), azimuth=np.radians(90))
    ap = hr.Aperture.grid(32, 0.0125, pose=pose)
    horn_at = np.array([0.0, -0.08, 0.25])
    horn = hr.PointSource(tuple(horn_at), pattern_exponent=4,
                          axis=tuple(np.array(target) - horn_at))
    plan = hr.plan_oblique(ap, horn, sand, target)
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget(target)]), ap, F0,
                    include_surface=False)
    zs = np.arange(0.2, 0.6, 0.002)
    img = hr.migrate(h, zs, upsample=2)
    iz = np.unravel_index(np.abs(img.data).argmax(), img.data.shape)[0]
    ray = plan.refraction_point - np.asarray(pose.center)
    along = plan.effective_distance * (ray @ pose.normal) / np.linalg.norm(ray)
    lam = hr.C0 / F0
    expected = along + theory.focal_shift(lam, plan.effective_distance, ap.size[0])
    assert abs(zs[iz] - expected) <= theory.longitudinal_resolution(
        lam, plan.effective_distance, ap.size[0]) / 4


def test_level_aperture_at_a_height_in_its_own_frame():
    """A level array 8 cm below the reference plane, 7 frequencies: in its own frame
    the planes are distances from it, the layers are seen from its height, and the
    frequencies are phased by the incident field at the pixels' world positions.
    The point 0.42 m deep (0.34 m from the array) focuses there, as in the ground
    frame (2 mm planes: to the plane)."""
    sand = hr.Medium.half_space(0.3, 2.5)
    target = (0.02, -0.01, 0.42)
    pose = hr.Pose((0.0, 0.0, 0.08))
    h = hr.simulate(hr.Scene(sand, hr.PlaneWave(), [hr.PointTarget(target)]),
                    hr.Aperture.grid(24, 0.012, pose=pose), np.linspace(8e9, 12e9, 7),
                    include_surface=False)
    own = hr.migrate(h, np.arange(0.30, 0.38, 0.002), medium=sand)
    ground = hr.migrate(h, np.arange(0.38, 0.46, 0.002), medium=sand, frame="ground")
    assert own.peak()[2] + 0.08 == pytest.approx(target[2], abs=1e-9)
    assert ground.peak()[2] == pytest.approx(target[2], abs=1e-9)


# ------------------------------------------------------------ review fixes, each guarded
def test_plane_wave_above_the_reference_plane_lags_in_phase():
    """A plane wave exp(i(p0 x + kz0 z)) has phase kz0 z < 0 at z < 0 (above the
    reference plane, where a raised or tilted aperture's elements lie): closed form."""
    pw = hr.PlaneWave(np.radians(20), 0.0)
    med = hr.Medium.half_space(0.3, 2.5)
    pts = np.array([[0.01, 0.02, -0.1], [0.0, 0.0, -0.03], [0.02, 0.0, 0.1]])
    p0 = K0 * np.sin(np.radians(20))
    kz0 = K0 * np.cos(np.radians(20))
    expect = np.exp(1j * (p0 * pts[:, 0] + kz0 * pts[:, 2]))
    np.testing.assert_allclose(pw.field(K0, med, pts), expect, rtol=1e-12)


def test_raised_level_views_synthesize_in_their_own_frame():
    """Three horn positions, one level array raised 10 cm above the reference plane:
    in the aperture's own frame the incident phase is taken at the pixels' world
    positions, so at the point (a pixel of the 2 mm grid) each view is |E0_i| times
    the same PSF(0), and the views add in phase: |sum| = sum |.| up to rounding
    (measured 1.0, bound 0.999). Incident fields taken at the aperture-local
    coordinates miss by the 10 cm height: measured 0.89."""
    sand = hr.Medium.half_space(0.3, 2.5)
    target = (0.0, 0.0, 0.40)
    ap = hr.Aperture.grid(20, 0.012, pose=hr.Pose((0.0, 0.0, -0.10)))
    views = [hr.simulate(hr.Scene(sand, hr.PointSource((x0, -0.15, -0.05)),
                                  [hr.PointTarget(target)]), ap, F0, include_surface=False)
             for x0 in (-0.2, 0.0, 0.2)]
    img, each = hr.synthesize(views, 0.50, medium=sand, upsample=6, return_views=True)
    iy, ix = np.unravel_index(np.abs(img.data).argmax(), img.data.shape)
    assert np.hypot(img.x[ix] - target[0], img.y[iy] - target[1]) <= 0.003
    assert abs(img.data[iy, ix]) > 0.999 * np.abs(each[:, iy, ix]).sum()


def test_default_ground_grid_covers_the_footprint_of_a_raised_tilted_array():
    """The corners carried along the normal through 20 cm of air above z = 0 and on
    into the sand (Snell): the grid must reach every such point (within a pitch)."""
    from holoradar.imaging.migration.backends.oblique import ground_grid

    sand = hr.Medium.half_space(0.3, 4.0)
    pose = hr.Pose((0.0, 0.0, -0.2), tilt=np.radians(35))
    ap = hr.Aperture.grid(8, 0.02, pose=pose)
    h = hr.Hologram(np.ones((8, 8)), ap.x, ap.y, F0, pose=pose)
    zs = np.array([0.35, 0.5])
    gx, gy = ground_grid(h, zs, sand)
    n = pose.normal
    s_t = n[0] / 2.0                      # sin(theta) in the sand, n = 2
    for c in ap.points[[0, 7, -8, -1]]:
        for z in zs:
            x = c[0] + (0.3 - c[2]) * n[0] / n[2] + (z - 0.3) * s_t / np.sqrt(1 - s_t**2)
            assert gx[0] - 1e-9 <= x <= gx[-1] + 0.02
            assert gy[0] - 1e-9 <= c[1] <= gy[-1] + 0.02


def test_streaming_refuses_posed_views():
    x = (np.arange(8) - 3.5) * 0.01
    h = hr.Hologram(np.ones((8, 8), complex), x, x, F0, source=hr.PointSource((0, 0, -0.1)),
                    pose=hr.Pose((0.0, 0.0, -0.05)))
    with pytest.raises(ValueError, match=r"views\[0\]\.pose"):
        hr.StreamImager([h], 0.3, hr.Medium.half_space(0.2, 2.5))


@pytest.mark.parametrize("kw, match", [
    ({"fov": "full"}, "fov"), ({"upsample": 1.5}, "upsample"),
    ({"upsample": 2, "x": np.arange(4) * 0.01, "y": np.arange(4) * 0.01}, "upsample"),
    ({"dtype": np.float64}, "dtype"),
])
def test_ground_frame_refuses_bad_options(kw, match):
    pose = hr.Pose((0.0, 0.0, 0.05), tilt=0.5)
    x = np.arange(8) * 0.01
    h = hr.Hologram(np.ones((8, 8)), x, x, F0, pose=pose)
    with pytest.raises(ValueError, match=match):
        hr.migrate(h, 0.3, frame="ground", **kw)


def test_planner_traces_the_ray_through_every_layer():
    """Straight down (level array over the target) the apparent distance is the
    closed form h_air + sum h_j/n_j; a half-space split by an interface between two
    equal layers plans exactly as the half-space; a faster lower layer shortens the
    apparent distance of an oblique target as Snell says."""
    ap = hr.Aperture.grid(16, 0.02, pose=hr.Pose((0.0, 0.0, 0.1)))
    horn = hr.PointSource((0.0, -0.3, 0.2), axis=(0.0, 0.5, 0.1))
    two = hr.Medium((0.3, 0.4), (1.0, 2.5, 6.25))
    plan = hr.plan_oblique(ap, horn, two, (0.0, 0.0, 0.5))
    expect = 0.2 + 0.1 / np.sqrt(2.5) + 0.1 / 2.5
    assert plan.sagittal_distance == pytest.approx(expect, rel=1e-9)
    assert plan.tangential_distance == pytest.approx(expect, rel=1e-9)
    tilted = hr.Aperture.grid(16, 0.02, pose=hr.Pose((0.0, -0.2, 0.1), tilt=np.radians(35),
                                                      azimuth=np.radians(90)))
    target = (0.0, 0.05, 0.5)
    one = hr.plan_oblique(tilted, horn, hr.Medium.half_space(0.3, 2.5), target)
    split = hr.plan_oblique(tilted, horn, hr.Medium((0.3, 0.4), (1.0, 2.5, 2.5)), target)
    for a, b in ((one.sagittal_distance, split.sagittal_distance),
                 (one.tangential_distance, split.tangential_distance)):
        assert a == pytest.approx(b, rel=1e-9)
    np.testing.assert_allclose(one.refraction_point, split.refraction_point, atol=1e-9)
    faster = hr.plan_oblique(tilted, horn, hr.Medium((0.3, 0.4), (1.0, 2.5, 6.25)), target)
    assert faster.sagittal_distance < one.sagittal_distance


@pytest.mark.slow
def test_small_air_gap_matches_the_exact_layered_adjoint():
    """A level array 1 cm above the sand: components evanescent across the gap but
    travelling in the sand reach kappa ~ 1850 rad/m, beyond the Nyquist of the
    12 mm output pitch (262 rad/m); the spectrum is then computed on a grid m times
    finer and every m-th sample kept. Measured 0.94% RMS against the Sommerfeld
    adjoint (2.3% when the grid stopped at the output pitch): bound 1.5%, the taper's
    ringing as in the 35-degree case. About 40 s (the reference integrals)."""
    sand = hr.Medium.half_space(0.3, 2.5 + 0.05j)
    assert _kernel_error(hr.Pose((0.0, 0.0, 0.29)), sand, True) < 0.015
