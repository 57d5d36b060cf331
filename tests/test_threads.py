"""The thread limit: HOLORADAR_THREADS caps holoradar's FFT threads and its pool."""

from __future__ import annotations

import pytest

from holoradar import _threads


@pytest.fixture
def restore(monkeypatch):
    yield
    monkeypatch.undo()               # the environment first, then the limit it sets
    _threads.apply_environment()


def test_the_environment_limits_ffts_and_the_pool(monkeypatch, restore):
    monkeypatch.setenv("HOLORADAR_THREADS", "1")
    _threads.apply_environment()
    assert _threads.fft_workers(512 * 512) == 1 and _threads.POOL_SIZE == 1
    assert _threads.pool()._max_workers == 1
    monkeypatch.delenv("HOLORADAR_THREADS")
    _threads.apply_environment()
    assert _threads.fft_workers(512 * 512) == -1          # every core
    assert _threads.fft_workers(64 * 64) == 1              # small: one thread


@pytest.mark.parametrize("value", ["0", "two", "-3"])
def test_a_bad_limit_is_named(monkeypatch, restore, value):
    monkeypatch.setenv("HOLORADAR_THREADS", value)
    with pytest.raises(ValueError, match="HOLORADAR_THREADS must be a whole number >= 1"):
        _threads.apply_environment()
