"""Shared helpers of the size-learning tests: random biorders, a checking oracle, and
policies walked over all biorders of a size (biorders as uint64 masks, bit p·n+h = fits)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from hypothesis import strategies as st

from asp.sizes.biorders import all_biorders
from asp.sizes.knowledge import Knowledge
from asp.sizes.truth_oracle import TruthOracle


@st.composite
def biorders(draw, max_parts: int = 8, max_holes: int = 8) -> TruthOracle:
    """A random biorder: part and hole sizes on one line, with ties (few distinct sizes)."""
    n_parts = draw(st.integers(1, max_parts))
    n_holes = draw(st.integers(1, max_holes))
    levels = draw(st.integers(1, 4))
    part_sizes = draw(st.lists(st.integers(0, levels), min_size=n_parts, max_size=n_parts))
    hole_sizes = draw(st.lists(st.integers(0, levels), min_size=n_holes, max_size=n_holes))
    parts = [f"p{i}" for i in range(1, n_parts + 1)]
    holes = [f"h{j}" for j in range(1, n_holes + 1)]
    # a part fits when it is strictly smaller; equal sizes do not fit (closed world)
    fits = {(p, h) for p, a in zip(parts, part_sizes) for h, b in zip(holes, hole_sizes) if a < b}
    return TruthOracle(parts, holes, fits)


class CheckingOracle:
    """Answers from a truth and asserts that no asked pair is already known or repeated."""

    def __init__(self, truth: TruthOracle) -> None:
        self.truth = truth
        self.knowledge: Knowledge | None = None
        self.asked: list[tuple[str, str]] = []

    def observe(self, _experiment, knowledge: Knowledge) -> None:
        self.knowledge = knowledge

    def ask(self, part: str, hole: str) -> str:
        assert (part, hole) not in self.asked, f"({part},{hole}) asked twice"
        if self.knowledge is not None:
            assert self.knowledge.result(part, hole) is None, f"({part},{hole}) was entailed"
        self.asked.append((part, hole))
        return self.truth.ask(part, hole)


Chooser = Callable[[int, int, int, int], int]
"""(m, n, fit mask, no-fit mask of the known pairs) -> the pair (bit) to ask next."""


def known_masks(possible: np.ndarray, pairs: int) -> tuple[int, int]:
    """Pairs on which every possible relation agrees (the closure, complete for biorders)."""
    every = int(np.bitwise_and.reduce(possible))
    some = int(np.bitwise_or.reduce(possible))
    return every, ((1 << pairs) - 1) & ~some


def consistent(possible: np.ndarray, bit: int, answer: bool) -> np.ndarray:
    """The possible biorders that give ``answer`` on the pair ``bit``."""
    return possible[((possible >> np.uint64(bit)) & np.uint64(1)).astype(bool) == answer]


def experiments_per_truth(m: int, n: int, chooser: Chooser) -> dict[int, int]:
    """Experiments the policy needs for every m×n biorder (walking its decision tree)."""
    needed: dict[int, int] = {}

    def walk(possible: np.ndarray, depth: int) -> None:
        if len(possible) == 1:
            needed[int(possible[0])] = depth
            return
        bit = chooser(m, n, *known_masks(possible, m * n))
        for answer in (True, False):
            branch = consistent(possible, bit, answer)
            assert 0 < len(branch) < len(possible), "chose a pair whose outcome was entailed"
            walk(branch, depth + 1)

    walk(all_biorders(m, n), 0)
    return needed


def systematic(m: int, n: int, fit_mask: int, no_fit_mask: int) -> int:
    """Lowest part index, then lowest hole index, among unknown pairs."""
    return next(i for i in range(m * n) if not ((fit_mask | no_fit_mask) >> i) & 1)
