"""The default upsampling: pixels of a quarter of the finest lateral resolution cell
``lambda L / A`` (at least ``lambda / 2``), no more than the pitch needs."""

from __future__ import annotations

import numpy as np
import pytest

import holoradar as hr
from holoradar.imaging.migration.pixel_size import upsample_for

C0 = 299792458.0


def _grid(n: int, pitch: float, f, *, line: bool = False) -> hr.Hologram:
    f = np.atleast_1d(np.asarray(f, float))
    shape = (f.size, 1 if line else n, n) if f.size > 1 else (1 if line else n, n)
    y = np.zeros(1) if line else np.arange(n) * pitch
    return hr.Hologram(np.zeros(shape, complex), np.arange(n) * pitch, y,
                       f if f.size > 1 else float(f[0]))


def test_factor_follows_the_cell_of_the_nearest_plane():
    h = _grid(16, 0.025, 9.9e9)
    lam, A = C0 / 9.9e9, 15 * 0.025
    for L in (0.3, 0.6, 1.2):
        cell = max(lam * L / A, lam / 2)
        assert upsample_for(h, L) == int(np.ceil(0.025 / (cell / 4)))
    # a sweep: the nearest plane (finest cell) decides
    assert upsample_for(h, [0.3, 1.2]) == upsample_for(h, 0.3)


def test_a_scan_finer_than_a_quarter_cell_gets_one_pixel_per_element():
    # lambda/2 = 1.5 cm at 10 GHz: a quarter of it 3.75 mm, coarser than a 3 mm pitch at
    # any range, even at the aperture (z = 0)
    h = _grid(64, 0.003, np.linspace(8e9, 12e9, 5))
    assert upsample_for(h, np.linspace(0.0, 0.18, 10)) == 1


def test_a_ground_nears_the_plane_and_a_line_uses_its_length():
    h = _grid(16, 0.025, 9.9e9)
    sand = hr.Medium.half_space(0.1, 4.0)
    # 0.5 m below the aperture is 0.1 + 0.4 * 2 = 0.9 m apparent: a coarser cell
    assert upsample_for(h, 0.5, sand) == upsample_for(h, sand.apparent_distance(0.5))
    line = _grid(16, 0.025, 9.9e9, line=True)
    assert upsample_for(line, 0.6) == upsample_for(h, 0.6)


def test_top_and_bad_ranges():
    h = _grid(16, 0.05, 30e9)
    assert upsample_for(h, 0.01, top=3) == 3
    with pytest.raises(ValueError, match="z must be finite"):
        upsample_for(h, [np.nan])
