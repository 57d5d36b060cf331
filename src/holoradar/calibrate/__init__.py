"""Calibration of a receiver array: raw I and Q in, a calibrated Hologram out.

Each step is a function, tested on simulated raw data with known faults
(:class:`DeviceFaults` is the receiver model the steps invert):

============================  ==================================================
:func:`dc_offset`             DC offsets of the I and Q channels (dark frames)
:func:`iq_imbalance`          Q gain and phase error, blind, with standard errors
:func:`detect_iq_sign`        ``I + iQ`` or ``I - iQ`` from two references
:func:`find_bad_elements`     dead and noisy elements (masked, not interpolated)
:func:`equalize_frequencies`  the complex response of each frequency
:func:`element_gains`         each element's complex gain (measured / modelled)
:func:`reference_field`       the modelled reference: a metal plate or nothing
:func:`fit_calibration`       all of it, in order, into a :class:`Calibration`
============================  ==================================================

A :class:`Calibration` is saved to a file of its own with the device's identity
(:meth:`Calibration.save`) and applied by name (:func:`apply`); frames of
another device, array or set of frequencies are refused. Details and measured
accuracies: ``docs/calibration.md``.

Examples
--------
>>> import numpy as np
>>> x = (np.arange(2) - 0.5) * 0.025
>>> cal = Calibration("HSR-7", x, x, 9.9e9, iq_sign="I+iQ", response=[1j],
...                   gains=np.ones((2, 2)))
>>> raw = RawFrames(np.zeros((2, 2)), np.ones((2, 2)), x, x, 9.9e9, "HSR-7")
>>> cal.apply(raw).data[0, 0]
np.complex128(1+0j)
"""

from .calibration import Calibration, apply
from .dc import DCOffset, dc_offset, remove_dc
from .equalize import equalize_frequencies
from .faults import DeviceFaults
from .fit import CalibrationWarning, Reference, fit_calibration
from .gains import element_gains
from .iq import IQImbalance, correct_iq, iq_imbalance, iq_residual
from .mask import BadElements, find_bad_elements, interpolate_for_display
from .raw import RawFrames
from .reference import reference_field
from .sign import IQSign, detect_iq_sign

__all__ = [
    "BadElements",
    "Calibration",
    "CalibrationWarning",
    "DCOffset",
    "DeviceFaults",
    "IQImbalance",
    "IQSign",
    "RawFrames",
    "Reference",
    "apply",
    "correct_iq",
    "dc_offset",
    "detect_iq_sign",
    "element_gains",
    "equalize_frequencies",
    "find_bad_elements",
    "fit_calibration",
    "interpolate_for_display",
    "iq_imbalance",
    "iq_residual",
    "reference_field",
    "remove_dc",
]
