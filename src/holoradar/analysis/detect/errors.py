"""The detection's refusals as types, so that a caller can say them in its own terms
without reading the message: both are ``ValueError``."""

from __future__ import annotations

from typing import Any

__all__ = ["DetectionInputError", "HologramFitError"]


class DetectionInputError(ValueError):
    """An input that the detection of an image, a hologram or a survey store refuses,
    naming the argument to change.

    Attributes
    ----------
    name : str
        The argument: ``"source"`` (the image, hologram or store searched), ``"z"`` (its
        planes, or the one plane to search).
    """

    def __init__(self, message: str, name: str) -> None:
        super().__init__(message)
        self.name = name

    def __reduce__(self) -> tuple[Any, ...]:
        return type(self), (str(self), self.name)


class HologramFitError(ValueError):
    """:func:`~holoradar.detect`'s refusal of the hologram given for its point fit.

    Attributes
    ----------
    reason : str
        ``"type"`` (not a Hologram), ``"frames"`` (several frames), ``"tilted"`` (not a
        level aperture at z = 0), ``"frequency"`` (the image's frequencies are not the
        hologram's), ``"grid"`` (the image's grid is not the elements' at a whole
        upsampling), ``"mismatch"`` (the image is not its migration: another source,
        data, ground or option).
    difference : float or None
        ``"mismatch"``: how far the image and the hologram's migration differ, as a
        fraction of the image's peak.
    """

    def __init__(self, message: str, reason: str, difference: float | None = None) -> None:
        super().__init__(message)
        self.reason = reason
        self.difference = difference

    def __reduce__(self) -> tuple[Any, ...]:
        return type(self), (str(self), self.reason, self.difference)
