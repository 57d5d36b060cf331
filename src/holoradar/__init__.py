"""holoradar: holographic subsurface radar imaging and simulation.

Conventions (docs/conventions.md): SI units, time dependence exp(-i*omega*t),
z is the range from the aperture plane towards the scene, Im(eps) >= 0 for loss.

Examples
--------
>>> import holoradar as hr
>>> scene = hr.Scene(hr.Medium.half_space(0.30, 2.5 + 0.0125j), hr.PlaneWave(),
...                  [hr.PointTarget((0.0, 0.0, 0.42))])
>>> holo = hr.simulate(scene, hr.Aperture.grid(64, 0.015), 9.9e9, include_surface=False)
>>> img = hr.migrate(holo, [0.40, 0.42, 0.44], medium=scene.medium)
>>> round(img.peak()[2], 2)
0.42
"""

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # what static checkers and IDEs see
    from . import calibrate, io, survey, theory
    from ._validate import AliasingWarning
    from ._version import __version__
    from .analysis.detect import detect, rebar_layers, unbiased_peak
    from .analysis.detect.api import PermittivityIntervalWarning
    from .analysis.oblique_plan import ObliquePlan, plan_oblique
    from .data.grid_axes import CoordinateWarning
    from .data.hologram import C0, Hologram, Image
    from .data.pose import Pose
    from .data.wideband import apply_calibration, conjugate, remove_mean
    from .imaging.autofocus import AutofocusResult, autofocus
    from .imaging.glare import (
        FitWarning,
        GlareWarning,
        SuppressionReport,
        estimate_permittivity,
        suppress_surface,
    )
    from .imaging.inversion import invert
    from .imaging.iq import IQSignWarning, check_iq_sign, iq_convention
    from .imaging.lines import stack_lines
    from .imaging.migrate import IlluminationWarning, migrate
    from .imaging.migration.linear import MigrationOperator, migration_operator
    from .imaging.migration.settings import MigrationSettings
    from .imaging.propagate import propagate
    from .imaging.stream import StreamImager
    from .imaging.synthesis import align_phases, synthesize
    from .io import load, save
    from .model.scene import Aperture, Scene
    from .model.simulate import simulate
    from .model.targets import LineTarget, PlanarTarget, PointTarget
    from .physics.dipole import Dipole
    from .physics.medium import Medium, permittivity
    from .physics.parabolic import ParabolicEquation
    from .physics.propagation import AngularSpectrum, Fresnel
    from .physics.sources import GaussianBeam, PlaneWave, PointSource
    from .reporting import report

# The public names, each imported from its module on first use (PEP 562): `import
# holoradar` then costs little more than numpy even where bytecode is not cached (every
# module compiled afresh), and `hr.migrate` etc. behave as plain attributes.
_SUBMODULES = ("calibrate", "io", "survey", "theory")
_NAMES = {
    "__version__": "._version",
    "AliasingWarning": "._validate",
    "PermittivityIntervalWarning": ".analysis.detect.api",
    "AngularSpectrum": ".physics.propagation",
    "Aperture": ".model.scene",
    "AutofocusResult": ".imaging.autofocus",
    "C0": ".data.hologram",
    "CoordinateWarning": ".data.grid_axes",
    "Dipole": ".physics.dipole",
    "FitWarning": ".imaging.glare",
    "Fresnel": ".physics.propagation",
    "GaussianBeam": ".physics.sources",
    "GlareWarning": ".imaging.glare",
    "Hologram": ".data.hologram",
    "IQSignWarning": ".imaging.iq",
    "IlluminationWarning": ".imaging.migrate",
    "Image": ".data.hologram",
    "LineTarget": ".model.targets",
    "MigrationOperator": ".imaging.migration.linear",
    "MigrationSettings": ".imaging.migration.settings",
    "Medium": ".physics.medium",
    "ObliquePlan": ".analysis.oblique_plan",
    "ParabolicEquation": ".physics.parabolic",
    "PlanarTarget": ".model.targets",
    "PlaneWave": ".physics.sources",
    "PointSource": ".physics.sources",
    "PointTarget": ".model.targets",
    "Pose": ".data.pose",
    "Scene": ".model.scene",
    "StreamImager": ".imaging.stream",
    "SuppressionReport": ".imaging.glare",
    "align_phases": ".imaging.synthesis",
    "apply_calibration": ".data.wideband",
    "autofocus": ".imaging.autofocus",
    "check_iq_sign": ".imaging.iq",
    "conjugate": ".data.wideband",
    "detect": ".analysis.detect",
    "unbiased_peak": ".analysis.detect",
    "rebar_layers": ".analysis.detect",
    "estimate_permittivity": ".imaging.glare",
    "iq_convention": ".imaging.iq",
    "load": ".io",
    "invert": ".imaging.inversion",
    "migrate": ".imaging.migrate",
    "migration_operator": ".imaging.migration.linear",
    "permittivity": ".physics.medium",
    "propagate": ".imaging.propagate",
    "plan_oblique": ".analysis.oblique_plan",
    "remove_mean": ".data.wideband",
    "report": ".reporting",
    "save": ".io",
    "simulate": ".model.simulate",
    "suppress_surface": ".imaging.glare",
    "synthesize": ".imaging.synthesis",
    "stack_lines": ".imaging.lines",
}

def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        value = importlib.import_module(f"{__name__}.{name}")
    elif name in _NAMES:
        value = getattr(importlib.import_module(_NAMES[name], __name__), name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # later reads skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))



__all__ = [
    "C0",
    "AliasingWarning",
    "AngularSpectrum",
    "Aperture",
    "AutofocusResult",
    "CoordinateWarning",
    "Dipole",
    "FitWarning",
    "Fresnel",
    "GaussianBeam",
    "GlareWarning",
    "Hologram",
    "IQSignWarning",
    "IlluminationWarning",
    "Image",
    "LineTarget",
    "Medium",
    "MigrationOperator",
    "MigrationSettings",
    "ObliquePlan",
    "ParabolicEquation",
    "PermittivityIntervalWarning",
    "PlanarTarget",
    "PlaneWave",
    "PointSource",
    "PointTarget",
    "Pose",
    "Scene",
    "StreamImager",
    "SuppressionReport",
    "__version__",
    "align_phases",
    "apply_calibration",
    "autofocus",
    "calibrate",
    "check_iq_sign",
    "conjugate",
    "detect",
    "estimate_permittivity",
    "invert",
    "io",
    "iq_convention",
    "load",
    "migrate",
    "migration_operator",
    "permittivity",
    "plan_oblique",
    "propagate",
    "rebar_layers",
    "remove_mean",
    "report",
    "save",
    "simulate",
    "stack_lines",
    "suppress_surface",
    "survey",
    "synthesize",
    "theory",
    "unbiased_peak",
]
