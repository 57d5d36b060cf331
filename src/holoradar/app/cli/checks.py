"""What ``holoradar image`` says about its result that the picture cannot: data recorded
as ``I - iQ`` (they focus behind the array), and an image whose brightest point is the
surface glare rather than an object. Each is one warning line naming the fix."""

from __future__ import annotations

import shlex
import warnings
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["check_image", "ground_flags"]


def ground_flags(spec: dict[str, Any]) -> str:
    """The ground flags as the user gave them (``--eps 2.5 --z-surface 0.3``), for a command
    line to repeat.

    Examples
    --------
    >>> ground_flags({"eps": "2.5+0.0125j", "z_surface": 0.3, "tan_delta": None,
    ...               "sigma": None, "layers": None, "medium_file": None})
    '--eps 2.5+0.0125j --z-surface 0.3'
    """
    names = (("eps", "--eps"), ("z_surface", "--z-surface"), ("tan_delta", "--tan-delta"),
             ("sigma", "--sigma"), ("layers", "--layers"), ("medium_file", "--medium"))
    return " ".join(f"{flag} {shlex.quote(str(spec[key]))}" for key, flag in names
                    if spec.get(key) is not None)


def check_image(path: Path, hologram: Any, image: Any, medium: Any, medium_spec: dict[str, Any],
                z: np.ndarray, *, layout: str | None, method: str, frame: str,
                upsample: int) -> dict[str, Any]:
    """Warn when the hologram looks recorded as ``I - iQ`` or the glare makes the image's
    brightest point, each with the command that fixes it.

    Parameters
    ----------
    path : Path
        The hologram's file, as given.
    hologram : Hologram
        What was imaged.
    image : Image
        Its image.
    medium : Medium or None
        The ground it was imaged through.
    medium_spec : dict
        The ground flags as parsed (repeated in the suggested command).
    z : ndarray
        The image's ranges, metres.
    layout, method, frame, upsample
        The command's options.

    Returns
    -------
    dict
        ``iq_sign`` (the decided sign or None) and ``glare_dominates`` (None where
        it cannot be told), for the JSON summary.
    """
    from ...imaging.glare.dominance import GlareWarning, dominance_message, glare_share
    from ...imaging.iq import warn_if_conjugated

    own = layout is None and path.suffix.lower() in (".nc", ".nc4")
    if own:
        iq_fix = ("conjugate it once, python -c \"import holoradar as hr; hr.save(hr.conjugate("
                  f"hr.load('{path}')), 'conjugated.nc')\", and image conjugated.nc")
    else:
        iq_fix = ("add iq_sign=I-iQ to the layout: --layout "
                  + shlex.quote(",".join(p for p in (layout, "iq_sign=I-iQ") if p)))
    # The check looks at ranges in front of the array: a plane at the aperture itself
    # (z = 0) focuses nothing on either side and is left out of it.
    ahead = np.atleast_1d(np.asarray(z, float))
    ahead = ahead[ahead > 0]
    iq = warn_if_conjugated(hologram, ahead if ahead.size else None, what=path.name,
                            fix=iq_fix, medium=medium, frame=frame, method=method,
                            stacklevel=2)
    if iq.sign is None and ahead.size:
        # Nothing compact at the planes imaged: the ranges where a scene in front of
        # such an aperture focuses (what reading a user's file checks) may still tell.
        iq = warn_if_conjugated(hologram, None, what=path.name, fix=iq_fix, medium=medium,
                                frame=frame, method=method, stacklevel=2)
    out: dict[str, Any] = {"iq_sign": iq.sign, "glare_dominates": None}
    if iq.sign == "I-iQ":  # the glare fit of data in the other convention means nothing
        return out
    found = glare_share(hologram, image, medium, method=method, upsample=upsample, frame=frame)
    if found is None:
        return out
    out["glare_dominates"] = found.dominates
    if found.dominates:
        flags = ground_flags(medium_spec)
        clean = shlex.quote(str(_fresh(path)))
        fix = (f"remove it first: holoradar suppress {shlex.quote(str(path))} {flags} "
               f"--method image_source{'' if found.direct else ' --no-direct'} -o {clean}, "
               f"then image {clean}")
        warnings.warn(dominance_message(found, path.name, fix), GlareWarning, stacklevel=2)
    return out


def _fresh(path: Path) -> Path:
    """A name beside ``path`` for its glare-free copy that no file has yet
    (``scan_noglare.nc``, ``scan_noglare_2.nc``, ...): the suggested command must run."""
    base = path.with_name(f"{path.stem}_noglare.nc")
    out, i = base, 2
    while out.exists():
        out = base.with_name(f"{base.stem}_{i}.nc")
        i += 1
    return out
