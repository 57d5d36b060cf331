"""A scene to open in ``holoradar view``, and a saved look of it to render in batch.

Six views of two small objects 8 and 12 cm deep in sand (eps 2.5 + 0.01i, the
surface 30 cm in front of the paper's 16 x 16 array, pitch 2.5 cm, 9.9 GHz):
a cos^4 horn 5 cm behind the array at six places, aimed at the scene, with the
sand's glare and the horn's direct wave in every view (holoradar's forward
model). Writes ``viewer_scene/view0.nc`` ... ``view5.nc`` and
``viewer_scene/look.toml``: the settings the page's "export settings" writes,
here the coherent sum of the six views 12 cm deep with the glare removed by the
Gaussian-beam fit. Files that exist already are kept, not overwritten.

Run: ``.venv/bin/python examples/viewer_scene.py [out_dir]``, then

    holoradar view viewer_scene/view*.nc --eps 2.5+0.01j --z-surface 0.30
    holoradar render viewer_scene/look.toml -o look.nc
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import holoradar as hr
from holoradar.app.view.settings import ViewSettings, settings_toml

SURFACE, EPS = 0.30, 2.5 + 0.01j
HORNS = [(-0.15, -0.10), (0.0, -0.15), (0.15, -0.10), (-0.15, 0.10), (0.0, 0.15),
         (0.15, 0.10)]


def main(out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    sand = hr.Medium.half_space(SURFACE, EPS)
    objects = [hr.PointTarget((0.02, 0.01, SURFACE + 0.12), 0.05),
               hr.PointTarget((-0.06, 0.0, SURFACE + 0.08), 0.03)]
    paths = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hr.AliasingWarning)  # 2.5 cm pitch, as the paper's
        for i, (x, y) in enumerate(HORNS):
            horn = hr.PointSource((x, y, -0.05), pattern_exponent=4, axis=(-x, -y, 0.35))
            h = hr.simulate(hr.Scene(sand, horn, objects), hr.Aperture.grid(16, 0.025),
                            9.9e9, include_direct=True)
            p = out / f"view{i}.nc"
            paths.append(p if p.exists() else hr.save(h, p))  # an existing file is kept
    look = ViewSettings(files=tuple(str(p) for p in paths), depth=0.12, glare="gaussian",
                        ground={"surface": SURFACE, "eps": f"{EPS.real}{EPS.imag:+}j"})
    toml = out / "look.toml"
    if not toml.exists():
        toml.write_text(settings_toml(look, relative_to=out), encoding="utf-8")
    return [*paths, toml]


if __name__ == "__main__":
    for p in main(Path(sys.argv[1] if len(sys.argv) > 1 else "viewer_scene")):
        print(p)
