"""Shared test helpers."""

from __future__ import annotations

import os
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

# Property tests draw the same inputs on every run (a failure seen once is seen again;
# CI cannot turn red by the luck of a draw); HOLORADAR_FUZZ_SEED=random explores anew.
settings.register_profile("holoradar", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile("explore" if os.environ.get("HOLORADAR_FUZZ_SEED") == "random"
                      else "holoradar")

DATA = Path(__file__).parent / "data"

# The fixtures' generators (data/make_*.py) run in their solvers' environments: not
# test modules, and --doctest-modules must not import them.
collect_ignore_glob = ["data/*.py"]
F0 = 9.9e9


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def crandn(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


FUZZED: Counter[str] = Counter()
"""Inputs tried by each property-based (fuzzing) test, reported at the end of the run."""


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    if FUZZED:
        terminalreporter.write_sep("-", "fuzzing: inputs tried")
        for name, n in sorted(FUZZED.items()):
            terminalreporter.write_line(f"{n:6d}  {name}")


def migrate64(*args, **kwargs):
    """``hr.migrate`` in double precision unless a dtype is given: the tests that compare
    an image with closed forms or with another path to 1e-10 test the arithmetic, not the
    single-precision default (whose own accuracy, 1e-6 of double, has its test)."""
    import holoradar as hr

    kwargs.setdefault("dtype", np.complex128)
    return hr.migrate(*args, **kwargs)
