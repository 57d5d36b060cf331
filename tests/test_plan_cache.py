"""The wideband sum's plans are kept between calls in their own cache (a band's plan
outgrows the 256 MiB transfer cache: rebuilt at every call, a 64-frequency 512 x 512
plan cost 1.1 s of a 1.9 s call), and freed with the transfer functions."""

import numpy as np
import pytest

import holoradar as hr
from holoradar.imaging.migration.backends import columns
from holoradar.physics.propagation import clear_transfer_cache


@pytest.mark.skipif(not columns.available(), reason="numba absent: no compiled sum")
def test_plans_are_kept_and_freed():
    rng = np.random.default_rng(0)
    data = rng.standard_normal((4, 24, 24)) + 1j * rng.standard_normal((4, 24, 24))
    h = hr.Hologram(data, np.arange(24) * 0.005, np.arange(24) * 0.005,
                    np.linspace(9e9, 11e9, 4), monostatic=True)
    clear_transfer_cache()
    columns.warm()   # loaded: even this small band takes the compiled sum
    zs = np.linspace(0.05, 0.2, 16)
    first = hr.migrate(h, zs)
    assert any(k[0] == "columns" for k in columns.PLAN_CACHE._data)
    again = hr.migrate(h, zs)
    np.testing.assert_array_equal(first.data, again.data)
    clear_transfer_cache()
    assert not columns.PLAN_CACHE._data
    assert columns.PLAN_CACHE.max_bytes >= 256 * 2**20
