"""Autofocus: the ground permittivity that focuses a buried object best.

The sharpness measure is the *focus fraction*: the share of the hologram's
energy that one compact scatterer explains, the exact field of a point at
``r`` in a ground of permittivity eps' (:mod:`holoradar.imaging.point_response`),
fitted with its complex amplitude,

    F(eps', r) = |<h, g>|^2 / (||g||^2 ||h||^2).

It is the peak of the matched-filter image normalised, pixel by pixel, by the
energy its point response leaves on the finite aperture. Image-domain measures
(the peak, the normalised fourth moment, the entropy of a migrated image) are
not normalised that way: a point's image through a finite aperture brightens
and narrows as eps' grows (refraction squeezes more of its wave front onto the
array), so they drift to high eps' (4.5 for a true 4.0 with the 16 x 16
array). ``max F`` is the maximum-likelihood fit of one object in white noise,
without that drift.

Confidence interval: the profile likelihood. With ``R(eps') = ||h||^2 (1 -
max_r F)`` the residual energy, the interval holds the eps' with
``R - R_min <= (z s sqrt(phi) + sqrt(E_err))^2``: ``z`` the normal quantile of the confidence,
``s^2 = R_min / (2N - 6)`` the residual's variance per real component (N complex
samples, six real parameters), and ``phi >= 1`` a sandwich correction for a
residual that is not white (model error: a sphere is not a point, a vector field
not a scalar one): ``phi = sum_k |D_k|^2 |R_k|^2 / (sigma^2 sum_k |D_k|^2)``, with
``R_k`` the residual's spectrum and ``D_k`` that of the model's derivative with
respect to eps' (made orthogonal to the derivatives in amplitude and position).
It weighs the residual's power at the spatial frequencies (and delays) where
eps' acts: 1 for white noise, more when the residual looks like a change of eps'.
``E_err`` is the energy of the residual's smooth part (model error), which could
shift the estimate by at most ``sqrt(E_err)/||D||``.

Modules: :mod:`.api` (:func:`autofocus`, its steps), :mod:`.checks` (its
arguments), :mod:`.search` (the best fit at each trial eps'),
:mod:`.fit_statistics` (noise, detection and the sandwich factor at a fit),
:mod:`.interval` (the profile-likelihood interval), :mod:`.crb` (the Cramér-Rao
bound of eps' at the estimate, and why an interval exceeds it), :mod:`.glare_estimate`
(the glare's own estimate and its combination with the focus's) and :mod:`.result`
(:class:`AutofocusResult`).
"""

from .api import autofocus
from .result import AutofocusResult

__all__ = ["AutofocusResult", "autofocus"]
