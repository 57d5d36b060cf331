"""``detect``: the objects in an image, one row each."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .clean import CleanResult, clean
from .grid import Volume, as_volume
from .table import COLUMNS, as_eps_interval, cramer_rao_factor, depth_of, detection_row

__all__ = ["detect"]

_KINDS = ("point", "line", "area")

#: Why an image searched alone may give nothing, and what to pass instead.
NOTHING_FROM_THE_IMAGE = (
    "no object above the threshold: from the image alone the noise is the image's own "
    "level, which echoes filling the image (a mat under the whole aperture) raise above "
    "every object; pass the hologram it was imaged from (hologram=, --hologram FILE) to "
    "read them off the reflectivity inverted with the receiver noise")


def _check(false_alarm: Any, kinds: Any, medium: Any, eps_interval: Any) -> tuple[float, set[str]]:
    try:
        fa = float(false_alarm)
    except (TypeError, ValueError):
        fa = np.nan
    if not (0 < fa <= 0.1):
        raise ValueError("false_alarm must be a probability per resolution cell in (0, 0.1], "
                         f"got {false_alarm!r}")
    if isinstance(kinds, str) or not isinstance(kinds, Sequence | set | frozenset):
        raise ValueError(f"kinds must be a sequence drawn from {_KINDS}, got {kinds!r}")
    ks = set(kinds)
    bad = ks - set(_KINDS)
    if bad or not ks:
        raise ValueError(f"kinds must be a non-empty sequence drawn from {_KINDS}, got {kinds!r}")
    if medium is not None and not hasattr(medium, "z_interfaces"):
        raise ValueError(f"medium must be a holoradar.Medium or None, got {type(medium).__name__}")
    if eps_interval is not None and (medium is None or not medium.z_interfaces):
        raise ValueError("eps_interval gives a depth interval, which needs medium= (a ground "
                         "with a surface)")
    return fa, ks


class PermittivityIntervalWarning(UserWarning):
    """An eps' interval that excludes the permittivity the image was focused with."""


def _warn_if_outside(interval: tuple[float, float] | None, medium: Any) -> None:
    """The depths are the image's, at the ground's own eps'; an interval that does not
    hold it describes another focus: said, with the way out."""
    if interval is None or medium is None or not medium.z_interfaces:
        return
    ground = [float(complex(e).real) for e in medium.eps[1:]]
    lo, hi = interval
    if all(not lo <= e <= hi for e in ground):
        import warnings

        from ..._validate import outside_stacklevel

        shown = ", ".join(f"{e:.3g}" for e in ground)
        warnings.warn(f"eps_interval [{lo:.3g}, {hi:.3g}] excludes the permittivity the image "
                      f"was focused with ({shown}): the depths are that focus's, and their "
                      "intervals stretch to the other eps'; image through a ground inside the "
                      "interval (or give an interval about the image's eps')",
                      PermittivityIntervalWarning, stacklevel=outside_stacklevel())


def detect(image: Any, *, medium: Any = None, eps_interval: Any = None,
           false_alarm: float = 1e-3, kinds: Sequence[str] = _KINDS,
           hologram: Any = None, migrate_options: Mapping[str, Any] | None = None,
           max_objects: int = 100, noise: float | None = None,
           progress: bool | None = None) -> Any:
    """The objects in an image: what, where, how deep, how big, how sure.

    Parameters
    ----------
    image : Image
        A plane ``(ny, nx)`` or a volume ``(nz, ny, nx)`` with coordinates in metres
        (one frame; a wideband image summed over its frequencies). Sample it at
        several pixels per resolution cell (``migrate(..., upsample=4)`` or finer).
    medium : Medium, optional
        The ground the image was formed through: depths are ranges below its first
        interface (``depth`` columns are NaN without it).
    eps_interval : (float, float) or AutofocusResult, optional
        Interval of the ground's real permittivity (e.g. ``autofocus``'s 95 %
        interval): widens ``depth_low``/``depth_high`` (needs ``medium``).
    false_alarm : float
        Expected number of false objects per resolution cell on noise (default
        1e-3); sets the threshold from the image's own noise (docs/detect.md).
    kinds : sequence of str
        Which kinds to report: ``"point"``, ``"line"``, ``"area"`` (a planar
        reflector or void: its outline polygon in ``df.attrs["outlines"]``, keyed
        by row).
    hologram : Hologram, optional
        The hologram the image was migrated from (one frame; a tilted array's image in
        the ground frame). With it the objects are read off the reflectivity inverted
        from it on the image's planes (:func:`holoradar.invert`: the illumination
        divided out, no sidelobes, no pull towards the array), and a point under a
        level array is the exact point response fitted to the hologram, with its
        Cramer-Rao standard deviations. Without it, CLEAN on the image with its own
        point response (the spectral window) and its peak.
    migrate_options : mapping, optional
        Keyword arguments of ``migrate`` other than ``medium`` and ``upsample`` the
        image was made with (checked: the image must equal the hologram's migration).
    max_objects : int
        The most objects reported (strongest first).
    noise : float, optional
        With ``hologram``: the receiver noise's standard deviation per sample, in the
        hologram's units (default: estimated from its evanescent band, or, where its
        pitch leaves none, assumed 40 dB below its power with a ``NoiseWarning``; a
        noise set too low lets the inversion fit it, and spurious pieces follow).
    progress : bool, optional
        With ``hologram``: a progress bar over the inversion's steps (default: once
        the work has lasted a second; False: never).

    Returns
    -------
    pandas.DataFrame
        One row per object with the columns :data:`~holoradar.analysis.detect.table.COLUMNS`:
        ``kind``; ``x``, ``y``, ``range`` (metres, the image's axes; the range from
        the aperture); ``depth`` below the surface with ``depth_low``/``depth_high``
        (95 %: the range's uncertainty and the permittivity's interval); ``length``,
        ``width``, ``azimuth_deg`` (degrees from +x towards +y; lines and areas),
        ``x_start``, ``y_start``, ``x_end``, ``y_end`` (a line's ends), ``spacing``
        (to the nearest parallel line); ``amplitude_db`` (20 log10 of the object's
        image amplitude), ``snr_db`` (its intensity over the local noise),
        ``x_std``, ``y_std``, ``range_std`` (metres), ``model_error_db`` (what the
        model leaves of the object, relative, dB), ``area`` (m^2; areas). ``df.attrs``
        holds the threshold, the noise, the cell, the permittivity interval
        (``eps_interval``) and the areas' ``outlines``.

    Raises
    ------
    ValueError
        An image without coordinates, a bad ``false_alarm`` or ``kinds``, an
        ``eps_interval`` that is not an interval or without a ``medium``, a
        hologram that did not make the image.

    Examples
    --------
    >>> import numpy as np, holoradar as hr
    >>> scene = hr.Scene(hr.Medium.free_space(), hr.PlaneWave(),
    ...                  [hr.PointTarget((0.02, 0.0, 0.5))])
    >>> h = hr.simulate(scene, hr.Aperture.grid(24, 0.0125), 9.9e9, snr_db=30, seed=1)
    >>> img = hr.migrate(h, np.arange(0.44, 0.57, 0.03), upsample=4)
    >>> df = detect(img, hologram=h)
    >>> len(df), round(float(df.x[0]), 2), round(float(df.range[0]), 2)
    (1, 0.02, 0.5)
    """
    fa, ks = _check(false_alarm, kinds, medium, eps_interval)
    interval = as_eps_interval(eps_interval)
    _warn_if_outside(interval, medium)
    vol = as_volume(image)
    if isinstance(max_objects, bool) or not isinstance(max_objects, int | np.integer) \
            or max_objects < 1:
        raise ValueError(f"max_objects must be a whole number >= 1, got {max_objects!r}")
    if vol.y.size == 1:
        # A line scan's x-z section: each spot one bar across the line.
        if vol.z.size < 2:
            raise ValueError("image: a line scan's image needs several ranges (an x-z "
                             "section), got one plane")
        from .section import detect_section

        rows, meta = detect_section(vol, medium, fa, int(max_objects), interval)
        return _frame([r for r in rows if r["kind"] in ks], meta, fa, interval)
    if hologram is not None:
        from .reflectivity import detect_by_inversion

        rows, meta = detect_by_inversion(vol, hologram, medium, dict(migrate_options or {}),
                                         noise,
                                         interval, fa, int(max_objects), progress)
        return _frame([r for r in rows if r["kind"] in ks], meta, fa, interval)
    if migrate_options:
        raise ValueError("migrate_options needs hologram=")
    if noise is not None:
        raise ValueError("noise is the hologram's receiver noise: it needs hologram= (the "
                         "image alone sets its threshold from its own noise)")
    if vol.z.size > 1:
        if not _wideband(vol):
            raise ValueError("image: a volume at one frequency needs hologram= (its "
                             "range focus is tens of centimetres long: a point's "
                             "response along range comes from the hologram); without "
                             "it pass one plane, e.g. image.plane(z)")
        from .stack import detect_planes

        def run_plane(plane: Volume, rate: float
                      ) -> tuple[list[dict[str, Any]], CleanResult, str]:
            model = _image_model(plane, medium)
            return (*_one(plane, model, medium, rate, ks, int(max_objects), interval),
                    model.kind)

        rows, meta = detect_planes(vol, run_plane, fa, medium, interval)
        if not rows:
            meta["note"] = NOTHING_FROM_THE_IMAGE
        return _frame(rows, meta, fa, interval)
    model = _image_model(vol, medium)
    rows, result = _one(vol, model, medium, fa, ks, int(max_objects), interval)
    return _frame(rows, {"threshold": float(result.noise.t),
                         "resolution_cell": [float(c) for c in result.noise.cell],
                         "n_cells": float(result.noise.n_cells), "model": model.kind}, fa,
                  interval)


def _wideband(vol: Volume) -> bool:
    return vol.frequency is not None and np.atleast_1d(vol.frequency).size > 1


def _image_model(vol: Volume, medium: Any) -> Any:
    """The image's own point response (one frequency, a level array's grid) or the
    analytic spectral window."""
    from .psf import ApertureModel
    from .window import WindowModel

    return ApertureModel(vol, medium) if ApertureModel.applies(vol) else WindowModel(vol, medium)


def _one(vol: Volume, model: Any, medium: Any, fa: float, ks: set[str], max_objects: int,
         interval: tuple[float, float] | None) -> tuple[list[dict[str, Any]], CleanResult]:
    """CLEAN one image with one model, the components grouped into areas and lines."""
    result = clean(vol, model, fa, max_objects=max_objects)
    rows = _rows(result, vol, model, medium, interval)
    from .ringing import absorb_ringing

    rows = absorb_ringing(rows, result.noise.cell, model)
    if "area" in ks:
        from .areas import group_areas

        rows = group_areas(rows, result.noise.cell, model)
    if "line" in ks:
        from .lines import group_lines

        rows = group_lines(rows, result.noise.cell, model)
    if "point" not in ks:
        rows = [r for r in rows if r["kind"] != "point"]
    return rows, result


def _frame(rows: list[dict[str, Any]], meta: dict[str, Any], fa: float,
           interval: tuple[float, float] | None = None) -> Any:
    import pandas as pd

    df = pd.DataFrame(rows, columns=COLUMNS)
    df.attrs.update(meta)
    df.attrs.update({"false_alarm": fa,
                     "eps_interval": None if interval is None else list(interval),
                     "outlines": {i: r["outline"] for i, r in enumerate(rows) if "outline" in r}})
    return df


def _rows(result: CleanResult, vol: Volume, model: Any, medium: Any,
          interval: tuple[float, float] | None) -> list[dict[str, Any]]:
    stds: list[Any] = [c.std for c in result.components]
    positions = [c.position for c in result.components]
    wideband = np.atleast_1d(vol.frequency).size > 1 if vol.frequency is not None else False
    rows = []
    for c, pos, std in zip(result.components, positions, stds, strict=True):
        s2 = float(result.noise.sigma2[c.peak_index])
        amp2 = abs(c.amplitude) ** 2
        snr = 10 * np.log10(amp2 / s2) if s2 > 0 else np.inf
        if not np.all(np.isfinite(std)) and getattr(model, "kind", "") in ("window",
                                                                       "aperture"):
            mu, nu = model.widths(pos[2])
            k = cramer_rao_factor(amp2 / s2 if s2 > 0 else np.inf)
            std = (k / mu, k / nu, np.nan)
        depth, lo, hi = depth_of(pos[2], std[2], medium, interval, wideband)
        rows.append(detection_row(
            "point", pos[0], pos[1], pos[2], depth=depth, depth_low=lo, depth_high=hi,
            length=0.0, width=0.0, amplitude_db=20 * np.log10(max(abs(c.amplitude), 1e-300)),
            snr_db=snr, x_std=std[0], y_std=std[1], range_std=std[2],
            model_error_db=20 * np.log10(max(c.model_error, 1e-6))))
    return rows
