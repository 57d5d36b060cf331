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

from . import calibrate, survey, theory
from ._validate import AliasingWarning
from .analysis.detect import detect
from .analysis.oblique_plan import ObliquePlan, plan_oblique
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
from .imaging.iq import IQSignWarning, check_iq_sign, iq_convention
from .imaging.migrate import IlluminationWarning, migrate
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

__version__ = "0.1.0"

__all__ = [
    "C0",
    "AliasingWarning",
    "AngularSpectrum",
    "Aperture",
    "AutofocusResult",
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
    "ObliquePlan",
    "ParabolicEquation",
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
    "iq_convention",
    "load",
    "migrate",
    "permittivity",
    "plan_oblique",
    "remove_mean",
    "save",
    "simulate",
    "suppress_surface",
    "survey",
    "synthesize",
    "theory",
]
