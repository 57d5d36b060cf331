"""Modules imported on first use, so that ``import holoradar`` stays cheap.

``import holoradar`` and ``holoradar --help`` should cost little more than numpy:
``scipy.fft`` alone adds about as much as numpy again, ``scipy.interpolate`` and
``scipy.stats`` several times that (docs: README, "Start-up"). A module-level
``sfft = lazy_module("scipy.fft")`` keeps the call sites as they are (``sfft.fft2``)
and imports the module on the first attribute read; the few names taken with
``from scipy.x import y`` are imported inside the functions that use them.

Examples
--------
>>> from holoradar._lazy import lazy_module
>>> fft = lazy_module("numpy.fft")
>>> fft
<lazy module 'numpy.fft'>
>>> float(fft.fft([1.0, 1.0])[0].real)
2.0
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any

__all__ = ["LazyModule", "lazy_module"]


class LazyModule:
    """Stands for a module that is imported when one of its attributes is first read.

    Parameters
    ----------
    name : str
        The module's absolute name, e.g. ``"scipy.fft"``.

    Notes
    -----
    The module is imported with :func:`importlib.import_module`, under the import
    system's lock, so threads that reach it together import it once. Nothing is put
    in ``sys.modules`` before that: a test can tell whether it has been imported.
    """

    __slots__ = ("_module", "_name")

    def __init__(self, name: str) -> None:
        self._name = name
        self._module: ModuleType | None = None

    def __getattr__(self, attr: str) -> Any:
        # Only reached for names the proxy itself lacks, i.e. the module's own.
        module = self._module
        if module is None:
            module = self._module = importlib.import_module(self._name)
        return getattr(module, attr)

    def __dir__(self) -> list[str]:
        return dir(importlib.import_module(self._name))

    def __repr__(self) -> str:
        state = "module" if self._module is not None else "lazy module"
        return f"<{state} {self._name!r}>"


def lazy_module(name: str) -> Any:
    """A stand-in for module ``name`` that imports it on the first attribute read.

    Parameters
    ----------
    name : str
        The module's absolute name.

    Returns
    -------
    LazyModule
        Typed ``Any``: a type checker would otherwise flag every ``sfft.fft2(...)``
        as an unknown attribute of the proxy.
    """
    return LazyModule(name)
