"""Size models: which part-hole relations the size learner considers possible.

The learner entails an outcome only when every relation of its model that agrees with
the observations agrees on it (docs/sizes.md, "Size models"). A model puts each part on
the size line of a *section* (``section(P,S)`` facts for ``sizes/closure.lp``); the
relations it allows are those whose rows of each section form a biorder (Ferrers
relation), independently across sections. Three models, strongest first:

- ``line``: one section for all parts (the paper's eqs. 2-5, sizes on one line);
- ``sections``: one line per cross-section of the product description: pegs with the
  same ``section`` are scaled copies of one cross-section, and whether such a peg
  passes a hole is monotone in its scale (round in round or square, square in round
  by its diagonal, one rectangle's aspect in any hole), so each section is a line; a
  part whose cross-section the product does not state is on a line of its own (nothing
  says it is a scaled copy of another part, so no outcome of it is entailed through
  another part's);
- ``pairs``: every part its own section: nothing is entailed, every pair is tried.

A model is weakened along this order when observations contradict it
(:func:`weaker`).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

from asp import PlannerError
from asp.sizes.biorders import biorder_count
from bridge.assembly import SIZE_MODELS

MODELS = SIZE_MODELS
"""The size models, strongest first (the names a product may declare)."""

LINE_SECTION = "line"
"""The one section of the ``line`` model."""


def own_section(part: str, taken: Collection[str]) -> str:
    """The section of ``part`` alone: ``of_<part>``, with ``_`` appended until it is not in
    ``taken`` (the sections the product states), so it shares no other part's line."""
    label = f"of_{part}"
    while label in taken:
        label += "_"
    return label


def stated_or_own(parts: Sequence[str], declared: Mapping[str, str]) -> dict[str, str]:
    """Part -> its stated section in ``declared``, or a section of its own
    (:func:`own_section`) when the product states none."""
    taken = set(declared.values())
    return {part: declared[part] if part in declared else own_section(part, taken) for part in parts}


def group_by_section(sections: Mapping[str, str]) -> dict[str, list[str]]:
    """Section -> its parts, in the order of ``sections`` (part -> section)."""
    found: dict[str, list[str]] = {}
    for part, section in sections.items():
        found.setdefault(section, []).append(part)
    return found


@dataclass(frozen=True)
class SizeModel:
    """A model applied to a product: its ``name`` and the section of each part.

    ``sections`` maps every part to the section whose size line it lies on; ``declared``
    is the sections the product states (for the parts whose cross-section it states;
    ``sections`` puts each other part on a line of its own), kept so that a weaker model
    can be derived and the summary can say what ``line`` merges.
    """

    name: str
    sections: Mapping[str, str]
    declared: Mapping[str, str]

    def groups(self) -> dict[str, list[str]]:
        """Section -> its parts, in the parts' order."""
        return group_by_section(self.sections)

    def assumption(self) -> str:
        """One line saying what the model assumes, printed and written beside the results."""
        if not self.sections:
            return f"size model {self.name}: nothing to learn (no part goes into a hole or onto a pin)"
        if self.name == "pairs":
            return "size model pairs: no two pairs related, every pair is tried"
        groups = self.groups()
        if self.name == "line":
            kinds = len(set(self.declared.values()))
            merged = f" (the product declares {kinds} cross-sections)" if kinds > 1 else ""
            return f"size model line: every part and hole on one size line{merged}"
        unstated = [part for part in self.sections if part not in self.declared]
        lines = [f"{section}: {' '.join(parts)}" for section, parts in groups.items()
                 if parts[0] in self.declared]
        if unstated:
            lines.append(f"no cross-section stated, each on its own line: {' '.join(unstated)}")
        return f"size model sections: one size line per cross-section ({'; '.join(lines)})"

    def information_bits(self, holes: int) -> float:
        """log2 of the number of relations the model allows with ``holes`` holes [bit]:
        the sum over sections of log2 B(m_S, n), B the poly-Bernoulli number."""
        return sum(math.log2(biorder_count(len(parts), holes)) for parts in self.groups().values())


def build_model(name: str, parts: Sequence[str], declared: Mapping[str, str] | None = None) -> SizeModel:
    """The model ``name`` for ``parts``; ``declared`` maps parts to the sections the
    product states (under ``sections`` a part missing from it is on a line of its own)."""
    if name not in MODELS:
        raise PlannerError(f"size model '{name}': expected one of {', '.join(MODELS)}")
    stated = {part: section for part, section in (declared or {}).items() if part in parts}
    if name == "line":
        sections = dict.fromkeys(parts, LINE_SECTION)
    elif name == "sections":
        sections = stated_or_own(parts, stated)
    else:
        sections = {part: f"of_{part}" for part in parts}
    return SizeModel(name, sections, stated)


def weaker(model: SizeModel) -> SizeModel | None:
    """The next weaker model (``line`` -> ``sections`` -> ``pairs``; ``sections`` is
    skipped where it is ``line`` itself, all parts stating one section, or ``pairs``
    itself, no two parts on one line), or None for ``pairs``."""
    parts = list(model.sections)
    lines = group_by_section(stated_or_own(parts, model.declared)).values()
    if model.name == "line" and len(lines) > 1 and max(map(len, lines)) > 1:
        return build_model("sections", parts, model.declared)
    if model.name in ("line", "sections"):
        return build_model("pairs", parts, model.declared)
    return None


def check_line_allowed(model: SizeModel, declared_by_product: bool) -> None:
    """Refuse ``line`` on parts of several declared cross-sections unless the product
    itself declares the line (the explicit override, which the summary repeats)."""
    if model.name != "line" or declared_by_product:
        return
    groups = group_by_section(model.declared)
    if len(groups) > 1:
        listed = "; ".join(f"{section}: {' '.join(parts)}" for section, parts in groups.items())
        raise PlannerError(
            f"size model line puts parts of {len(groups)} cross-sections ({listed}) on one size "
            "line, which can entail fits that do not exist; use --model sections, or declare "
            "[sizes] model = \"line\" in the product's assembly.toml when its sizes are known to lie on one line"
        )


def model_for(parts: Sequence[str], requested: str | None, declared_model: str | None,
              declared_sections: Mapping[str, str]) -> SizeModel:
    """The model a run uses: ``requested`` (a command-line choice), else the product's
    ``declared_model``, else ``sections``; ``line`` on parts of several declared
    cross-sections only when the product declares it (:func:`check_line_allowed`)."""
    name = requested or declared_model or "sections"
    model = build_model(name, parts, declared_sections)
    check_line_allowed(model, declared_by_product=declared_model == "line")
    return model
