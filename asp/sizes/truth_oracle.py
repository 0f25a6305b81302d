"""Oracles answer "insert part P into hole H" with ``fit`` or ``no_fit`` (paper 2.2).

Here the answers come from a ground truth (an assembly's ``sizes.lp``, paper Fig. 5,
or any facts file of ``part/1``, ``hole/1``, ``fits/2``; closed world: a pair not
listed does not fit). Later the simulated cell answers through Zenoh behind the same
:class:`Oracle` protocol. A truth must be one the size model allows: within each
section (a line of the model, :mod:`asp.sizes.models`) a biorder (Ferrers relation),
else the learner's reasoning by transitivity would be unsound for it.
"""

from __future__ import annotations

import random
import re
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Literal, Protocol

from asp import PlannerError
from asp.sizes.models import LINE_SECTION, group_by_section, stated_or_own
from asp.solve import atoms_by_name, check_facts, load_atoms, pairs_by_name
from bridge.assembly import load_assembly
from bridge.inputs import read_text

Result = Literal["fit", "no_fit"]


class Oracle(Protocol):
    """Anything that can run one insertion experiment."""

    def ask(self, part: str, hole: str) -> Result:
        """Try to insert ``part`` into ``hole``: ``"fit"`` or ``"no_fit"``."""
        ...


def ferrers_violation(
    parts: Sequence[str], holes: Sequence[str], fits: set[tuple[str, str]]
) -> tuple[str, str, str, str] | None:
    """``(p, h, q, k)`` with p fits h, q fits k, but p not k and q not h; None if a biorder."""
    rows = {p: {h for h in holes if (p, h) in fits} for p in parts}
    ordered = sorted(parts, key=lambda p: len(rows[p]))
    for small, big in zip(ordered, ordered[1:]):
        if not rows[small] <= rows[big]:
            h = min(rows[small] - rows[big], key=holes.index)
            k = min(rows[big] - rows[small], key=holes.index)
            return small, h, big, k
    return None


class TruthOracle:
    """Answers from a known part-hole relation (closed world), validated as a biorder on
    each section's parts (``sections``: part -> section, a part missing from it on a line
    of its own; None: all parts on one line).

    ``parts`` and ``holes`` keep their order: it is the index order of the learner. A
    truth naming no part or no hole, and no fit (a product with no part in a hole or on a
    pin: nothing to learn), is accepted with ``allow_empty``, else refused.
    """

    def __init__(
        self, parts: Sequence[str], holes: Sequence[str], fits: Iterable[tuple[str, str]],
        source: str = "truth", sections: Mapping[str, str] | None = None, allow_empty: bool = False,
    ) -> None:
        self.parts, self.holes = tuple(parts), tuple(holes)
        self.fits = set(fits)
        self.declared_sections: dict[str, str] = dict(sections or {})
        """The parts' sections stated by the truth's source (its product or section/2 facts)."""
        self.declared_model: str | None = None
        """The size model the truth's product declares, if any."""
        empty = allow_empty and not self.fits and not (self.parts and self.holes)
        if (not self.parts or not self.holes) and not empty:
            raise PlannerError(f"{source}: expected at least one part/1 and one hole/1")
        for p, h in sorted(self.fits):
            if p not in self.parts:
                raise PlannerError(f"{source}: fits({p},{h}): '{p}' is not a declared part/1")
            if h not in self.holes:
                raise PlannerError(f"{source}: fits({p},{h}): '{h}' is not a declared hole/1")
        for section, members in group_by_section(
                dict.fromkeys(self.parts, LINE_SECTION) if sections is None
                else stated_or_own(self.parts, sections)).items():
            bad = ferrers_violation(members, self.holes, self.fits)
            if bad:
                p, h, q, k = bad
                line = "sizes on one line" if sections is None else f"one size line for section {section}"
                raise PlannerError(
                    f"{source}: not a biorder ({line}): {p} fits {h} but not {k}, "
                    f"while {q} fits {k} but not {h}"
                )

    def ask(self, part: str, hole: str) -> Result:
        if part not in self.parts or hole not in self.holes:
            raise PlannerError(f"oracle: unknown pair ({part},{hole}); expected a part and a hole")
        return "fit" if (part, hole) in self.fits else "no_fit"

    @classmethod
    def from_facts(cls, path: Path | str) -> TruthOracle:
        """A truth facts file (``part/1``, ``hole/1``, ``fits/2``, optional ``section/2``, the
        parts' cross-sections); index order = order of first mention in the file. Without
        ``section/2`` the truth is checked to be one size line, and declares the ``line``
        model (its relation is one); with it, a part it gives no section is on its own line."""
        parts, holes, fits, sections = _read_truth(Path(path))
        found = cls(parts, holes, fits, source=str(path), sections=sections or None)
        if not sections:
            found.declared_model = "line"
        return found

    @classmethod
    def from_assembly(cls, name_or_path: str, allow_empty: bool = False) -> TruthOracle:
        """An assembly's ``sizes.lp``, in the order of its ``assembly.toml`` (``allow_empty``:
        one naming no part or no hole is nothing to learn, not refused)."""
        assembly = load_assembly(name_or_path)
        truth_parts, truth_holes, fits, _ = _read_truth(assembly.file("sizes.lp"))
        for kind, ids, known in (("part", truth_parts, assembly.part_ids),
                                 ("hole", truth_holes, assembly.hole_ids)):
            unknown = [i for i in ids if i not in known]
            if unknown:
                raise PlannerError(
                    f"{assembly.folder / 'sizes.lp'}: {kind}(s) {unknown} are not in "
                    f"{assembly.folder / 'assembly.toml'}"
                )
        parts = [p for p in assembly.part_ids if p in truth_parts]
        holes = [h for h in assembly.hole_ids if h in truth_holes]
        declared = assembly.sections()
        sections = None if assembly.size_model == "line" else declared
        found = cls(parts, holes, fits, source=str(assembly.folder / "sizes.lp"), sections=sections,
                    allow_empty=allow_empty)
        found.declared_sections, found.declared_model = declared, assembly.size_model
        return found


def _read_truth(path: Path) -> tuple[list[str], list[str], set[tuple[str, str]], dict[str, str]]:
    """Parts and holes (in order of first mention), fits and ``section/2`` of a truth file."""
    atoms = load_atoms([path])
    check_facts(atoms, {"part": 1, "hole": 1, "fits": 2, "section": 2}, str(path))
    parts = [a for (a,) in atoms_by_name(atoms, "part", 1)]
    holes = [a for (a,) in atoms_by_name(atoms, "hole", 1)]
    text = re.sub(r"%.*", "", read_text(path, "truth facts file", error=PlannerError))

    def mention(name: str) -> int:
        found = re.search(rf"(?<![\w']){re.escape(name)}(?![\w'])", text)
        return found.start() if found else len(text)

    parts.sort(key=mention)
    holes.sort(key=mention)
    return parts, holes, set(pairs_by_name(atoms, "fits")), dict(pairs_by_name(atoms, "section"))


class NoisyOracle:
    """Wraps an oracle and flips each answer with probability ``flip_probability``."""

    def __init__(self, inner: Oracle, flip_probability: float, seed: int = 0) -> None:
        self.inner, self.flip_probability = inner, flip_probability
        self.rng = random.Random(seed)

    def ask(self, part: str, hole: str) -> Result:
        answer = self.inner.ask(part, hole)
        if self.rng.random() < self.flip_probability:
            return "no_fit" if answer == "fit" else "fit"
        return answer
