"""What the size learner knows: the closure of the smaller-than relation (paper 2.2).

:class:`Knowledge` is an immutable snapshot read from one model of
``sizes_closure.lp``: the smaller-than relation on each section's size line, the
part-hole pairs known to fit / not to fit (observed or entailed), the pairs still
unknown, and the observations that lie on a cycle (noise, or a model the observations
contradict). Policies written in Python receive it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import clingo

from asp.sizes.models import LINE_SECTION

Pair = tuple[str, str]
"""A part-hole pair ``(part, hole)`` of ASP constants."""

RESULTS: tuple[str, str] = ("fit", "no_fit")
"""The two outcomes of an insertion experiment."""


@dataclass(frozen=True)
class Knowledge:
    """The learner's knowledge after some experiments.

    ``parts`` and ``holes`` are in index order (index 1 first); the pair sets hold
    ``(part, hole)``; ``smaller`` holds ``(x, y)`` with x smaller than y, both parts or
    holes (``smaller/2`` of the closure); ``lines`` holds ``(section, x, y)``: x smaller
    than y on that section's size line; ``sections`` maps each part to its section
    (empty: every part on one line); ``conflicts`` holds ``(part, hole, result)``
    observations on a cycle.
    """

    parts: tuple[str, ...]
    holes: tuple[str, ...]
    smaller: frozenset[tuple[str, str]]
    fits: frozenset[Pair]
    no_fit: frozenset[Pair]
    conflicts: frozenset[tuple[str, str, str]]
    lines: frozenset[tuple[str, str, str]] = frozenset()
    sections: tuple[tuple[str, str], ...] = ()

    def section_of(self, part: str) -> str:
        """The section whose size line ``part`` lies on (:data:`LINE_SECTION` when none is given)."""
        return dict(self.sections).get(part, LINE_SECTION)

    def restricted(self, parts: Sequence[str]) -> Knowledge:
        """The knowledge of ``parts`` (one section's parts) and every hole, in index order."""
        keep = set(parts)
        return Knowledge(
            parts=tuple(p for p in self.parts if p in keep), holes=self.holes,
            smaller=frozenset((x, y) for x, y in self.smaller if x in keep or y in keep),
            fits=frozenset(pair for pair in self.fits if pair[0] in keep),
            no_fit=frozenset(pair for pair in self.no_fit if pair[0] in keep),
            conflicts=frozenset(c for c in self.conflicts if c[0] in keep),
            lines=frozenset(e for e in self.lines if e[1] in keep or e[2] in keep),
            sections=tuple((p, s) for p, s in self.sections if p in keep))

    @property
    def unknown(self) -> list[Pair]:
        """Pairs neither known to fit nor known not to fit, in index order."""
        return [
            (p, h)
            for p in self.parts
            for h in self.holes
            if (p, h) not in self.fits and (p, h) not in self.no_fit
        ]

    @property
    def complete(self) -> bool:
        """Every pair known and no conflict left."""
        return not self.conflicts and not self.unknown

    def result(self, part: str, hole: str) -> str | None:
        """``"fit"``, ``"no_fit"`` or None when the pair is unknown (or in conflict: both)."""
        fit, no_fit = (part, hole) in self.fits, (part, hole) in self.no_fit
        if fit == no_fit:
            return None
        return "fit" if fit else "no_fit"

    def matrix(self) -> list[list[int | None]]:
        """Rows = parts, columns = holes: 1 fits, 0 does not fit, None unknown."""
        code = {"fit": 1, "no_fit": 0, None: None}
        return [[code[self.result(p, h)] for h in self.holes] for p in self.parts]

    @classmethod
    def from_symbols(
        cls,
        parts: Sequence[str],
        holes: Sequence[str],
        symbols: Iterable[clingo.Symbol],
        decoded: dict[clingo.Symbol, tuple[str, tuple[str, ...]]] | None = None,
        sections: Sequence[tuple[str, str]] = (),
    ) -> Knowledge:
        """Read the shown atoms of a ``sizes_closure.lp`` model.

        ``decoded`` caches ``symbol -> (name, argument strings)`` across calls (reading
        arguments through clingo's API costs more than the solve on small instances).
        """
        decoded = {} if decoded is None else decoded
        entries = []
        for symbol in symbols:
            entry = decoded.get(symbol)
            if entry is None:
                entry = decoded[symbol] = (symbol.name, tuple(str(a) for a in symbol.arguments))
            entries.append(entry)
        return cls.from_entries(parts, holes, entries, sections)

    @classmethod
    def from_entries(
        cls,
        parts: Sequence[str],
        holes: Sequence[str],
        entries: Iterable[tuple[str, tuple[str, ...]]],
        sections: Sequence[tuple[str, str]] = (),
    ) -> Knowledge:
        """:meth:`from_symbols` of atoms already decoded as ``(name, argument strings)``."""
        sets: dict[str, set] = {"smaller": set(), "fits": set(), "no_fit": set(), "in_conflict": set(), "lt": set()}
        for name, arguments in entries:
            target = sets.get(name)
            if target is not None:
                target.add(arguments)
        return cls(
            parts=tuple(parts),
            holes=tuple(holes),
            smaller=frozenset(sets["smaller"]),
            fits=frozenset(sets["fits"]),
            no_fit=frozenset(sets["no_fit"]),
            conflicts=frozenset(sets["in_conflict"]),
            lines=frozenset(sets["lt"]),
            sections=tuple(sections),
        )
