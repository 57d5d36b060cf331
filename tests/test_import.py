"""Reading users' own files: every format to the same hologram, declared layouts and units,
errors that list what a file holds, refusal of pickles, plausibility of units."""

from __future__ import annotations

import io
import json
import os
import zipfile
from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy.io
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import holoradar as hr
from conftest import FUZZED
from holoradar.io.layout import Layout

DATA = Path(__file__).parent / "data"
F = 9.9e9
X = (np.arange(8) - 3.5) * 0.025
Y = (np.arange(6) - 2.5) * 0.025
RNG = np.random.default_rng(7)
FIELD = RNG.normal(size=(6, 8)) + 1j * RNG.normal(size=(6, 8))
TRUTH = hr.Hologram(FIELD, X, Y, F)


def _same(h: hr.Hologram, ref: hr.Hologram = TRUTH) -> None:
    # Every format stores float64 numbers: the reading must be exact, no tolerance.
    assert np.array_equal(h.data, ref.data)
    assert np.array_equal(h.x, ref.x) and np.array_equal(h.y, ref.y)
    assert np.array_equal(np.atleast_1d(h.frequency), np.atleast_1d(ref.frequency))


def write_mat73(path: Path, variables: dict[str, np.ndarray]) -> None:
    """A MATLAB v7.3 file as MATLAB writes it: HDF5 behind a 512-byte header, arrays
    column-major (axes reversed in HDF5), complex as a (real, imag) compound."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, arr in variables.items():
            a = np.asarray(arr)
            a = a.reshape(1, -1) if a.ndim < 2 else a
            cls = "double"
            if np.iscomplexobj(a):
                comp = np.empty(a.T.shape, dtype=[("real", "<f8"), ("imag", "<f8")])
                comp["real"], comp["imag"] = a.T.real, a.T.imag
                ds = f.create_dataset(name, data=comp)
            else:
                ds = f.create_dataset(name, data=a.T.astype(float))
            ds.attrs["MATLAB_class"] = np.bytes_(cls)
    head = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Tue Nov 24 2026 HDF5 schema"
    head = head.ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM"
    with open(path, "r+b") as fh:
        fh.write(head)


def test_every_format_gives_the_same_hologram(tmp_path):
    np.savez(tmp_path / "a.npz", data=FIELD, x=X, y=Y, frequency=F)
    _same(hr.load(tmp_path / "a.npz"))
    # .npy + a JSON sidecar with the coordinates
    np.save(tmp_path / "b.npy", FIELD)
    (tmp_path / "b.json").write_text(json.dumps({"x": X.tolist(), "y": Y.tolist(),
                                                 "frequency": F}))
    _same(hr.load(tmp_path / "b.npy"))
    # MATLAB v5 (scipy.io) and v7.3 (HDF5) keep MATLAB's axis order: data(iy, ix)
    scipy.io.savemat(tmp_path / "c.mat", {"data": FIELD, "x": X, "y": Y, "frequency": F})
    _same(hr.load(tmp_path / "c.mat"))
    write_mat73(tmp_path / "d.mat", {"data": FIELD, "x": X, "y": Y, "frequency": np.array(F)})
    _same(hr.load(tmp_path / "d.mat"))
    # HDF5 with groups and the frequency as an attribute, named by the layout
    with h5py.File(tmp_path / "e.h5", "w") as f:
        g = f.create_group("scan")
        g["field"] = FIELD
        g["x"], g["y"] = X, Y
        f.attrs["f_GHz"] = F / 1e9
    _same(hr.load(tmp_path / "e.h5", layout="data=scan/field, x=scan/x, y=scan/y, "
                                            "frequency=@f_GHz, frequency_unit=GHz"))
    # separate I and Q; amplitude and phase in degrees
    np.savez(tmp_path / "f.npz", I=FIELD.real, Q=FIELD.imag, x=X, y=Y, frequency=F)
    _same(hr.load(tmp_path / "f.npz"))
    np.savez(tmp_path / "g.npz", amplitude=np.abs(FIELD), phase=np.degrees(np.angle(FIELD)),
             x=X, y=Y, frequency=F)
    g = hr.load(tmp_path / "g.npz", layout="phase_unit=deg")
    # amplitude * exp(i deg2rad(degrees(phase))): a few ulps of rounding, no more
    assert np.allclose(g.data, FIELD, rtol=1e-14, atol=0)


def test_csv_table_of_iq_per_element(tmp_path):
    yy, xx = np.meshgrid(Y, X, indexing="ij")
    rows = np.column_stack([xx.ravel(), yy.ravel(), FIELD.real.ravel(), FIELD.imag.ravel()])
    order = RNG.permutation(len(rows))  # rows in any order
    path = tmp_path / "scan.csv"
    lines = ["# exported by a lab program", "x_mm, y_mm, I, Q"]
    lines += [",".join(repr(float(v) * (1000 if j < 2 else 1)) for j, v in enumerate(r))
              for r in rows[order]]
    path.write_text("\n".join(lines) + "\n")
    h = hr.load(path, layout="x=x_mm, y=y_mm, units=mm, frequency=9.9, frequency_unit=GHz")
    assert np.allclose(h.x, X, rtol=0, atol=1e-15) and np.allclose(h.y, Y, rtol=0, atol=1e-15)
    assert np.array_equal(h.data, FIELD) and h.frequency == pytest.approx(F, rel=1e-15)
    # a missing row: the grid is incomplete, said so
    path.write_text("\n".join(lines[:-1]) + "\n")
    with pytest.raises(ValueError, match=r"do not fill a grid: 1 of 48"):
        hr.load(path, layout="x=x_mm, y=y_mm, units=mm, frequency=9.9, frequency_unit=GHz")


def test_wideband_and_frames_with_declared_axes(tmp_path):
    f = np.array([9.0e9, 9.5e9, 10e9])
    cube = RNG.normal(size=(8, 6, 3)) + 1j * RNG.normal(size=(8, 6, 3))  # (x, y, f)
    np.savez(tmp_path / "w.npz", data=cube, x=X, y=Y, frequency=f)
    h = hr.load(tmp_path / "w.npz", layout="axes=xyf")
    assert h.is_wideband and h.data.shape == (3, 6, 8)
    assert np.array_equal(h.data, np.transpose(cube, (2, 1, 0)))
    # a real array with an I/Q axis and frames first
    iq = np.stack([FIELD.real, FIELD.imag], axis=-1)[None].repeat(2, axis=0)
    np.savez(tmp_path / "c.npz", data=iq, x=X, y=Y, frequency=F)
    h = hr.load(tmp_path / "c.npz", layout="axes=tyxc")
    assert h.data.shape == (2, 6, 8) and np.array_equal(h.data[1], FIELD)
    conj = hr.load(tmp_path / "c.npz", layout="axes=tyxc, iq_sign=I-iQ")
    assert np.array_equal(conj.data[0], FIELD.conj())
    # transposed coordinates are noticed
    np.savez(tmp_path / "t.npz", data=FIELD.T, x=X, y=Y, frequency=F)
    with pytest.raises(ValueError, match=r"look swapped: declare axes=xy"):
        hr.load(tmp_path / "t.npz")
    assert np.array_equal(hr.load(tmp_path / "t.npz", layout="axes=xy").data, FIELD)


def test_fixtures_open_like_any_file():
    # The independent full-wave cases are plain .npz + sidecar: a layout names the field.
    h = hr.load(DATA / "S2_buried_sphere_metal_inc+00.npz", layout="data=E_scat[1]")
    with np.load(DATA / "S2_buried_sphere_metal_inc+00.npz") as d:
        assert np.array_equal(h.data, d["E_scat"][1])
        assert np.array_equal(h.x, d["x_m"]) and h.frequency == d["f_hz"][0]
    rod = hr.load(DATA / "run_C_rod.npz", layout="data=Ey")
    assert rod.is_wideband and rod.data.shape == (21, 41, 41)
    # S7: element coordinates in the array's own plane; the frequency from the sidecar
    s7 = hr.load(DATA / "S7_tilted_array_sphere.npz",
                 layout="data=E_scat[0], x=x_local_m, y=y_local_m")
    assert s7.frequency == 9.9e9 and s7.pitch == pytest.approx((0.015, 0.015), abs=1e-12)


def test_errors_list_what_the_file_holds_and_what_is_needed(tmp_path):
    with pytest.raises(ValueError) as e:
        hr.load(DATA / "S2_buried_sphere_metal_inc+00.npz")
    msg = str(e.value)
    assert "no hologram found" in msg and "E_scat (3, 64, 64) complex128" in msg
    assert "data=E_scat[1]" in msg and "I and Q" in msg
    np.savez(tmp_path / "nof.npz", data=FIELD, x=X, y=Y)
    with pytest.raises(ValueError, match=r"no frequency found.*frequency=9.9e9.*data \(6, 8\)"):
        hr.load(tmp_path / "nof.npz")
    np.save(tmp_path / "bare.npy", FIELD)
    with pytest.raises(ValueError, match=r"no coordinates found.*pitch"):
        hr.load(tmp_path / "bare.npy", layout="frequency=9.9e9")
    h = hr.load(tmp_path / "bare.npy", layout="frequency=9.9e9, pitch=2.5, units=cm")
    assert h.pitch == pytest.approx((0.025, 0.025), rel=1e-15)
    with pytest.raises(ValueError, match=r"has no variable 'E'.*found: data"):
        hr.load(tmp_path / "bare.npy", layout="data=E, frequency=9.9e9, pitch=0.025")
    with pytest.raises(ValueError, match=r"unknown format '.txt'.*\.csv"):
        hr.load(tmp_path / "scan.txt")
    with pytest.raises(ValueError, match=r"unknown key.*colour"):
        hr.load(tmp_path / "bare.npy", layout={"colour": "red"})


def test_pickled_object_arrays_are_refused_without_suggesting_pickle(tmp_path):
    p = tmp_path / "evil.npz"
    np.savez(p, data=np.array([{"a": 1}, None], dtype=object), x=X)
    before = p.read_bytes()
    with pytest.raises(ValueError) as e:
        hr.load(p)
    assert "never unpickles" in str(e.value) and "'data'" in str(e.value)
    assert "allow_pickle" not in str(e.value)
    q = tmp_path / "evil.npy"
    np.save(q, np.array([1, "x"], dtype=object), allow_pickle=True)
    with pytest.raises(ValueError, match=r"never unpickles") as e:
        hr.load(q)
    assert "allow_pickle" not in str(e.value)
    assert p.read_bytes() == before


def test_huge_declared_size_and_truncation_are_refused_before_allocating(tmp_path):
    p = tmp_path / "huge.npy"
    hdr = {"descr": "<f8", "fortran_order": False, "shape": (400000, 400000)}
    with open(p, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, hdr)
        fh.write(b"\0" * 128)
    with pytest.raises(ValueError, match=r"more than the 8 GiB limit"):
        hr.load(p, layout="frequency=9.9e9, pitch=0.025")
    hdr["shape"] = (40, 40)
    with open(p, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, hdr)
        fh.write(b"\0" * 128)
    with pytest.raises(ValueError, match=r"truncated"):
        hr.load(p, layout="frequency=9.9e9, pitch=0.025")
    np.savez(tmp_path / "t.npz", data=FIELD, x=X, y=Y, frequency=F)
    blob = (tmp_path / "t.npz").read_bytes()
    (tmp_path / "cut.npz").write_bytes(blob[: len(blob) * 2 // 3])
    with pytest.raises(ValueError, match=r"cut.npz"):
        hr.load(tmp_path / "cut.npz")


def test_unit_mistakes_are_caught_before_imaging(tmp_path):
    np.savez(tmp_path / "mm.npz", data=FIELD, x=X * 1000, y=Y * 1000, frequency=F)
    with pytest.raises(ValueError, match=r"825.6 wavelengths.*millimetres.*length_unit=mm"):
        hr.load(tmp_path / "mm.npz")
    back = hr.load(tmp_path / "mm.npz", layout="units=mm")
    assert np.allclose(back.x, X, rtol=1e-15, atol=1e-17) and np.array_equal(back.data, FIELD)
    np.savez(tmp_path / "cm.npz", data=FIELD, x=X * 100, y=Y * 100, frequency=F)
    with pytest.raises(ValueError, match=r"centimetres.*length_unit=cm"):
        hr.load(tmp_path / "cm.npz")
    np.savez(tmp_path / "ghz.npz", data=FIELD, x=X, y=Y, frequency=9.9)
    with pytest.raises(ValueError, match=r"9.9 Hz.*GHz.*frequency_unit=GHz"):
        hr.load(tmp_path / "ghz.npz")
    np.savez(tmp_path / "m_as_mm.npz", data=FIELD, x=X / 1000, y=Y / 1000, frequency=F)
    with pytest.raises(ValueError, match=r"lambda/1211"):
        hr.load(tmp_path / "m_as_mm.npz")
    np.savez(tmp_path / "zero.npz", data=np.zeros_like(FIELD), x=X, y=Y, frequency=F)
    with pytest.raises(ValueError, match=r"every sample is zero"):
        hr.load(tmp_path / "zero.npz")
    assert not np.any(hr.load(tmp_path / "zero.npz", check=False).data)


@pytest.mark.parametrize("eps, cause", [(-2.5 + 0.01j, "negative real part"),
                                        (0.005, "below 1"), (0.5 + 0.1j, "below 1"),
                                        # a sign slip with its loss: the sign is the cause
                                        (-2.5 - 0.0125j, "-2.5-0.0125j has a negative real"),
                                        (2.5 - 0.0125j, "negative imaginary part, a medium "
                                                        "with gain")])
def test_implausible_permittivity_names_the_likely_mistake(eps, cause):
    with pytest.raises(ValueError, match=cause):
        hr.Medium.half_space(0.3, eps)
    with pytest.raises(ValueError, match=cause):
        hr.Medium.layered([0.3, 0.4], [2.5, eps])


# --- fuzzing: whatever the bytes, a clear ValueError and the input untouched ---------
_SEEDS: dict[str, bytes] = {}


def _seed_files(tmp: Path) -> dict[str, bytes]:
    if not _SEEDS:
        np.savez(tmp / "s.npz", data=FIELD, x=X, y=Y, frequency=F)
        np.save(tmp / "s.npy", FIELD)
        scipy.io.savemat(tmp / "s.mat", {"data": FIELD, "x": X, "y": Y, "frequency": F})
        write_mat73(tmp / "s73.mat", {"data": FIELD, "x": X, "y": Y, "frequency": np.array(F)})
        with h5py.File(tmp / "s.h5", "w") as f:
            f["data"], f["x"], f["y"], f["frequency"] = FIELD, X, Y, F
        yy, xx = np.meshgrid(Y, X, indexing="ij")
        rows = ["x,y,I,Q"] + [f"{a},{b},{c},{d}" for a, b, c, d in
                              zip(xx.ravel().tolist(), yy.ravel().tolist(),
                                  FIELD.real.ravel().tolist(), FIELD.imag.ravel().tolist(),
                                  strict=True)]
        (tmp / "s.csv").write_text("\n".join(rows))
        import xarray as xr

        xr.Dataset({"I": (("y", "x"), FIELD.real), "Q": (("y", "x"), FIELD.imag),
                    "frequency": F}, coords={"x": X, "y": Y}).to_netcdf(tmp / "s_foreign.nc",
                                                                        engine="h5netcdf")
        for name in ("s.npz", "s.npy", "s.mat", "s73.mat", "s.h5", "s.csv", "s_foreign.nc"):
            _SEEDS[name] = (tmp / name).read_bytes()
    return _SEEDS




@settings(max_examples=int(os.environ.get("HOLORADAR_FUZZ_EXAMPLES", "150")), deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(name=st.sampled_from(["s.npz", "s.npy", "s.mat", "s73.mat", "s.h5", "s.csv",
                             "s_foreign.nc"]),
       op=st.sampled_from(["truncate", "flip", "splice", "zero"]),
       where=st.floats(0, 1), byte=st.integers(0, 255), n=st.integers(1, 64))
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_fuzzed_files_give_a_clear_error_or_a_valid_hologram(tmp_path, name, op, where, byte,
                                                              n):
    seeds = _seed_files(tmp_path)
    blob = bytearray(seeds[name])
    i = int(where * (len(blob) - 1))
    if op == "truncate":
        blob = blob[:i]
    elif op == "flip":
        for k in range(i, min(i + n, len(blob))):
            blob[k] ^= byte or 1
    elif op == "splice":
        blob[i:i] = bytes([byte]) * n
    else:
        blob[i:i + n] = b"\0" * len(blob[i:i + n])
    path = tmp_path / f"fuzz_{name}"
    path.write_bytes(bytes(blob))
    before = path.read_bytes()
    listing = sorted(tmp_path.iterdir())
    FUZZED["readers: damaged npz/npy/mat/mat7.3/h5/csv/foreign-nc files"] += 1
    layout = Layout(pitch=0.025, frequency=F) if name == "s.npy" else None
    try:
        h = hr.load(path, layout=layout)
    except ValueError as exc:
        assert str(exc)  # one clear message, never another exception type
    else:
        assert isinstance(h, hr.Hologram) and np.all(np.isfinite(h.data))
    assert path.read_bytes() == before
    assert sorted(tmp_path.iterdir()) == listing  # nothing written


@settings(max_examples=100, deadline=None)
@given(text=st.text(max_size=80))
def test_fuzzed_layout_text_gives_a_clear_error(text):
    FUZZED["layout text"] += 1
    try:
        Layout.parse(text)
    except ValueError as exc:
        assert str(exc)


def test_npz_member_declaring_more_than_it_holds_is_refused(tmp_path):
    p = tmp_path / "bomb.npz"
    with zipfile.ZipFile(p, "w", compression=zipfile.ZIP_DEFLATED) as z:
        hdr = {"descr": "<f8", "fortran_order": False, "shape": (200_000_000,)}
        b = io.BytesIO()
        np.lib.format.write_array_header_1_0(b, hdr)
        z.writestr("data.npy", b.getvalue() + b"\0" * 1024)
    with pytest.raises(ValueError, match=r"holds only"):
        hr.load(p, layout="frequency=9.9e9, pitch=0.025")


def test_matlab_and_hdf5_parse_in_a_separate_process_that_survives_crashes(tmp_path):
    """The C parsers run in a kept parser process: a script without a main guard is not
    run again, and a parser process that dies is replaced on the next file."""
    import subprocess
    import sys

    from holoradar.io import readers

    script = tmp_path / "noguard.py"
    script.write_text(
        "import numpy as np, scipy.io, holoradar as hr\n"
        "print('top level ran')\n"
        f"p = {str(tmp_path / 'g.mat')!r}\n"
        "x = np.arange(4) * 0.01\n"
        "scipy.io.savemat(p, {'data': np.ones((4, 4)) + 1j, 'x': x, 'y': x, "
        "'frequency': 9.9e9})\n"
        "print(hr.load(p).data.shape)\n")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("top level ran") == 1 and "(4, 4)" in done.stdout
    scipy.io.savemat(tmp_path / "a.mat", {"data": FIELD, "x": X, "y": Y, "frequency": F})
    _same(hr.load(tmp_path / "a.mat"))
    readers._PARSER.proc.kill()  # as if a parser had crashed
    readers._PARSER.proc.wait()
    _same(hr.load(tmp_path / "a.mat"))
    # variables named like numpy's own arguments come through
    with h5py.File(tmp_path / "n.h5", "w") as f:
        f["file"], f["allow_pickle"] = np.arange(3.0), np.ones(2)
    got = readers.read_variables(tmp_path / "n.h5")
    assert np.array_equal(got["file"], np.arange(3.0)) and got["allow_pickle"].size == 2


def test_foreign_netcdf_is_cf_decoded_and_netcdf3_read(tmp_path):
    """A NetCDF file from another program is read as NetCDF tools show it: packed
    integers scaled back, NetCDF-3 classic files too."""
    import xarray as xr

    scale = 1e-4
    packed = xr.Dataset({"I": (("y", "x"), np.round(FIELD.real / scale).astype(np.int16)),
                         "Q": (("y", "x"), np.round(FIELD.imag / scale).astype(np.int16))},
                        coords={"x": X, "y": Y})
    for v in ("I", "Q"):
        packed[v].attrs.update(scale_factor=scale, add_offset=0.0)
    packed.attrs["frequency"] = F
    packed.to_netcdf(tmp_path / "packed.nc", engine="h5netcdf")
    h = hr.load(tmp_path / "packed.nc", layout="frequency=@frequency")
    # int16 packing rounds to half a step: |error| <= scale/2 on each of I and Q.
    assert np.max(np.abs(h.data.real - FIELD.real)) <= scale / 2 + 1e-12
    assert np.max(np.abs(h.data.imag - FIELD.imag)) <= scale / 2 + 1e-12
    classic = xr.Dataset({"I": (("y", "x"), FIELD.real), "Q": (("y", "x"), FIELD.imag)},
                         coords={"x": X, "y": Y}, attrs={"frequency": F})
    classic.to_netcdf(tmp_path / "classic.nc", engine="scipy")
    _same(hr.load(tmp_path / "classic.nc", layout="frequency=@frequency"))


def test_hdf5_external_storage_is_not_followed(tmp_path):
    secret = tmp_path / "secret.bin"
    secret.write_bytes(np.arange(8.0).tobytes())
    with h5py.File(tmp_path / "ext.h5", "w") as f:
        f.create_dataset("data", shape=(8,), dtype="<f8", external=[(str(secret), 0, 64)])
    got = hr.io.read_variables(tmp_path / "ext.h5")
    assert "data" not in got and "not read" in " ".join(map(str, got["__other__"]))


def _rows(sep: str = ",", decimal: str = ".") -> list[str]:
    yy, xx = np.meshgrid(Y, X, indexing="ij")
    out = []
    for a, b, c, d in zip(xx.ravel(), yy.ravel(), FIELD.real.ravel(), FIELD.imag.ravel(),
                          strict=True):
        out.append(sep.join(repr(float(v)).replace(".", decimal) for v in (a, b, c, d)))
    return out


def test_csv_exports_as_spreadsheets_write_them(tmp_path):
    """A byte-order mark, ';' with decimal commas, tabs, bracketed unit headers,
    coordinates printed with rounding noise, a constant frequency column."""
    p = tmp_path / "bom.csv"
    p.write_text("\ufeffx,y,I,Q\n" + "\n".join(_rows()), encoding="utf-8")
    _same(hr.load(p, layout="frequency=9.9e9"))
    p = tmp_path / "semi.csv"
    p.write_text("x;y;I;Q\n" + "\n".join(_rows(";", ",")))
    _same(hr.load(p, layout="frequency=9.9e9"))
    p = tmp_path / "tab.csv"
    p.write_text("x [m]\ty [m]\tI [V]\tQ [V]\n" + "\n".join(_rows("\t")))
    _same(hr.load(p, layout="x=x [m], y=y [m], i=I [V], q=Q [V], frequency=9.9e9"))
    p = tmp_path / "noisy.csv"
    rows = [r.split(",") for r in _rows()]
    jitter = np.random.default_rng(1).uniform(-1e-12, 1e-12, (len(rows), 2))
    lines = [",".join([repr(float(r[0]) + float(j[0])), repr(float(r[1]) + float(j[1])),
                       r[2], r[3],
                       "9.9e9"]) for r, j in zip(rows, jitter, strict=True)]
    p.write_text("x,y,I,Q,frequency\n" + "\n".join(lines))
    h = hr.load(p)
    # each coordinate is the mean of its rows: within the 1e-12 m jitter of the truth
    assert np.allclose(h.x, X, rtol=0, atol=1e-12) and h.data.shape == (6, 8)
    assert h.frequency == F and np.array_equal(h.data, FIELD)
    p.write_text("I,Q\n1,2\n3,4\n")
    with pytest.raises(ValueError, match="a table needs x and y columns"):
        hr.load(p, layout="frequency=9.9e9")


def test_layout_edge_cases(tmp_path):
    """Explicit keys override a sidecar even at their default; a declared pitch wins over
    an index 'x'; a meshgrid is accepted; phases in degrees read as radians are caught;
    MATLAB's (ny, nx, nf) order is hinted; one frequency adds no frame axis."""
    np.save(tmp_path / "s.npy", FIELD)
    (tmp_path / "s.json").write_text(json.dumps({"x": (X * 1e3).tolist(),
                                                 "y": (Y * 1e3).tolist(),
                                                 "frequency": F,
                                                 "layout": {"units": "mm"}}))
    assert np.allclose(hr.load(tmp_path / "s.npy").x, X, rtol=1e-15, atol=0)
    with pytest.raises(ValueError, match="millimetres"):
        hr.load(tmp_path / "s.npy", layout="units=m")  # back to the default: it wins
    np.savez(tmp_path / "idx.npz", data=FIELD, x=np.arange(8.0), y=np.arange(6.0), f=F)
    h = hr.load(tmp_path / "idx.npz", layout="pitch=0.025")
    assert np.allclose(h.x, X, rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="not both"):
        hr.load(tmp_path / "idx.npz", layout="pitch=0.025, x=x")
    gx, gy = np.meshgrid(X, Y)
    scipy.io.savemat(tmp_path / "m.mat", {"data": FIELD, "X": gx, "Y": gy, "f": F})
    _same(hr.load(tmp_path / "m.mat", layout="x=X, y=Y"))
    np.savez(tmp_path / "deg.npz", amplitude=np.abs(FIELD), phase=np.degrees(np.angle(FIELD)),
             x=X, y=Y, frequency=F)
    with pytest.raises(ValueError, match="phase_unit=deg"):
        hr.load(tmp_path / "deg.npz")
    f3 = np.array([9e9, 9.5e9, 10e9])
    np.savez(tmp_path / "yxf.npz", data=np.repeat(FIELD[..., None], 3, axis=-1), x=X, y=Y,
             frequency=f3)
    with pytest.raises(ValueError, match="axes=yxf"):
        hr.load(tmp_path / "yxf.npz")
    np.savez(tmp_path / "one.npz", data=FIELD[None], x=X, y=Y, frequency=np.array([F]))
    assert hr.load(tmp_path / "one.npz").data.shape == (6, 8)


def test_a_sidecar_coordinate_in_another_form_is_refused(tmp_path):
    """x given as an object in a sidecar was skipped without a word: refused by name."""
    np.save(tmp_path / "s.npy", FIELD)
    (tmp_path / "s.json").write_text(json.dumps({"x": {"start": -0.0875, "step": 0.025, "n": 8},
                                                 "y": Y.tolist(), "frequency": F}))
    with pytest.raises(ValueError, match=r"^sidecar s.json: 'x' must be a number or a list of "
                                         r"numbers .* got an object \{\"start\""):
        hr.load(tmp_path / "s.npy")
    # the same for a variable the sidecar's layout names as a coordinate
    (tmp_path / "s.json").write_text(json.dumps({"layout": {"y": "rows"}, "x": X.tolist(),
                                                 "rows": "0, 0.025, 0.05", "frequency": F}))
    with pytest.raises(ValueError, match=r"'rows' must be a number or a list of numbers"):
        hr.load(tmp_path / "s.npy")
    # metadata that is no coordinate may take any form
    (tmp_path / "s.json").write_text(json.dumps({"x": X.tolist(), "y": Y.tolist(),
                                                 "frequency": F, "device": {"id": "HSR-7"}}))
    _same(hr.load(tmp_path / "s.npy"))


_json = st.recursive(st.one_of(st.none(), st.booleans(), st.integers(-10**9, 10**9),
                               st.floats(allow_nan=False), st.text(max_size=8)),
                     lambda kids: st.one_of(st.lists(kids, max_size=5),
                                            st.dictionaries(st.text(max_size=8), kids,
                                                            max_size=5)), max_leaves=20)
_layout_keys = ["data", "i", "q", "x", "y", "frequency", "pitch", "axes", "units",
                "frequency_unit", "phase_unit", "iq_sign", "monostatic", "colour"]


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(doc=st.dictionaries(st.sampled_from(["x", "y", "frequency", "layout", "other"]),
                           st.one_of(_json, st.dictionaries(st.sampled_from(_layout_keys),
                                                            _json, max_size=4)),
                           max_size=5))
def test_fuzzed_sidecars_give_a_clear_error_or_a_hologram(tmp_path, doc):
    """Any JSON beside a .npy: a ValueError or a valid hologram, nothing else."""
    FUZZED["JSON sidecars"] += 1
    np.save(tmp_path / "f.npy", FIELD)
    (tmp_path / "f.json").write_text(json.dumps(doc))
    try:
        h = hr.load(tmp_path / "f.npy")
    except ValueError as exc:
        assert str(exc)
    else:
        assert isinstance(h, hr.Hologram) and np.all(np.isfinite(h.data))
