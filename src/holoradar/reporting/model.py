"""What one section of the report holds: a source, its objects and how they were found."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["Ground", "Section"]


@dataclass
class Ground:
    """The ground the objects' depths are measured in.

    Attributes
    ----------
    medium : Medium or None
        The layered ground (None: free space, no depths).
    how : str
        How it was found, in words (given, the file's history, the store's settings).
    eps_interval : (float, float) or None
        The interval of the ground's real permittivity that widened the depth
        intervals (None: not given).
    interval_how : str
        Where that interval came from, in words.
    """

    medium: Any
    how: str
    eps_interval: tuple[float, float] | None = None
    interval_how: str = ""


@dataclass
class Section:
    """One source of the report: its picture, objects and provenance.

    Attributes
    ----------
    name : str
        The source's name (its file name, or ``"image 1"`` for an object).
    kind : str
        ``"image"``, ``"hologram"`` or ``"survey"``.
    image : Image or None
        What the figures draw: a plane or a volume on the objects' axes (None for a
        survey, whose plan views are mosaics read from ``store``).
    table : pandas.DataFrame
        ``hr.detect``'s table (a survey's also ``frame``); row ``i`` is object ``i + 1``.
    ground : Ground
        The ground and its permittivity interval.
    detection : dict
        The detection's settings and outcome: ``false_alarm``, ``kinds``, ``model``,
        ``threshold``, ``n_cells``, ``resolution_cell`` (m) and, for a survey, ``frames``.
    device : list of (str, str)
        The device and its settings, as label and value.
    history : list of dict
        The processing steps stored with the source (oldest first).
    warnings : list of str
        Warnings raised while the source was read, imaged and searched
        (``"Category: message"``, each once).
    store : str or None
        A survey store's path (its mosaic is drawn).
    min_cover : float or None
        The specified minimum cover (m) the bars are checked against.
    """

    name: str
    kind: str
    image: Any
    table: Any
    ground: Ground
    detection: dict[str, Any] = field(default_factory=dict)
    device: list[tuple[str, str]] = field(default_factory=list)
    history: list[dict[str, Any]] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    store: str | None = None
    min_cover: float | None = None
