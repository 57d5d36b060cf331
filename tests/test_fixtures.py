"""Independent full-wave holograms (tests/data, independent full-wave fixtures).

Frames: the fixtures' z points UP with the sand surface at z = 0 and receivers at
z = +0.30 m; holoradar's z is range from the aperture, so z_ours = 0.30 - z_fixture.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import holoradar as hr
from conftest import DATA
from holoradar import theory
from holoradar.analysis.metrics import _parabolic, peak_position

Z_RX = 0.30  # receiver plane height above the sand in the fixtures' frame


def _to_range(z_up: float) -> float:
    return Z_RX - z_up


# --------------------------------------------------------------------------- S2
@pytest.mark.parametrize("inc", ["+00", "+20", "-20", "+40", "-40"])
def test_smuthi_buried_sphere_focuses_at_its_mirror_focus(inc):
    """SMUTHI T-matrix: metal sphere (a = 1.5 cm) 10 cm deep in sand, plane wave at inc.

    Geometrical optics: a convex spherical mirror lit by a plane wave reflects it as if
    from its virtual focus, on the axis through the centre parallel to the (refracted)
    incident direction k_t, a/2 from the centre: r_F = centre - (a/2) k_t, with
    sin(t) = sin(inc)/n. A monochromatic image focuses on that point (wideband ranging
    would find the surface instead). GO's error here is O(a/(k_m a)^2) = 0.6 mm
    (k_m a = 4.9): laterally the bound is lambda_m/20 = 1 mm. In range the focus lies
    short of r_F by the finite-aperture focal shift n*focal_shift(L) (Fresnel number
    9.6: 3.4 mm), within the quarter-wave focus tolerance lambda_m/4 = 4.8 mm.
    """
    meta = json.loads((DATA / f"S2_buried_sphere_metal_inc{inc}.json").read_text())
    with np.load(DATA / f"S2_buried_sphere_metal_inc{inc}.npz") as d:
        f = float(d["f_hz"][0])
        eps = complex(d["sand_eps"][0])
        h = hr.Hologram(d["E_scat"][1], d["x_m"], d["y_m"], f)  # E_y: the TE component
        centre = d["sphere_centre_m"].copy()
        a = float(d["sphere_radius_m"][0])
    assert meta["illumination"]["polarization"].startswith("TE")
    z_surface = _to_range(0.0)
    zc = _to_range(centre[2])
    medium = hr.Medium.half_space(z_surface, eps)
    n = medium.n(1).real
    lam = hr.C0 / f
    lam_m = lam / n
    # Refracted incident direction (x, range): positive inc travels towards +x.
    sin_t = np.sin(np.radians(float(inc))) / n
    x_focus = centre[0] - 0.5 * a * sin_t
    z_focus = zc - 0.5 * a * np.sqrt(1 - sin_t**2)
    A = h.x.size * (h.x[1] - h.x[0])
    L = medium.apparent_distance(z_focus)
    shift = n * theory.focal_shift(lam, L, A)
    img = hr.migrate(h, np.linspace(0.32, 0.46, 141), medium=medium, upsample=2)
    x, y, z = peak_position(img)
    assert abs(x - x_focus) < lam_m / 20
    assert abs(y - centre[1]) < lam_m / 20
    assert abs(z - (z_focus + shift)) < lam_m / 4


def test_smuthi_sphere_without_medium_sits_near_apparent_distance():
    # Free-space migration places the sphere's mirror focus (a/2 above its centre, see
    # above) near its apparent distance L = z0 + d/n (paper section 3.2) plus the
    # focal shift, within a quarter of the depth response (paraxial: FWHM of theory).
    with np.load(DATA / "S2_buried_sphere_metal_inc+00.npz") as d:
        f = float(d["f_hz"][0])
        eps = complex(d["sand_eps"][0])
        h = hr.Hologram(d["E_scat"][1], d["x_m"], d["y_m"], f)
    medium = hr.Medium.half_space(0.30, eps)
    lam = hr.C0 / f
    L = medium.apparent_distance(0.40 - 0.0075)
    fw = theory.longitudinal_resolution(lam, L, 0.64)
    img = hr.migrate(h, np.linspace(0.28, 0.45, 171), upsample=2)
    assert abs(peak_position(img)[2] - (L + theory.focal_shift(lam, L, 0.64))) < fw / 4


# --------------------------------------------------------------------------- gprMax
def _x_focus(img: hr.Image) -> tuple[float, float, np.ndarray]:
    """Range and x of the sharpest x-focus of a line target along y.

    The intensity summed along the rod's axis (y) is, by Parseval, the energy of each
    x column; it peaks where the image concentrates in x (the line's focus).
    """
    e = np.sum(np.abs(img.data) ** 2, axis=1)  # (nz, nx)
    iz, ix = np.unravel_index(int(np.argmax(e)), e.shape)
    dz = img.z[1] - img.z[0]
    curve = e[:, ix] / e[:, ix].max()
    return float(img.z[iz] + _parabolic(e[:, ix], iz) * dz), float(img.x[ix]), curve


def _gprmax(fi: int):
    with np.load(DATA / "run_B_background.npz") as b, np.load(DATA / "run_C_rod.npz") as c:
        f = float(b["freqs_hz"][fi])
        scat = c["Ey"][fi].astype(complex) - b["Ey"][fi].astype(complex)
        return f, b["x_m"].copy(), b["y_m"].copy(), scat


@pytest.mark.parametrize("fi", [0, 9, 20])  # 9.0, 9.9 and 11.0 GHz
def test_gprmax_rod_found_where_it_lies(fi):
    """gprMax FDTD: PEC rod (15 mm, 30 cm along y) 10 cm deep, dipole lit from the side.

    Scattered field = run C - run B. The image must show a line along y at x = 0:
    laterally within the rod radius + lambda_m/4 of its axis; its bright part inside the
    rod's ends. In depth a monochromatic focus of a line seen by a 41 cm aperture is
    only defined within its depth response (FWHM ~ 10 cm here) and, with the side
    illumination, lies well short of the rod (finite-aperture focal shift, growing at
    lower frequencies). So the depth is compared with holoradar's own forward model of
    the same scene (a line scatterer at the rod's axis, the same dipole position),
    within a quarter of that model's depth-response FWHM; the fixture's stated errors
    (2 mm dispersion, 20% amplitude) are far inside that.
    """
    f, x, y, scat = _gprmax(fi)
    eps = hr.permittivity(2.5, sigma=0.0069, frequency=f)
    medium = hr.Medium.half_space(0.30, eps)
    lam_m = hr.C0 / f / medium.n(1).real
    zs = np.linspace(0.31, 0.50, 191)
    img = hr.migrate(hr.Hologram(scat, x, y, f), zs, medium=medium, upsample=2)
    z_fd, x_fd, _ = _x_focus(img)
    assert abs(x_fd) < 0.0075 + lam_m / 4
    plane = img.plane(z_fd)
    prof = np.abs(plane.data[:, int(np.argmin(np.abs(plane.x - x_fd)))])
    bright = plane.y[prof > 0.5 * prof.max()]
    assert bright.min() > -0.15 and bright.max() < 0.15
    # holoradar's model of the same scene: dipole at (x, y, height) = (-0.2, 0, 0.1) m.
    source = hr.PointSource((-0.20, 0.0, _to_range(0.10)))
    line = [hr.PointTarget((0.0, yy, _to_range(-0.10))) for yy in np.arange(-0.15, 0.1501, 0.005)]
    model = hr.simulate(hr.Scene(medium, source, line), hr.Aperture(x, y), f,
                        include_surface=False)
    z_model, _, curve = _x_focus(hr.migrate(model, zs, medium=medium, upsample=2))
    above = zs[curve >= 0.5]
    fwhm = above[-1] - above[0]
    assert abs(z_fd - z_model) < fwhm / 4


def test_gprmax_rod_depth_from_all_21_frequencies():
    """The 21 frequencies of the gprMax runs (9-11 GHz), summed coherently after each
    frequency's incident phase (the dipole's field through the sand, holoradar's
    exact model), focus the rod in depth: the range response is c/(2 B n) = 4.7 cm
    wide (first null) against ~10 cm and more at one frequency. A reflecting cylinder
    returns from its lit surface, between its top (9.25 cm deep) and its axis
    (10 cm), and the FDTD's dispersion moves a reflector about 2 mm deeper: the
    x-focus must lie within the rod's radius plus 2 mm of the axis (measured 4 mm
    above it, at the rod's upper half)."""
    with np.load(DATA / "run_B_background.npz") as b, np.load(DATA / "run_C_rod.npz") as c:
        f = b["freqs_hz"].copy()
        scat = c["Ey"].astype(complex) - b["Ey"].astype(complex)
        x, y = b["x_m"].copy(), b["y_m"].copy()
    eps = hr.permittivity(2.5, sigma=0.0069, frequency=9.9e9)
    medium = hr.Medium.half_space(0.30, eps)
    dipole = hr.PointSource((-0.20, 0.0, _to_range(0.10)), dipole=True, axis=(0, 1, 0))
    h = hr.Hologram(scat, x, y, f, source=dipole)
    zs = np.linspace(0.33, 0.47, 29)
    z_fd, x_fd, curve = _x_focus(hr.migrate(h, zs, medium=medium))
    assert abs(x_fd) < 0.0075 + hr.C0 / 11e9 / medium.n(1).real / 4
    assert abs(z_fd - _to_range(-0.10)) < 0.0075 + 0.002
    # ... and sharply: the focus curve falls to half within the range resolution.
    above = zs[curve >= 0.5]
    assert above[-1] - above[0] < hr.theory.range_resolution(2e9, eps.real, monostatic=False)
