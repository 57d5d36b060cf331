"""Atomic file output: write to a temporary file beside the target, then rename."""

from __future__ import annotations

import os
from pathlib import Path

from ..io.output import write_via_temp

__all__ = ["write_atomic"]


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
