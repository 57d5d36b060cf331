"""Start-up: ``import holoradar`` and ``holoradar --help``/``--version`` load no heavy module.

Each check runs in a fresh interpreter (this one has long since imported everything).
The modules named are those that cost the most when imported beside numpy (README,
"Start-up"; ``benchmarks/bench_startup.py`` times the whole). Speed itself is
measured there, never asserted here.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

# Each of these costs from about 0.05 s (h5py) to 1 s (scipy.stats) on top of numpy.
HEAVY = ("scipy.fft", "scipy.special", "scipy.optimize", "scipy.interpolate", "scipy.stats",
         "scipy.sparse", "scipy.linalg", "scipy.ndimage", "tqdm", "xarray", "dask",
         "distributed", "bokeh", "matplotlib", "h5py", "zarr")


def _loaded_after(code: str, watched: tuple[str, ...] = (*HEAVY, "importlib.metadata")
                  ) -> list[str]:
    """The ``watched`` modules (default: the heavy ones and ``importlib.metadata``) in
    ``sys.modules`` after ``code``."""
    probe = textwrap.dedent(code) + textwrap.dedent(f"""
        import json, sys
        watched = {watched!r}
        print(json.dumps(sorted(m for m in watched if m in sys.modules)))
        """)
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, timeout=120).stdout
    return json.loads(out.splitlines()[-1])


def test_import_holoradar_loads_no_heavy_module():
    assert _loaded_after("import holoradar") == []


@pytest.mark.parametrize("argv", [["--help"], ["--version"], ["view", "--help"],
                                  ["autofocus", "--help"]])
def test_cli_help_and_version_load_no_heavy_module(argv):
    # The command line as the `holoradar` script runs it, stopped where click exits.
    # --version states the version it was given: importlib.metadata is not needed.
    loaded = _loaded_after(f"""
        import contextlib, io, sys
        sys.argv = ["holoradar", *{argv!r}]
        from holoradar.app.cli import main
        with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):
            main()
        """)
    assert loaded == []


def test_lazy_module_imports_on_first_use_and_computes_as_before():
    # The proxy imports scipy.fft on the first attribute read, and the call is scipy's own.
    out = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import sys
        import numpy as np
        from holoradar.physics import propagation
        before = "scipy.fft" in sys.modules
        shape = propagation.padded_shape((100, 97), True, pitch=(0.01, 0.01))
        import scipy.fft
        same = shape == tuple(scipy.fft.next_fast_len(2 * n, real=False) for n in (100, 97))
        print(before, "scipy.fft" in sys.modules, same, repr(propagation.sfft))
        """)], capture_output=True, text=True, check=True, timeout=120).stdout.split()
    assert out[:3] == ["False", "True", "True"]
    assert "<module 'scipy.fft'>" in " ".join(out[3:])


def test_version_option_states_the_package_version():
    from click.testing import CliRunner

    import holoradar
    from holoradar.app.cli import main

    result = CliRunner().invoke(main, ["--version"], prog_name="holoradar")
    assert result.output.strip() == f"holoradar, version {holoradar.__version__}"


def test_public_names_are_imported_on_first_use_and_all_resolve():
    # `import holoradar` loads none of its own subpackages (nothing to compile where
    # bytecode is not cached); each public name resolves on first use, to the object
    # its module defines, and `from holoradar import *` gives every one of them.
    out = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import sys
        import holoradar as hr
        early = sorted(m for m in sys.modules if m.startswith("holoradar."))
        from holoradar.imaging.migrate import migrate
        ok = hr.migrate is migrate and hr.survey.__name__ == "holoradar.survey"
        ns = {}
        exec("from holoradar import *", ns)
        missing = [n for n in hr.__all__ if n not in ns]
        print(early, ok, missing)
        """)], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["[]", "True", "[]"], out.stdout


def test_the_public_names_agree_in_the_three_places_they_are_written():
    # __all__ (what ruff and `import *` read), the lazy table (what resolves a name)
    # and the TYPE_CHECKING imports (what static checkers and IDEs see) must name the
    # same things: a name added to one only is a name some user cannot reach.
    import ast
    from pathlib import Path

    import holoradar as hr

    init = Path(hr.__file__)
    tree = ast.parse(init.read_text())
    static = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING":
            for imp in ast.walk(node):
                if isinstance(imp, ast.ImportFrom):
                    static |= {a.asname or a.name for a in imp.names}
    lazy = set(hr._NAMES) | set(hr._SUBMODULES)
    assert static == lazy == set(hr.__all__), (static ^ lazy, lazy ^ set(hr.__all__))



def test_image_command_on_a_band_imports_neither_xarray_dask_nor_numba(tmp_path):
    # `holoradar image` on a user's scan, run once from a fresh process with the
    # defaults: the NetCDF file is written through h5netcdf (xarray's import and its
    # dask checks cost 0.6-1.2 s), and a band this small is summed in NumPy rather than
    # loading numba and its compiled loop (0.35-0.45 s, more than the sum itself).
    import numpy as np

    rng = np.random.default_rng(0)
    data = rng.standard_normal((5, 24, 20)) + 1j * rng.standard_normal((5, 24, 20))
    np.savez(tmp_path / "scan.npz", data=data, x=np.arange(20) * 0.003,
             y=np.arange(24) * 0.003, f=np.linspace(8e9, 12e9, 5))
    loaded = _loaded_after(f"""
        import contextlib, io, sys, warnings
        warnings.simplefilter("ignore")
        sys.argv = ["holoradar", "image", {str(tmp_path / "scan.npz")!r}, "--layout",
                    "data=data,x=x,y=y,frequency=f,axes=fyx,monostatic=true",
                    "--z", "0.01:0.05:0.002", "--no-png", "-q",
                    "-o", {str(tmp_path / "out.nc")!r}]
        from holoradar.app.cli import main
        with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):
            main()
        """, ("xarray", "pandas", "dask", "distributed", "numba", "matplotlib"))
    assert (tmp_path / "out.nc").exists()
    assert loaded == []
