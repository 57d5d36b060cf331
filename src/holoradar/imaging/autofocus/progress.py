"""The autofocus's progress bar: a total that only grows, a bar that ends full.

The work is known only as it goes (how many eps' a refinement needs, whether a rival
must be checked): the bar starts from the expected steps, makes room when more come,
and at the end counts the steps that were not needed as done, so that its total never
shrinks and the bar ends at 100 %.
"""

from __future__ import annotations

from typing import Any

__all__ = ["finish_bar", "make_room"]


def make_room(bar: Any, need: int) -> None:
    """Room for ``need`` more steps: the total grows when the count would reach it.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> bar = SimpleNamespace(n=9, total=10, refresh=lambda: None)
    >>> make_room(bar, 4); bar.total
    13
    >>> make_room(bar, 1); bar.total
    13
    """
    if bar is None or bar.total is None:
        return
    if bar.n + need > bar.total:
        bar.total = bar.n + need
        bar.refresh()


def finish_bar(bar: Any) -> None:
    """The work is done: the steps left (not needed) counted, the bar closed."""
    if bar is None:
        return
    if bar.total is not None and bar.n < bar.total:
        bar.update(bar.total - bar.n)
    bar.refresh()
    bar.close()
