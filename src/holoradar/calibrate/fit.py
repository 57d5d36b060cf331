"""Fit a calibration from reference measurements: the steps in order.

1. **DC offset** from dark frames (transmitter off): the mean of each channel.
2. **I/Q imbalance** from samples with spread phases: by default the references'
   repeat means (every element and frequency), or frames given as ``iq_samples``
   (a survey's frames; dark frames when the receiver noise enters before the
   demodulator). One (g, phi) for the device, or one per frequency.
3. **I/Q sign** from the first two references (:mod:`.sign`), or given.
4. **Dead and noisy elements** from the first reference's repeats (:mod:`.mask`).
5. **Equalisation between frequencies**: the common response over the good
   elements of the first reference (:mod:`.equalize`).
6. **Element gains** relative to it, per frequency (:mod:`.gains`).

The first reference sets the gains, so it should be the best known one: the
metal plate at a measured range, whose reflection is the horn's main lobe seen
in a mirror. See ``docs/calibration.md`` for how each reference is measured.

A weak I/Q estimate is warned of (:class:`CalibrationWarning`): the residual
image a correction leaves, ``|b/a| = sqrt(dg^2/g^2 + dphi^2)/(2 cos(phi))`` to
first order (:func:`.iq_residual`), taken at one standard error, above
``max_iq_image_db`` = -40 dB, i.e. a standard error above about 2% in the gain
alone or 1.1 degrees in the phase alone. Why -40 dB: the image is a coherent
ghost of every echo, the surface glare's included, which often stands 20-30 dB
above a buried target; the other steps reach -50 dB (element gains to 3e-3);
an uncorrected demodulator's own image is -20 to -30 dB (-20 dB for 15% and 8
degrees). One plate gives -33 dB, an empty scene and a plate -23 dB, the plate
at two ranges lambda/8 apart -55 dB (``docs/calibration.md``).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any, Literal

import numpy as np

from .calibration import SIGNS, Calibration
from .dc import dc_offset
from .equalize import equalize_frequencies
from .gains import element_gains
from .iq import IQImbalance, correct_iq, iq_imbalance
from .mask import find_bad_elements
from .raw import RawFrames
from .reference import KINDS, reference_field
from .sign import detect_iq_sign

__all__ = ["CalibrationWarning", "Reference", "fit_calibration"]


class CalibrationWarning(UserWarning):
    """A calibration step is poorly determined by the measurements given (the fix is named)."""


@dataclass(frozen=True, eq=False)
class Reference:
    """A reference measurement: its raw repeats and what stood in front of the array.

    Parameters
    ----------
    raw : RawFrames
        The repeats of the measurement (all leading axes are repeats).
    kind : {"plate", "empty"}
        A metal plate at a known range, or nothing (:func:`.reference_field`).
    plate_range : float, optional
        ``"plate"``: the plate's range from the array, metres.
    plate_size : (float, float), optional
        ``"plate"``: its width and height, metres (default: infinite).
    include_direct : bool, optional
        The horn's direct wave reaches the array (always for ``"empty"``).
    source : PointSource, PlaneWave or GaussianBeam, optional
        The horn; default ``raw.source``.

    Examples
    --------
    >>> import holoradar as hr
    >>> x = (np.arange(4) - 1.5) * 0.025
    >>> raw = RawFrames(np.ones((4, 4, 4)), np.zeros((4, 4, 4)), x, x, 9.9e9, "HSR-1",
    ...                 source=hr.PointSource((0.0, -0.2, -0.05)))
    >>> Reference(raw, "plate", plate_range=0.3).model().shape
    (1, 4, 4)
    """

    raw: RawFrames
    kind: Literal["plate", "empty"]
    plate_range: float | None = None
    plate_size: tuple[float, float] | None = None
    include_direct: bool | None = None
    source: Any = None

    def __post_init__(self) -> None:
        if not isinstance(self.raw, RawFrames):
            raise ValueError(f"raw must be RawFrames, got {type(self.raw).__name__}")
        if self.kind not in KINDS:
            raise ValueError(f"kind must be one of {KINDS}, got {self.kind!r}")
        if self.source is None:
            if self.raw.source is None:
                raise ValueError("a reference needs its source (the horn as mounted): pass "
                                 "source= or record it in the RawFrames")
            object.__setattr__(self, "source", self.raw.source)

    def model(self) -> np.ndarray:
        """The modelled field, complex, shape (nf, ny, nx) (nf = 1 for one frequency)."""
        m = reference_field(self.kind, self.raw.x, self.raw.y, self.raw.frequency, self.source,
                            plate_range=self.plate_range, plate_size=self.plate_size,
                            include_direct=self.include_direct)
        return m if m.ndim == 3 else m[None]

    def describe(self) -> dict[str, Any]:
        """The reference as JSON values, for the calibration's provenance."""
        return {"kind": self.kind,
                "plate_range_m": None if self.plate_range is None else float(self.plate_range),
                "plate_size_m": (None if self.plate_size is None
                                 else [float(v) for v in self.plate_size]),
                "include_direct": None if self.include_direct is None
                else bool(self.include_direct),
                "repeats": self.raw.n_frames}


def _same_device(frames: list[RawFrames]) -> None:
    first = frames[0]
    for r in frames[1:]:
        if r.device != first.device:
            raise ValueError(f"all frames must come from one device: {first.device!r} and "
                             f"{r.device!r}")
        if (r.element_shape != first.element_shape or not np.array_equal(r.x, first.x)
                or not np.array_equal(r.y, first.y)):
            raise ValueError("all frames must come from one array (same element coordinates)")
        if (r.frequencies.shape != first.frequencies.shape
                or not np.array_equal(r.frequencies, first.frequencies)):
            raise ValueError("all frames must have the same frequencies, got "
                             f"{first.frequencies} and {r.frequencies} Hz")


def _iq_fit(i: np.ndarray, q: np.ndarray, per_frequency: bool) -> list[IQImbalance]:
    """One fit over everything, or one per frequency (axis 1 of (n, nf, ny, nx)).

    The standard errors treat an element's samples as one group: they share its
    gain's phase.
    """
    ny, nx = i.shape[-2:]
    groups = np.broadcast_to(np.arange(ny * nx).reshape(ny, nx), i.shape)
    if not per_frequency:
        return [iq_imbalance(i, q, groups)] * i.shape[1]
    return [iq_imbalance(i[:, f], q[:, f], groups[:, f]) for f in range(i.shape[1])]


def iq_image_db(fit: IQImbalance) -> float:
    """The residual image (dB) a correction leaves at one standard error of ``fit``:
    ``20 log10(sqrt((SE(g)/g)^2 + SE(phi)^2)/(2 cos(phi)))`` (module text)."""
    rel = np.hypot(fit.stderr_gain / fit.gain, fit.stderr_phase) / (2 * np.cos(fit.phase))
    return float(20 * np.log10(rel)) if rel > 0 else -np.inf


def plus_minus(value: float, stderr: float) -> str:
    """``"value +- stderr"``: the error to 2 significant digits, the value to the same place.

    Examples
    --------
    >>> plus_minus(1.14637, 0.00361), plus_minus(7.981, 0.158), plus_minus(2.0, 0.0)
    ('1.1464 +- 0.0036', '7.98 +- 0.16', '2')
    """
    if not (np.isfinite(stderr) and stderr > 0):
        return f"{value:.4g}"
    places = max(0, 1 - int(np.floor(np.log10(stderr))))
    return f"{value:.{places}f} +- {stderr:.{places}f}"


def _warn_weak_iq(fits: list[IQImbalance], limit_db: float) -> None:
    images = [iq_image_db(f) for f in fits]
    worst = int(np.argmax(images))
    if not images[worst] > limit_db:
        return
    f = fits[worst]
    warnings.warn(
        f"the references determine the I/Q imbalance poorly: Q gain "
        f"{plus_minus(f.gain, f.stderr_gain)} ({100 * f.stderr_gain / f.gain:.1f}%), phase "
        f"{plus_minus(np.degrees(f.phase), np.degrees(f.stderr_phase))} deg, a residual image "
        f"of {images[worst]:.0f} dB at one standard error (limit {limit_db:g} dB: about 2% "
        f"or 1.1 deg; {f.effective_groups:.0f} effective elements carry it). Record more "
        "reference scenes whose phases differ: the plate at several ranges (two an eighth "
        "of a wavelength apart cancel most of the error) or a second reflector; or estimate "
        "it from a survey's frames (iq_samples=)", CalibrationWarning, stacklevel=3)


def fit_calibration(references: Sequence[Reference], *, dark: RawFrames | None = None,
                    iq_samples: RawFrames | None = None,
                    iq_sign: Literal["I+iQ", "I-iQ"] | None = None,
                    iq_per_frequency: bool = False, dead_below: float = 0.1,
                    noisy_above: float = 3.0, min_sign_margin_db: float = 10.0,
                    max_iq_image_db: float = -40.0, notes: str = "") -> Calibration:
    """Run the calibration steps in order (module text) and return the Calibration.

    Parameters
    ----------
    references : sequence of Reference
        At least one; the first (with >= 2 repeats, better 4 or more) gives the
        gains, the mask and the response; the first two give the I/Q sign unless
        ``iq_sign`` is given.
    dark : RawFrames, optional
        Dark frames (transmitter off) for the DC offsets; without them the
        offsets are taken as 0.
    iq_samples : RawFrames, optional
        Frames whose samples estimate the I/Q imbalance (default: the references'
        repeat means). Their frames must be independent (different scenes, or
        noise), not repeats of one scene.
    iq_sign : {"I+iQ", "I-iQ"}, optional
        The sign, if known; otherwise detected (needs two references).
    iq_per_frequency : bool
        One imbalance per frequency instead of one for the device.
    dead_below, noisy_above : float
        Thresholds of :func:`.find_bad_elements`.
    min_sign_margin_db : float
        Refuse a detected sign whose margin is smaller (dB).
    max_iq_image_db : float
        Warn (:class:`CalibrationWarning`) when the I/Q correction's residual image
        at one standard error exceeds this (dB; module text).
    notes : str
        Free text kept in the provenance.

    Returns
    -------
    Calibration

    Raises
    ------
    ValueError
        Frames of different devices, arrays or frequencies; too few references or
        repeats; an unclear sign.

    Warns
    -----
    CalibrationWarning
        The I/Q imbalance is poorly determined (``max_iq_image_db``).

    Examples
    --------
    >>> import holoradar as hr
    >>> from holoradar.calibrate import DeviceFaults
    >>> x = (np.arange(6) - 2.5) * 0.025
    >>> horn = hr.PointSource((0.0, -0.2, -0.05), pattern_exponent=2, axis=(0, 0.5, 1))
    >>> device = DeviceFaults(iq_gain=1.1, iq_phase=0.1, conjugate=True, noise=1e-3,
    ...                       element_gain=np.exp(2j * np.pi * np.arange(36) / 7).reshape(6, 6))
    >>> refs = [Reference(device.record(hr.Hologram(reference_field("plate", x, x, 9.9e9, horn,
    ...                   plate_range=z), x, x, 9.9e9, source=horn), "HSR-1", repeats=4,
    ...                   seed=i), "plate", plate_range=z) for i, z in enumerate((0.3, 0.304))]
    >>> cal = fit_calibration(refs)
    >>> cal.iq_sign, cal.provenance["iq_sign"]["margin_db"] > 20
    ('I-iQ', True)
    """
    refs = list(references)
    if not refs or not all(isinstance(r, Reference) for r in refs):
        raise ValueError("references must be a non-empty sequence of Reference")
    frames = [r.raw for r in refs] + [f for f in (dark, iq_samples) if f is not None]
    if not all(isinstance(f, RawFrames) for f in frames):
        raise ValueError("dark and iq_samples must be RawFrames")
    _same_device(frames)
    first = refs[0].raw
    if first.n_frames < 2:
        raise ValueError("the first reference needs at least 2 repeats (better 4) to find "
                         f"noisy elements, got {first.n_frames}")
    if iq_sign is not None and iq_sign not in SIGNS:
        raise ValueError(f"iq_sign must be one of {SIGNS} or None, got {iq_sign!r}")
    if iq_sign is None and len(refs) < 2:
        raise ValueError("the I/Q sign is told from two references (a plate at two ranges an "
                         "eighth of a wavelength apart, or the empty scene and the plate); "
                         "give a second reference or iq_sign=")
    nf = first.frequencies.size
    # 1. DC offset.
    if dark is not None:
        off = dc_offset(*dark.stacked())
        dc_i, dc_q = off.i, off.q
    else:
        dc_i = dc_q = np.zeros((nf, *first.element_shape))
    # 2. I/Q imbalance.
    stacks = [(i - dc_i, q - dc_q) for i, q in (r.raw.stacked() for r in refs)]
    means = [(i.mean(axis=0), q.mean(axis=0)) for i, q in stacks]
    if iq_samples is not None:
        si, sq = iq_samples.stacked()
        iq_from = "iq_samples"
        fits = _iq_fit(si - dc_i, sq - dc_q, iq_per_frequency)
    else:
        iq_from = "references"
        fits = _iq_fit(np.stack([m[0] for m in means]), np.stack([m[1] for m in means]),
                       iq_per_frequency)
    _warn_weak_iq(fits, max_iq_image_db)
    g = np.array([f.gain for f in fits])[:, None, None]
    phi = np.array([f.phase for f in fits])[:, None, None]
    z = [correct_iq(i, q, g, phi) for i, q in means]
    # 3. I/Q sign.
    models = [r.model() for r in refs]
    if iq_sign is None:
        found = detect_iq_sign(z[0], z[1], models[0], models[1])
        if found.margin_db < min_sign_margin_db:
            raise ValueError(f"the references tell the I/Q sign by {found.margin_db:.1f} dB "
                             f"only (< {min_sign_margin_db} dB): check their ranges and models, "
                             "or give iq_sign=")
        sign, how = found.sign, "detected"
        margin = found.margin_db if np.isfinite(found.margin_db) else "inf"
    else:
        sign, how, margin = iq_sign, "given", None
    flip = np.conj if sign == "I-iQ" else (lambda a: a)
    reference = flip(z[0])
    repeats = flip(correct_iq(*stacks[0], g, phi))
    # 4-6. Mask, equalisation, gains.
    bad = find_bad_elements(repeats, models[0], dead_below=dead_below, noisy_above=noisy_above)
    response = equalize_frequencies(reference, models[0], bad.mask)
    gains = element_gains(reference, models[0], response)
    from .._version import __version__

    provenance = {
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "holoradar_version": __version__,
        "references": [r.describe() for r in refs],
        "gains_from": "references[0]",
        "dark_frames": 0 if dark is None else dark.n_frames,
        "iq_imbalance": {"from": iq_from, "per_frequency": bool(iq_per_frequency),
                         "n_samples": [f.n_samples for f in fits],
                         "stderr_gain": [f.stderr_gain for f in fits],
                         "stderr_phase_rad": [f.stderr_phase for f in fits],
                         "effective_groups": [f.effective_groups for f in fits],
                         "image_db_at_stderr": [iq_image_db(f) for f in fits]},
        "iq_sign": {"how": how, "margin_db": margin},
        "dead_below": float(dead_below), "noisy_above": float(noisy_above),
        "dead": int(bad.dead.sum()), "noisy": int(bad.noisy.sum()),
        "notes": str(notes),
    }
    return Calibration(first.device, first.x, first.y, first.frequency, iq_sign=sign,
                       response=response, gains=gains, dc_i=dc_i, dc_q=dc_q,
                       iq_gain=g.ravel(), iq_phase=phi.ravel(), dead=bad.dead,
                       noisy=bad.noisy, source=refs[0].source, provenance=provenance)
