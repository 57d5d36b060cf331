"""Generate S8: metal sphere buried in sand, lit by a y-directed electric point
dipole in the air, scattered field on a 24 x 24 receiver grid in the air, at
five frequencies (9.0 ... 11.0 GHz).  Solver: SMUTHI 2.2.4 (T-matrix with
layered-medium Sommerfeld coupling).

Run with a python that has smuthi installed (NOT the project's .venv), e.g.

    python3.11 -m venv /tmp/smuthi-venv
    /tmp/smuthi-venv/bin/pip install numpy==1.26.4 scipy==1.13.1 "setuptools<65" wheel "cython<3"
    # smuthi 2.2.4 needs gfortran (apt-get install gfortran); its shipped Cython C
    # file predates Python 3.11: re-cythonize smuthi/utility/cython/cython_speedups.pyx
    # in the sdist, then `pip install --no-build-isolation .`
    /tmp/smuthi-venv/bin/python make_S8_dipole_sphere.py

Writes S8_dipole_lit_sphere_band.npz / .json next to this file.

SMUTHI's frame is used throughout: z up, sand for z < 0, air for z > 0, all
lengths in metres.  SMUTHI works in units where c = 1 (omega = 2 pi / lambda,
in 1/m) and, for the dipole, eps0 = mu0 = 1 (see the JSON's source.normalisation).
"""
import json
import os
import platform
import time

import numpy as np
import scipy
import smuthi
import smuthi.fields.transformations as trf
import smuthi.initial_field as init
import smuthi.layers as lay
import smuthi.particles as part
import smuthi.postprocessing.scattered_field as sf
import smuthi.simulation as simul

HERE = os.path.dirname(os.path.abspath(__file__))
C0 = 299792458.0

# ---------------------------------------------------------------- scene
EPS_SAND = 2.5 + 0.0125j
EPS_SPHERE = 1 + 1e4j
N_SAND = np.sqrt(EPS_SAND)
N_SPHERE = np.sqrt(EPS_SPHERE)
RADIUS = 0.015
CENTRE = [0.01, 0.0, -0.10]
DIPOLE_POS = [-0.20, 0.0, 0.10]
DIPOLE_MOMENT = [0.0, 1.0, 0.0]
F_HZ = np.array([9.0e9, 9.5e9, 10.0e9, 10.5e9, 11.0e9])
NX = NY = 24
PITCH = 0.02
X_M = (np.arange(NX) - (NX - 1) / 2) * PITCH    # -0.23 ... 0.23
Y_M = (np.arange(NY) - (NY - 1) / 2) * PITCH
Z_RX = 0.30

# ---------------------------------------------------------------- numerics
L_MAX = 14
SOMMERFELD_RES = 5e-4        # neff resolution of the Sommerfeld contour (coupling)
SOMMERFELD_IMAG = 1e-2
AIR_WAYPOINTS = [0, 0.9, 0.9 - 0.01j, 1.3 - 0.01j, 1.3]   # air-side PWE contour (as S2)
AIR_RES = 2.5e-4
AZ_STEP_DEG = 2.0


def layer_system():
    # layer 0: sand half-space (z < 0), layer 1: air half-space (z > 0)
    return lay.LayerSystem(thicknesses=[0, 0], refractive_indices=[N_SAND, 1.0])


def trapz_weights(x):
    """Trapezoid weights for samples x (complex allowed): sum(w*f) == np.trapz(f, x)."""
    d = np.diff(x)
    w = np.zeros(len(x), dtype=complex)
    w[:-1] += d / 2
    w[1:] += d / 2
    return w


def eval_pwe_on_grid(pwe, x, y, z0):
    """Electric field of a SMUTHI PlaneWaveExpansion on the plane z = z0, on the
    grid (y[iy], x[ix]); same quadrature as PlaneWaveExpansion.electric_field
    (trapezoid in azimuth, then trapezoid in k_parallel with weight k_parallel),
    double precision, done as a separable matrix product.  Returns (3, ny, nx)."""
    kp = pwe.k_parallel
    al = pwe.azimuthal_angles
    kpg, ag = np.meshgrid(kp, al, indexing='ij')
    kz = pwe.k_z_grid()
    ix_, iy_, iz_ = pwe._get_electric_field_integrands(kz, ag, kpg, np.complex128)
    w = (trapz_weights(kp) * kp)[:, None] * trapz_weights(al).real[None, :]
    ref = pwe.reference_point
    phase_z = np.exp(1j * kz * (z0 - ref[2]))
    kx = (kpg * np.cos(ag)).ravel()
    ky = (kpg * np.sin(ag)).ravel()
    ex = np.exp(1j * np.outer(kx, x - ref[0]))          # (N, nx)
    ey = np.exp(1j * np.outer(y - ref[1], ky))          # (ny, N)
    out = np.zeros((3, len(y), len(x)), dtype=complex)
    for c, integ in enumerate((ix_, iy_, iz_)):
        a = (integ[0] * w * phase_z).ravel()
        out[c] = ey @ (a[:, None] * ex)
    return out


def air_contour(k0):
    # build directly from waypoints (piecewise linear, resolution AIR_RES in neff)
    pts = []
    for a, b in zip(AIR_WAYPOINTS[:-1], AIR_WAYPOINTS[1:]):
        n = max(int(np.ceil(abs(b - a) / AIR_RES)), 1)
        seg = a + (b - a) * np.arange(n) / n
        pts.append(seg)
    pts.append(np.array([AIR_WAYPOINTS[-1]]))
    return np.concatenate(pts).astype(complex) * k0


def solve_one(f_hz, l_max=L_MAX, somm_res=SOMMERFELD_RES, air_res=AIR_RES, az_step_deg=AZ_STEP_DEG,
              x=X_M, y=Y_M, want_init=True):
    global AIR_RES
    wl = C0 / f_hz
    k0 = 2 * np.pi / wl
    ls = layer_system()
    sphere = part.Sphere(position=CENTRE, refractive_index=N_SPHERE, radius=RADIUS, l_max=l_max, m_max=l_max)
    dip = init.DipoleSource(vacuum_wavelength=wl, dipole_moment=DIPOLE_MOMENT, position=DIPOLE_POS)
    sim = simul.Simulation(layer_system=ls, particle_list=[sphere], initial_field=dip,
                           neff_resolution=somm_res, neff_imag=SOMMERFELD_IMAG,
                           solver_type='LU', log_to_terminal=False, log_to_file=False)
    t0 = time.time()
    sim.run()
    t_solve = time.time() - t0

    old = AIR_RES
    AIR_RES = air_res
    kp = air_contour(k0)
    AIR_RES = old
    az = np.arange(0, 2 * np.pi + 1e-9, np.deg2rad(az_step_deg))
    t0 = time.time()
    # field scattered by the sphere, transmitted into the air (layer 1): upgoing PWE
    pwe_up, _ = sf.scattered_field_pwe(wl, [sphere], ls, 1, k_parallel=kp, azimuthal_angles=az,
                                       include_direct=True, include_layer_response=True)
    e_scat = eval_pwe_on_grid(pwe_up, x, y, Z_RX)
    out = dict(E_scat=e_scat, b=sphere.scattered_field.coefficients.copy(), n_kpar=len(kp), n_az=len(az))
    if want_init:
        X, Y = np.meshgrid(x, y)
        Z = np.full_like(X, Z_RX)
        # direct (free-space) dipole field: SMUTHI's outgoing SWE of the dipole (exact)
        swe = dip.outgoing_spherical_wave_expansion(ls)
        ed = np.array(swe.electric_field(X.ravel(), Y.ravel(), Z.ravel())).reshape(3, *X.shape)
        # reflection of the dipole field from the sand surface (no sphere): upgoing PWE in air
        pu, _ = trf.swe_to_pwe_conversion(swe=swe, k_parallel=kp, azimuthal_angles=az, layer_system=ls,
                                          layer_number=1, layer_system_mediated=True)
        er = eval_pwe_on_grid(pu, x, y, Z_RX)
        out.update(E_direct=ed, E_surface_reflection=er)
    out['t_solve'] = t_solve
    out['t_eval'] = time.time() - t0
    return out


def rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def main():
    t_start = time.time()
    E_scat = np.zeros((3, len(F_HZ), NY, NX), complex)
    E_dir = np.zeros_like(E_scat)
    E_refl = np.zeros_like(E_scat)
    timing = []
    runs = {}
    for i, f in enumerate(F_HZ):
        r = solve_one(f)
        runs[f] = r
        E_scat[:, i] = r['E_scat']
        E_dir[:, i] = r['E_direct']
        E_refl[:, i] = r['E_surface_reflection']
        timing.append(dict(f_hz=float(f), solve_s=r['t_solve'], eval_s=r['t_eval']))
        print(f'{f/1e9:.1f} GHz: max|E_scat| {np.abs(r["E_scat"]).max():.4e}  '
              f'max|E_direct| {np.abs(r["E_direct"]).max():.4e}  '
              f'max|E_refl| {np.abs(r["E_surface_reflection"]).max():.4e}  ({time.time()-t_start:.0f} s)',
              flush=True)

    # ------------------------------------------------------------ checks at 11 GHz (largest k a)
    fchk = F_HZ[-1]
    ref = runs[fchk]
    conv = {}
    r = solve_one(fchk, l_max=L_MAX + 3, want_init=False)
    conv['l_max'] = dict(f_hz=float(fchk), compare=f'l_max=m_max={L_MAX} vs {L_MAX+3}',
                         max_rel_change_E_scat=rel(ref['E_scat'], r['E_scat']))
    print('lmax check', conv['l_max'], flush=True)
    r = solve_one(fchk, somm_res=SOMMERFELD_RES / 2, want_init=False)
    conv['sommerfeld_resolution'] = dict(f_hz=float(fchk), compare=f'neff_resolution {SOMMERFELD_RES} vs {SOMMERFELD_RES/2}',
                                         max_rel_change_E_scat=rel(ref['E_scat'], r['E_scat']),
                                         max_rel_change_b=rel(ref['b'], r['b']))
    print('sommerfeld check', conv['sommerfeld_resolution'], flush=True)
    r = solve_one(fchk, air_res=AIR_RES / 2, az_step_deg=AZ_STEP_DEG / 2)
    conv['air_side_quadrature'] = dict(
        f_hz=float(fchk),
        compare=f'air contour neff step {AIR_RES} vs {AIR_RES/2} and azimuth step {AZ_STEP_DEG} vs {AZ_STEP_DEG/2} deg',
        max_rel_change_E_scat=rel(ref['E_scat'], r['E_scat']),
        max_rel_change_E_surface_reflection=rel(ref['E_surface_reflection'], r['E_surface_reflection']))
    print('air check', conv['air_side_quadrature'], flush=True)

    # own grid evaluator vs SMUTHI's PlaneWaveExpansion.electric_field at a few receivers
    wl = C0 / fchk
    ls = layer_system()
    k0 = 2 * np.pi / wl
    # (re-run quickly to get the pwe object)
    sphere = part.Sphere(position=CENTRE, refractive_index=N_SPHERE, radius=RADIUS, l_max=L_MAX, m_max=L_MAX)
    dip = init.DipoleSource(vacuum_wavelength=wl, dipole_moment=DIPOLE_MOMENT, position=DIPOLE_POS)
    sim = simul.Simulation(layer_system=ls, particle_list=[sphere], initial_field=dip,
                           neff_resolution=SOMMERFELD_RES, neff_imag=SOMMERFELD_IMAG, solver_type='LU',
                           log_to_terminal=False, log_to_file=False)
    sim.run()
    kp = air_contour(k0)
    az = np.arange(0, 2 * np.pi + 1e-9, np.deg2rad(AZ_STEP_DEG))
    pwe_up, _ = sf.scattered_field_pwe(wl, [sphere], ls, 1, k_parallel=kp, azimuthal_angles=az)
    iys, ixs = np.array([0, 5, 11, 17, 23, 12]), np.array([0, 20, 12, 3, 23, 7])
    es = np.array(pwe_up.electric_field(X_M[ixs], Y_M[iys], np.full(len(ixs), Z_RX), max_chunksize=2,
                                        cpu_precision='double precision'))
    mine = ref['E_scat'][:, iys, ixs]
    conv['grid_evaluator_vs_smuthi_pwe_electric_field'] = dict(points=len(ixs), max_rel_diff=rel(mine, es))
    print('evaluator check', conv['grid_evaluator_vs_smuthi_pwe_electric_field'], flush=True)

    # dipole normalisation: SMUTHI direct field vs analytic (eps0=1) dipole field, at one receiver
    X, Y = np.meshgrid(X_M, Y_M)
    rvec = np.array([X[12, 12], Y[12, 12], Z_RX]) - np.array(DIPOLE_POS)
    R = np.linalg.norm(rvec)
    nh = rvec / R
    p = np.array(DIPOLE_MOMENT, float)
    e_an = (k0 ** 2 * np.cross(np.cross(nh, p), nh) / R
            + (3 * nh * nh.dot(p) - p) * (1 / R ** 3 - 1j * k0 / R ** 2)) * np.exp(1j * k0 * R) / (4 * np.pi)
    ratio = E_dir[:, -1, 12, 12] / e_an
    print('direct / analytic(p/(4 pi) form) =', ratio, flush=True)

    t_total = time.time() - t_start

    np.savez_compressed(os.path.join(HERE, 'S8_dipole_lit_sphere_band.npz'),
                        E_scat=E_scat, E_direct=E_dir, E_surface_reflection=E_refl,
                        x_m=X_M, y_m=Y_M, f_hz=F_HZ, z_receivers_m=np.array(Z_RX),
                        dipole_position_m=np.array(DIPOLE_POS), dipole_moment=np.array(DIPOLE_MOMENT, float),
                        sphere_centre_m=np.array(CENTRE), sphere_radius_m=np.array(RADIUS))

    meta = dict(
        scene='S8',
        view='S8_dipole_lit_sphere_band',
        description=('Metal sphere buried in lossy sand half-space (z<0) below air (z>0); lit by a y-directed '
                     'electric point dipole in the air beside the array; scattered field at the receiver plane '
                     'z=+0.30 m in air, five frequencies 9-11 GHz.'),
        solver='smuthi (T-matrix + layered-medium Sommerfeld coupling, LU solve)',
        versions=dict(smuthi=smuthi.__version__, numpy=np.__version__, scipy=scipy.__version__,
                      python=platform.python_version(), platform=platform.platform()),
        time_convention='exp(-i omega t); plane wave = exp(+i k.r); lossy media have Im(n)>0',
        axes='z vertical up; interface at z=0; arrays E[c, f, iy, ix], c=(x,y,z) components, f->f_hz, iy->y_m, ix->x_m',
        units=('lengths in m, f_hz in Hz; fields in SMUTHI dipole units (see source.normalisation): '
               'linear in the dipole moment, the same moment at every frequency'),
        f_hz=F_HZ.tolist(),
        vacuum_wavelength_m=(C0 / F_HZ).tolist(),
        k0_rad_per_m=(2 * np.pi * F_HZ / C0).tolist(),
        k_a_in_sand=(2 * np.pi * F_HZ / C0 * N_SAND.real * RADIUS).tolist(),
        sand=dict(relative_permittivity=[EPS_SAND.real, EPS_SAND.imag], loss_tangent=EPS_SAND.imag / EPS_SAND.real,
                  refractive_index=[N_SAND.real, N_SAND.imag], region='z<0'),
        air=dict(refractive_index=1.0, region='z>0'),
        sphere=dict(centre_m=CENTRE, radius_m=RADIUS, relative_permittivity=[EPS_SPHERE.real, EPS_SPHERE.imag],
                    refractive_index=[N_SPHERE.real, N_SPHERE.imag],
                    note='metal-like: eps=1+1e4i (as S2); skin depth << radius'),
        source=dict(
            type='electric point dipole (smuthi.initial_field.DipoleSource), in the air',
            position_m=DIPOLE_POS,
            dipole_moment=DIPOLE_MOMENT,
            moment_note='unit moment along +y, identical at every frequency (no source spectrum applied)',
            normalisation=('SMUTHI units: c = 1, eps0 = mu0 = 1 (omega = k0 = 2 pi/lambda in 1/m). '
                           'SMUTHI defines the source current j = -i omega p delta(r - r_D). '
                           'Its direct field in free space is E = (1/(4 pi)) [k0^2 (n x p) x n / R '
                           '+ (3 n (n.p) - p)(1/R^3 - i k0/R^2)] exp(i k0 R), i.e. the SI dipole field '
                           'with p/eps0 -> p. Check at receiver (0.01, 0.01, 0.30) m, 11 GHz: '
                           'E_direct / that formula = ' + str([complex(v) for v in ratio])),
        ),
        receivers=dict(z_rx_m=Z_RX, nx=NX, ny=NY, pitch_m=PITCH, x_m='(i-11.5)*0.02, i=0..23 (-0.23 ... +0.23)',
                       y_m='same', centre_m=[0.0, 0.0, Z_RX]),
        saved=dict(
            E_scat=('(3,5,24,24): field scattered by the sphere, as seen in air at the receivers: SMUTHI scattered '
                    'field of the particle, transmitted through the interface, including all sphere-interface '
                    'multiple interactions (self-consistent T-matrix solve with the layer-mediated self-coupling); '
                    'the excitation of the sphere is the dipole field transmitted into the sand. '
                    'Equals total field minus (E_direct + E_surface_reflection).'),
            E_direct=('(3,5,24,24): free-space field of the dipole alone (no sand), from SMUTHI\'s outgoing '
                      'spherical-wave expansion of the dipole (exact)'),
            E_surface_reflection=('(3,5,24,24): reflection of the dipole field from the flat sand surface '
                                  '(no sphere). E_direct + E_surface_reflection = what the receivers see '
                                  'without the sphere; adding E_scat gives the total field'),
        ),
        numerics=dict(
            l_max=L_MAX, m_max=L_MAX,
            sommerfeld_solve=dict(neff_resolution=SOMMERFELD_RES, neff_imag=SOMMERFELD_IMAG,
                                  neff_max='default (max Re n + 1)',
                                  note='used for the sphere layer-mediated self-coupling and for the dipole '
                                       'field at the sphere (initial-field contour, same settings)'),
            air_side_evaluation=dict(
                method=('smuthi scattered_field_pwe (upgoing PWE in air, layer 1); evaluated on the grid with the '
                        'same trapezoid quadrature as PlaneWaveExpansion.electric_field, double precision, as a '
                        'separable matrix product'),
                neff_waypoints=[str(w) for w in AIR_WAYPOINTS], neff_resolution=AIR_RES,
                azimuth_step_deg=AZ_STEP_DEG, n_kpar=runs[F_HZ[0]]['n_kpar'], n_azimuth=runs[F_HZ[0]]['n_az']),
            convergence=conv,
        ),
        wall_time_s=dict(total=t_total, per_frequency=timing),
    )
    with open(os.path.join(HERE, 'S8_dipole_lit_sphere_band.json'), 'w') as fh:
        json.dump(meta, fh, indent=1)
    print('done', t_total)


if __name__ == '__main__':
    main()
