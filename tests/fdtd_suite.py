"""The G suite (gprMax FDTD, tests/data/G_*.npz) as holoradar holograms.

Each case's scattered field is the case less its background run (same source, same
ground, nothing buried); the fields are E/I per unit source current, which is ``f``
times the field of the fixed dipole moment holoradar's ``Dipole`` models, so they are
divided by the frequency (``Dipole``'s docstring). The sidecar's frame has z up from
the ground surface; holoradar's z is the range from the aperture (the receivers'
plane), so a height ``h`` above the ground is the range ``z_rx - h``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

import holoradar as hr
from conftest import DATA

AXES = {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1)}


@dataclass(frozen=True)
class Case:
    hologram: hr.Hologram
    ground: hr.Medium
    surface: float          # the ground's range from the aperture, m
    meta: dict


def load(case: str, every: int = 1, component: str | None = None) -> Case:
    """The case's scattered field as a Hologram (every ``every``-th frequency), the
    recorded component along the source's axis unless ``component`` is given."""
    meta = json.loads((DATA / f"{case}.json").read_text())
    src = meta["source_rel"]
    comp = component or "E" + src["polarisation"]
    with np.load(DATA / f"{meta['background_run']}.npz") as b, \
            np.load(DATA / f"{case}.npz") as c:
        f = b["freqs_hz"].astype(float)[::every]
        scat = (c[comp].astype(complex) - b[comp].astype(complex))[::every]
        x, y, z_rx = b["x_m"].copy(), b["y_m"].copy(), float(b["z_m"])
    g = meta["ground_rel"]
    eps = hr.permittivity(g["eps_r"], sigma=g["sigma_S_per_m"], frequency=10e9)
    ground = hr.Medium.half_space(z_rx, eps)
    p = src["position_m"]
    source = hr.Dipole((p[0], p[1], z_rx - p[2]), AXES[src["polarisation"]])
    h = hr.Hologram(scat / f[:, None, None], x, y, f, source=source,
                    polarization=AXES[comp[1]])
    return Case(h, ground, z_rx, meta)
