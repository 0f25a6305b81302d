"""The one progress mechanism of long work: a ``tqdm`` bar on stderr.

A bar is drawn only when stderr is a terminal and the log level lets INFO through (the
command line's default; ``-q`` silences it), so pipes, files, CI logs and tests see
nothing. Results never go through here: they are printed or written by the caller.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Iterable, Iterator
from typing import TypeVar

from tqdm import tqdm

T = TypeVar("T")


def progress_wanted() -> bool:
    """Whether a progress bar would be shown now (a terminal on stderr, INFO enabled)."""
    return sys.stderr.isatty() and logging.getLogger().isEnabledFor(logging.INFO)


def progress(iterable: Iterable[T], *, desc: str, total: int | None = None, unit: str = "it") -> Iterator[T]:
    """``iterable``, with a bar ``desc`` (``total`` items of ``unit``) when wanted."""
    if not progress_wanted():
        yield from iterable
        return
    yield from tqdm(iterable, desc=desc, total=total, unit=unit, file=sys.stderr, dynamic_ncols=True)
