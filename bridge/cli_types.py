"""Argument types both command lines share (argparse ``type=`` callables).

A malformed value raises :class:`argparse.ArgumentTypeError`, which argparse turns into
``error: argument --x: ...`` and exit code 2.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import TypeVar

from bridge import BridgeError

T = TypeVar("T")


def comma_list(
    item: Callable[[str], T], what: str = "values", allow_empty: bool = False
) -> Callable[[str], list[T]]:
    """An argparse type: ``"a,b,c"`` → ``[item("a"), item("b"), item("c")]``.

    Empty items, and items ``item`` rejects (ValueError, ArgumentTypeError, BridgeError), are an
    error naming the whole text and ``what`` was expected; ``""`` is the empty list when
    ``allow_empty``.
    """

    def parse(text: str) -> list[T]:
        if allow_empty and not text.strip():
            return []
        parts = [part.strip() for part in text.split(",")]
        try:
            if not all(parts):
                raise ValueError(text)
            return [item(part) for part in parts]
        except (ValueError, argparse.ArgumentTypeError, BridgeError):
            raise argparse.ArgumentTypeError(f"{text!r}: expected comma-separated {what}") from None

    return parse


def number_in(kind: Callable[[str], float], low: float, high: float) -> Callable[[str], float]:
    """An item type: a finite number of ``kind`` in [low, high) (ValueError otherwise)."""

    def parse(text: str) -> float:
        value = kind(text)
        if not (math.isfinite(value) and low <= value < high):
            raise ValueError(text)
        return value

    return parse


def size_pair(text: str) -> tuple[int, int]:
    """An item type: ``"4x5"`` → ``(4, 5)``, both positive (ValueError otherwise)."""
    m, sep, n = text.partition("x")
    size = (int(m), int(n)) if sep else (0, 0)
    if min(size) < 1:
        raise ValueError(text)
    return size


def part_hole_pair(text: str) -> tuple[str, str]:
    """An item type: ``"p1:r1"`` → ``("p1", "r1")`` (ValueError otherwise)."""
    part, sep, hole = text.partition(":")
    if not (sep and part and hole) or ":" in hole:
        raise ValueError(text)
    return part, hole
