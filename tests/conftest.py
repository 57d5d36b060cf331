"""Shared test helpers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).parent / "data"
F0 = 9.9e9


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def crandn(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
