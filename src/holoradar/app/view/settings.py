"""What the viewer shows, as a value: read from and written to a TOML file.

The page's state is one :class:`ViewSettings`. ``holoradar view`` starts from
one (``--settings``), the page's *settings* export writes one, and ``holoradar
render`` turns one into the same image in batch. The TOML form::

    files = ["view_a.nc", "view_b.nc"]   # relative to the TOML's folder

    [image]
    depth = 0.10          # m below the ground surface (range from the array without one)
    frame = "aperture"    # or "ground" (level planes, for a tilted array)
    upsample = 4          # image pixels per element pitch
    fov = "full"          # or "aperture"
    sweep = [0.0, 0.3]    # depths of the sections, m
    planes = 61

    [views]
    use = [0, 1]              # indices of the views summed (default all)
    mode = "coherent"         # or "quasi-coherent", "amplitude"
    frequency = "coherent"    # or "incoherent", or an index into the frequencies

    [glare]
    method = "off"        # or "gaussian", "image_source", "cut"
    direct = true         # also remove the horn's direct wave

    [display]
    scale = "db"          # or "linear"
    db_range = 30.0
    plane = "image"       # or "mirror": the glare's mirror-source plane, or
                          # "reflectivity": one view's inverted reflectivity (hr.invert)
    section = [0.0, 0.0]  # x, y (m) of the vertical sections; omitted: through the peak

    [ground]              # as holoradar's scene and medium files: surface, eps[, tan_delta]
    surface = 0.30        # or [[ground.layer]] tables with top, eps
    eps = "2.5+0.0125j"
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ...imaging.migration.settings import MigrationSettings, check_choice, check_upsample

__all__ = ["GLARE_METHODS", "MODES", "PLANES", "ViewSettings", "read_settings", "settings_toml"]

GLARE_METHODS = ("off", "gaussian", "image_source", "cut")
MODES = ("coherent", "quasi-coherent", "amplitude")
PLANES = ("image", "mirror", "reflectivity")
_FREQ = ("coherent", "incoherent")


@dataclass(frozen=True)
class ViewSettings:
    """One look at the data: every knob of the viewer (see the module docstring).

    Examples
    --------
    >>> s = ViewSettings(files=("a.nc",), depth=0.1, ground={"surface": 0.3, "eps": 2.5})
    >>> s.replace(glare="gaussian").glare
    'gaussian'
    """

    files: tuple[str, ...] = ()
    depth: float = 0.1
    frame: str = "aperture"
    upsample: int = 4
    fov: str = "full"
    sweep: tuple[float, float] | None = None
    planes: int = 61
    views: tuple[int, ...] | None = None
    mode: str = "coherent"
    frequency: str | int = "coherent"
    glare: str = "off"
    direct: bool = True
    scale: str = "db"
    db_range: float = 30.0
    plane: str = "image"
    section: tuple[float, float] | None = None
    ground: Mapping[str, Any] | None = field(default=None)

    def __post_init__(self) -> None:
        # Lists (as TOML and JSON give them) are taken as the tuples the fields hold.
        for name in ("files", "sweep", "views", "section"):
            v = getattr(self, name)
            if isinstance(v, list):
                object.__setattr__(self, name, tuple(v))
        _check(self)

    def migration(self) -> MigrationSettings:
        """How these settings migrate a view: ``migrate``'s options (a coherent band
        unless ``frequency`` is "incoherent"; the field of view in the aperture's own
        frame only; no progress bar in a page).

        Examples
        --------
        >>> ViewSettings(upsample=2, fov="aperture").migration().fov
        'aperture'
        """
        return MigrationSettings(
            upsample=self.upsample, frame=self.frame,
            fov=self.fov if self.frame == "aperture" else "aperture",
            combine="incoherent" if self.frequency == "incoherent" else "coherent",
            progress=False, dtype=np.complex64)   # migrate's default precision

    def replace(self, **changes: Any) -> ViewSettings:
        """A copy with ``changes`` (checked like the constructor's arguments)."""
        return replace(self, **changes)


def _fail(name: str, expected: str, got: Any) -> None:
    raise ValueError(f"{name} must be {expected}, got {got!r}")


def _finite(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _check(s: ViewSettings) -> None:
    if not isinstance(s.files, tuple) or not all(isinstance(f, str) and f for f in s.files):
        _fail("files", "a list of file names", s.files)
    if not _finite(s.depth):
        _fail("image.depth", "a depth in metres", s.depth)
    # The imaging options are migrate's own, checked by the same functions.
    check_choice(s.frame, "image.frame", ("aperture", "ground"))
    check_upsample(s.upsample, "image.upsample", top=16)
    check_choice(s.fov, "image.fov", ("full", "aperture"))
    if s.sweep is not None and not (isinstance(s.sweep, tuple | list) and len(s.sweep) == 2
                                    and all(map(_finite, s.sweep))
                                    and s.sweep[1] > s.sweep[0]):
        _fail("image.sweep", "[first, last] depths in metres, last > first", s.sweep)
    if not isinstance(s.planes, int) or isinstance(s.planes, bool) or not 2 <= s.planes <= 1000:
        _fail("image.planes", "an integer from 2 to 1000", s.planes)
    if s.views is not None and not (isinstance(s.views, tuple) and s.views and all(
            isinstance(i, int) and not isinstance(i, bool) and i >= 0 for i in s.views)):
        _fail("views.use", "a non-empty list of view indices (0, 1, ...)", s.views)
    if s.views is not None and len(set(s.views)) != len(s.views):
        _fail("views.use", "view indices each named once", s.views)
    if s.mode not in MODES:
        _fail("views.mode", " or ".join(map(repr, MODES)), s.mode)
    f = s.frequency
    if not (f in _FREQ or (isinstance(f, int) and not isinstance(f, bool) and f >= 0)):
        _fail("views.frequency", "'coherent', 'incoherent' or a frequency index (0, 1, ...)", f)
    if s.glare not in GLARE_METHODS:
        _fail("glare.method", " or ".join(map(repr, GLARE_METHODS)), s.glare)
    if not isinstance(s.direct, bool):
        _fail("glare.direct", "true or false", s.direct)
    if s.scale not in ("db", "linear"):
        _fail("display.scale", "'db' or 'linear'", s.scale)
    if not _finite(s.db_range) or not 1 <= s.db_range <= 200:
        _fail("display.db_range", "a number of dB from 1 to 200", s.db_range)
    if s.plane not in PLANES:
        _fail("display.plane", "'image', 'mirror' or 'reflectivity'", s.plane)
    if s.section is not None and not (isinstance(s.section, tuple | list)
                                      and len(s.section) == 2
                                      and all(map(_finite, s.section))):
        _fail("display.section", "[x, y] in metres", s.section)
    if s.ground is not None and not isinstance(s.ground, Mapping):
        _fail("ground", "a table (surface, eps or [[ground.layer]])", s.ground)


_TABLES: dict[str, dict[str, str]] = {
    "image": {"depth": "depth", "frame": "frame", "upsample": "upsample", "fov": "fov",
              "sweep": "sweep", "planes": "planes"},
    "views": {"use": "views", "mode": "mode", "frequency": "frequency"},
    "glare": {"method": "glare", "direct": "direct"},
    "display": {"scale": "scale", "db_range": "db_range", "plane": "plane",
                "section": "section"},
}


def read_settings(path: str | Path) -> ViewSettings:
    """Read a settings TOML (as the viewer's *settings* export writes it).

    Relative file names are taken from the TOML's folder.

    Parameters
    ----------
    path : str or Path
        The TOML file (format in this module's docstring).

    Returns
    -------
    ViewSettings

    Raises
    ------
    ValueError
        Not TOML, an unknown table or key (named), or a value of the wrong form.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "look.toml"
    >>> _ = p.write_text('files = ["a.nc"]\\n[image]\\ndepth = 0.05\\n')
    >>> s = read_settings(p)
    >>> s.depth, Path(s.files[0]).name
    (0.05, 'a.nc')
    """
    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{p.name} is not valid TOML ({exc})") from None
    unknown = set(doc) - {"files", "ground", *_TABLES}
    if unknown:
        raise ValueError(f"{p.name}: unknown entries {sorted(unknown)}; expected files, "
                         f"{', '.join(f'[{t}]' for t in _TABLES)}, [ground]")
    kw: dict[str, Any] = {}
    files = doc.get("files", [])
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        _fail(f"{p.name}: files", "a list of file names", files)
    kw["files"] = tuple(str((p.parent / f) if not Path(f).is_absolute() else Path(f))
                        for f in files)
    for table, keys in _TABLES.items():
        t = doc.get(table, {})
        if not isinstance(t, dict):
            _fail(f"{p.name}: [{table}]", "a table", t)
        bad = set(t) - set(keys)
        if bad:
            raise ValueError(f"{p.name}: unknown keys {sorted(bad)} in [{table}]; expected "
                             f"{', '.join(keys)}")
        for k, v in t.items():
            kw[keys[k]] = tuple(v) if isinstance(v, list) else v
    if "ground" in doc:
        kw["ground"] = doc["ground"]
    try:
        return ViewSettings(**kw)
    except ValueError as exc:
        raise ValueError(f"{p.name}: {exc}") from None


def _plain(v: Any) -> Any:
    if isinstance(v, complex):
        # repr keeps every digit: a saved look reproduces the image bit for bit
        return f"{v.real!r}{v.imag:+}j"
    if isinstance(v, Mapping):
        return {k: _plain(x) for k, x in v.items() if x is not None}
    if isinstance(v, list | tuple):
        return [_plain(x) for x in v]
    return v


def settings_toml(s: ViewSettings, *, relative_to: Path | None = None) -> str:
    """The TOML text of ``s`` (file names relative to ``relative_to`` where possible).

    Parameters
    ----------
    s : ViewSettings
    relative_to : Path, optional
        The folder the TOML will live in.

    Returns
    -------
    str
        What :func:`read_settings` reads back to ``s``.

    Examples
    --------
    >>> print(settings_toml(ViewSettings(files=("a.nc",), glare="gaussian")).splitlines()[0])
    # holoradar view settings: `holoradar render THIS.toml -o image.nc` reproduces the image
    """
    import tomli_w

    d = asdict(s)
    files = []
    for f in s.files:
        fp = Path(f).resolve()
        if relative_to is not None:
            try:
                fp = fp.relative_to(relative_to.resolve())
            except ValueError:
                pass
        files.append(fp.as_posix())
    doc: dict[str, Any] = {"files": files}
    for table, keys in _TABLES.items():
        doc[table] = {k: _plain(d[a]) for k, a in keys.items() if d[a] is not None}
    if s.ground is not None:
        doc["ground"] = _plain(dict(s.ground))
    head = ("# holoradar view settings: `holoradar render THIS.toml -o image.nc` reproduces "
            "the image\n")
    return head + tomli_w.dumps(doc)
