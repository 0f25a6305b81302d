"""Shared helpers of the size-learning tests: random biorders and a checking oracle."""

from __future__ import annotations

from hypothesis import strategies as st

from asp.oracle import TruthOracle
from asp.size_knowledge import Knowledge


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
