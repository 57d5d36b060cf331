"""Atomic file output: write to a temporary file beside the target, then rename
(:func:`holoradar.io.output.write_atomic`, here for the applications' modules)."""

from __future__ import annotations

from ..io.output import write_atomic

__all__ = ["write_atomic"]
