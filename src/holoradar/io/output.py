"""Safe output files: never an input, never an existing file unless asked, the folder
checked before any work, written atomically with the user's umask."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

__all__ = ["check_output", "default_mode", "write_atomic", "write_via_temp"]


def default_mode() -> int:
    """Permission bits a new file gets from ``open()``: ``0o666`` less the umask.

    Temporary files are created 0600; the finished file is given these bits so
    that it looks like any other file the user writes. The umask is read from
    ``/proc/self/status`` where the system has it: setting it to learn it (the
    portable way) would briefly change it for the process's other threads.
    """
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def check_output(path: str | os.PathLike[str], *, suffixes: Iterable[str],
                 inputs: Iterable[str | os.PathLike[str]] = (), overwrite: bool = False,
                 name: str = "path", folder: bool = False,
                 replace_word: str | None = None) -> Path:
    """Validate an output path before any computation; return it as a ``Path``.

    ``folder=True`` for an output that is itself a folder (a Zarr store). A
    ``name`` that is a command-line option (``--out``, ``--out's PNG``) gets the
    command line's word in a refusal (``--force``); any other the API's
    (``overwrite=True``), unless ``replace_word`` names the caller's own.

    Raises
    ------
    ValueError
        The suffix does not match the format, the path is one of the inputs, it
        exists and ``overwrite`` is False, its folder does not exist or is not
        writable, or it is a folder (for a file output).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> check_output(d / "a.nc", suffixes=[".nc"]).name
    'a.nc'
    >>> check_output(d / "a.png", suffixes=[".nc"])
    Traceback (most recent call last):
    ...
    ValueError: path must end in .nc for this format, got 'a.png'
    """
    target = Path(path)
    allowed = [s.lower() for s in suffixes]
    if not any(target.name.lower().endswith(s) for s in allowed):
        raise ValueError(f"{name} must end in {' or '.join(allowed)} for this format, got "
                         f"{target.name!r}")
    # An input exists: a target that does not cannot be one (no path to resolve per input:
    # a survey passes thousands). One that does is compared by file identity.
    here = _identity(target)
    for src in inputs if here is not None else ():
        if _identity(src) == here:
            raise ValueError(f"{name} {str(target)!r} is one of the inputs: refusing to replace "
                             "the data it was computed from")
    if not target.parent.is_dir():
        raise ValueError(f"{name}: the folder {str(target.parent)!r} does not exist")
    if not os.access(target.parent, os.W_OK | os.X_OK):
        raise ValueError(f"{name}: the folder {str(target.parent)!r} is not writable")
    if target.is_dir() and not folder:
        raise ValueError(f"{name} {str(target)!r} is a folder")
    if target.exists() and not overwrite:
        how = replace_word or ("--force" if name.startswith("--") else "overwrite=True")
        raise ValueError(f"{name} {str(target)!r} exists: pass {how} to replace it")
    return target


def write_via_temp(target: Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``target``, then rename it onto
    ``target`` with the user's umask; on failure nothing is left behind."""
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        write(tmp_path)
        with open(tmp_path, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp_path, default_mode())
        os.replace(tmp_path, target)
    except BaseException:
        tmp_path.unlink(missing_ok=True)
        raise
    return target


def write_atomic(path: str | os.PathLike[str], payload: bytes) -> Path:
    """Write ``payload`` to ``path`` so that readers see the old file or the new one, never half.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> write_atomic(d / "a.txt", b"hi").read_bytes()
    b'hi'
    """
    return write_via_temp(Path(path), lambda tmp: tmp.write_bytes(payload))


def _identity(path: str | os.PathLike[str]) -> tuple[int, int] | None:
    """``(device, inode)`` of an existing path (links followed), else None."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino
