"""Suppression of the surface glare (paper section 3.3, docs/glare.md).

The radiator's specular reflection from a flat ground is the wave of its mirror
image at range ``z_m = 2*z0 - z_s``: migrated through AIR it focuses there into a
compact bright spot, while buried objects stay defocused. Methods:

``"cut"``
    Migrate to z_m (the whole padded grid: the spot may lie beside the array),
    mask the spot with a hard disk or a raised-cosine taper, propagate the masked
    part back to the aperture and subtract it (paper's "biting off"). The sharp
    edge leaves parasitic ripples (paper Fig. 14c).
``"gaussian"``
    Fit a Gaussian beam to the glare and subtract it. The beam is the exact
    complex-source-point beam ``exp(i*k*Rc)/Rc`` with
    ``Rc = sqrt((x - xc)^2 + (y - yc)^2 + (zc - i*b)^2)``: waist
    ``w0 = sqrt(2*b/k)`` at range zc, a spherical wave from the mirror image when
    b -> 0. It is evaluated on the array's elements, i.e. as seen through the
    finite rectangular aperture, and fitted there (centre, range, waist, complex
    amplitude) by least squares; subtracting it from the hologram equals
    subtracting its aperture-limited image at z_m and propagating back.
``"image_source"``
    The physical model: the exact reflected field of the source from the layered
    ground (Sommerfeld integral with the angle-dependent reflection coefficient,
    :func:`~holoradar.physics.green.layered_green`), with the ground's
    permittivity and the source's complex amplitude fitted. It yields the
    permittivity of the top layer with its uncertainty.
``"background"``
    Subtract a measured or simulated hologram of the empty scene.

The radiator's direct wave into the aperture (its own spherical wave times its
pattern, known in shape) is fitted jointly, with a free complex amplitude, and
removed too (``direct=True``). It would focus at the radiator's own range, which
is usually the aperture plane or behind it, where no image can be formed.

Layout: :mod:`.suppress` (:func:`suppress_surface`: its checks, the background
subtraction, the dispatch), :mod:`.spot` (the mirror plane and the glare's spot that
every model method starts from), one module per method (:mod:`.cut`, :mod:`.beams`
for the Gaussian beam, :mod:`.image_source` for the exact reflected field and the
permittivity fit), :mod:`.report` (the report, the warning, a method's answer),
:mod:`.permittivity` (:func:`estimate_permittivity`), :mod:`.dominance`
(:func:`glare_share`: whether an image's brightest point is the glare), ``_common``
(the direct wave, linear fits).
"""

# direct_wave: imported by holoradar.imaging.stream (re-exported, private)
from ._common import direct_wave as direct_wave
from .dominance import GlareShare, GlareWarning, glare_share
from .permittivity import estimate_permittivity
from .suppress import FitWarning, SuppressionReport, suppress_surface

__all__ = ["FitWarning", "GlareShare", "GlareWarning", "SuppressionReport",
           "estimate_permittivity", "glare_share", "suppress_surface"]
