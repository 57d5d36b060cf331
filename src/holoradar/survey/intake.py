"""The frames a run is given: made distinct, checked, and those found bad remembered.

Before anything is written, :func:`check_frames` keeps one entry per distinct file and
skips the paths that are no files or empty ones; :func:`drop_remembered` (a resumed
store) skips the frames an earlier run found bad and whose file has not changed since;
:func:`drop_unreadable` (a new store) reads the frames up to the first that can be
imaged, whose geometry the survey takes. Each step returns a new :class:`Intake`. Once
the run ends (or stops early), :func:`remember` records in the store why frames are
missing.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from .frames import FrameGeometry
from .store import file_stamp, note_skipped
from .worker import read_frame

__all__ = ["Intake", "check_frames", "drop_remembered", "drop_unreadable", "remember"]


@dataclass(frozen=True)
class Intake:
    """The frames of a run, sorted into those to image and those skipped.

    Attributes
    ----------
    tried : tuple of Path
        Every distinct frame given (absolute paths), in the order given.
    frames : tuple of (Path, str)
        The frames to image: absolute path and name as given, in the order given.
    skipped : tuple of dict
        ``{"name", "reason"}`` per frame skipped so far, in the order found; a frame an
        earlier run found bad also has ``"remembered": True``.
    stamps : mapping of str to list of int or None
        :func:`~holoradar.survey.store.file_stamp` of each frame that passed the first
        checks, taken before any is read (by absolute path): a frame found bad is
        remembered with it, so a file changed while the run read it is read again next time.
    bad : mapping of str to str
        Absolute path -> reason, for the frames found bad when read (by this run or,
        remembered, an earlier one).
    """

    tried: tuple[Path, ...]
    frames: tuple[tuple[Path, str], ...]
    skipped: tuple[dict[str, Any], ...]
    stamps: Mapping[str, list[int] | None]
    bad: Mapping[str, str]

    @property
    def count(self) -> int:
        """Distinct frames given."""
        return len(self.tried)


def check_frames(given: Sequence[Path], strict: bool) -> Intake:
    """The distinct frames of ``given``, and the checks that need no reading.

    A path that is not a file, or an empty file, is skipped (with ``strict``:
    ``ValueError`` naming it). Duplicates (the same absolute path) count once.
    """
    tried: list[Path] = []
    seen: set[Path] = set()
    frames: list[tuple[Path, str]] = []
    skipped: list[dict[str, Any]] = []
    for p in given:
        key = p.resolve()
        if key in seen:
            continue
        seen.add(key)
        tried.append(key)
        problem = _problem(p)
        if problem is None:
            frames.append((key, str(p)))
        elif strict:
            raise ValueError(f"frame {str(p)!r}: {problem} (strict: nothing was written)")
        else:
            skipped.append({"name": str(p), "reason": problem})
    stamps = {str(k): file_stamp(k) for k, _ in frames}
    return Intake(tuple(tried), tuple(frames), tuple(skipped), stamps, {})


def _problem(path: Path) -> str | None:
    """Why ``path`` cannot be a frame, as far as its size says (None: it may be one)."""
    if not path.is_file():
        return "is not a file"
    return "is empty" if path.stat().st_size == 0 else None


def drop_remembered(intake: Intake, known_bad: Mapping[str, str], strict: bool) -> Intake:
    """The frames left once those of ``known_bad`` (absolute path -> reason) are skipped.

    With ``strict`` such a frame raises ``ValueError`` instead (nothing is written yet).
    """
    keep: list[tuple[Path, str]] = []
    skipped = list(intake.skipped)
    bad = dict(intake.bad)
    for key, name in intake.frames:
        reason = known_bad.get(str(key))
        if reason is None:
            keep.append((key, name))
            continue
        if strict:
            raise ValueError(f"frame {name!r}: {reason} (found by an earlier run; strict: "
                             "nothing was written; retry_bad reads it again)")
        skipped.append({"name": name, "reason": reason, "remembered": True})
        bad[str(key)] = reason
    return replace(intake, frames=tuple(keep), skipped=tuple(skipped), bad=bad)


def drop_unreadable(intake: Intake, strict: bool,
                    layout: Any = None) -> tuple[Intake, FrameGeometry]:
    """The frames left once those read before the first readable one are skipped (they
    cannot be imaged), and that frame's geometry: the survey's.

    ``ValueError`` when no frame can be imaged, or (``strict``) at the first that cannot.
    """
    found, refused = _reference(intake.frames, strict, layout)
    refused_names = {name for name, _ in refused}
    skipped = [*intake.skipped, *({"name": name, "reason": reason} for name, reason in refused)]
    bad = {**intake.bad,
           **{str(k): r for k, n in intake.frames for name, r in refused if n == name}}
    if found is None:
        raise ValueError(f"none of the {intake.count} frames can be imaged: "
                         + "; ".join(f"{s['name']}: {s['reason']}" for s in skipped[:3]))
    frames = tuple(f for f in intake.frames if f[1] not in refused_names)
    return replace(intake, frames=frames, skipped=tuple(skipped), bad=bad), found


def _reference(frames: Sequence[tuple[Path, str]], strict: bool,
               layout: Any = None) -> tuple[FrameGeometry | None, list[tuple[str, str]]]:
    """The geometry of the first frame that can be read, and the frames refused before it."""
    refused: list[tuple[str, str]] = []
    for path, name in frames:
        holo, problem = read_frame(str(path), None, layout)
        if holo is not None:
            return FrameGeometry.of(holo), refused
        assert problem is not None
        if strict:
            raise ValueError(f"frame {name!r}: {problem} (strict: nothing was written)")
        refused.append((name, problem))
    return None, refused


def remember(target: Path, intake: Intake, records: Sequence[Mapping[str, Any]]) -> None:
    """Keep in the store why frames are missing, for ``holoradar info`` and the next run.

    ``records``: those of the tasks that ended (a frame skipped there was found bad when
    read or imaged). Called also when the run stops early. Frames are keyed by absolute
    path; those found bad when read keep their file's stamp
    (:func:`~holoradar.survey.store.note_skipped`).
    """
    by_name = {name: str(k) for k, name in intake.frames}
    bad = {**intake.bad, **{by_name[r["name"]]: r["reason"] for r in records
                            if r["status"] == "skipped" and r["name"] in by_name}}
    reasons = {str(Path(k["name"]).resolve()): k["reason"] for k in intake.skipped}
    reasons.update(bad)
    note_skipped(target, reasons, [str(p) for p in intake.tried],
                 {k: v for k, v in intake.stamps.items() if k in bad and v is not None})
