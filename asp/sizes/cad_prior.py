"""The size prior from nominal CAD dimensions (``sizes learn --prior cad --tolerance T``).

``import`` writes ``nominal_sizes.lp``: ``nominal_margin(P,H,M)``, the room M [µm] of
part P's nominal cross-section in hole H's (negative: it does not pass). Real parts are
made within a tolerance, so only margins beyond it decide: M > T is a fit, M < -T a
no-fit, |M| <= T is left to the experiments. The decided outcomes start the learner as
answers (:class:`asp.sizes.learner.SizeLearner`'s ``prior``), so its closure entails
more and it tries fewer pairs; it still learns from what it observes, and an
observation that contradicts the prior is a conflict re-tested like any other.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import clingo

from asp import MAX_IDS, PlannerError
from asp.sizes.knowledge import Pair
from asp.sizes.truth_oracle import Result
from asp.solve import read_ground_facts
from bridge.assembly import Assembly, is_id
from bridge.inputs import shorten

NOMINAL_FILE = "nominal_sizes.lp"
MAX_TOLERANCE_M = 0.1
"""The largest tolerance a prior takes [m]."""


class Margins(dict[Pair, int]):
    """(part, hole) -> margin [µm] read from ``path``, with the ``lines`` of the file that
    state them (so that a later check can name the line)."""

    def __init__(self, path: Path) -> None:
        super().__init__()
        self.path = path
        self.lines: dict[Pair, int] = {}


def nominal_margins(path: Path) -> Margins:
    """(part, hole) -> margin [µm] of ``path``, read as data (:func:`read_ground_facts`, at
    most one fact per pair of :data:`asp.MAX_IDS` parts and holes);
    PlannerError naming the file and line when it holds anything else, two different margins
    for one pair (naming both lines), or no facts."""
    margins = Margins(path)
    lines = margins.lines
    for line, atom in read_ground_facts(path, "nominal_margin(Part,Hole,Micrometres) facts",
                                        max_facts=MAX_IDS * MAX_IDS):
        arguments = atom.arguments
        if (atom.name != "nominal_margin" or len(arguments) != 3 or not all(is_id(str(a)) for a in arguments[:2])
                or arguments[2].type != clingo.SymbolType.Number):
            raise PlannerError(f"{path}:{line}: {shorten(atom, 60)}: expected nominal_margin(Part,Hole,Micrometres) "
                               "facts only (a part and hole id, an integer)")
        pair, value = (str(arguments[0]), str(arguments[1])), arguments[2].number
        if pair in margins and margins[pair] != value:
            raise PlannerError(f"{path}:{line}: nominal_margin({pair[0]},{pair[1]},{value}) contradicts line "
                               f"{lines[pair]}: nominal_margin({pair[0]},{pair[1]},{margins[pair]}); expected one "
                               "margin per part and hole")
        margins[pair] = value
        lines.setdefault(pair, line)
    if not margins:
        raise PlannerError(f"{path}: no nominal_margin/3 facts (expected the file ./run.sh import writes)")
    return margins


def decided(margins: Margins, tolerance: float, parts: tuple[str, ...], holes: tuple[str, ...]
            ) -> list[tuple[Pair, Result]]:
    """The outcomes the margins decide beyond ``tolerance`` [m], in part then hole order;
    PlannerError naming the file (and the line of the first fact) when the margins name a
    part or hole not among ``parts`` and ``holes``, or miss a pair of ``parts`` × ``holes``."""
    strange = sorted((line, pair) for pair, line in margins.lines.items()
                     if pair[0] not in parts or pair[1] not in holes)
    if strange:
        unknown = sorted({p for _, (p, _) in strange if p not in parts}
                         | {h for _, (_, h) in strange if h not in holes})
        raise PlannerError(f"{margins.path}:{strange[0][0]}: unknown part or hole {' '.join(unknown[:5])} (expected "
                           f"the parts {' '.join(parts)} and holes {' '.join(holes)} of the product)")
    missing = [f"{p}->{h}" for p in parts for h in holes if (p, h) not in margins]
    if missing:
        raise PlannerError(f"{margins.path}: no nominal margin for {' '.join(missing[:5])} (expected every part "
                           "and hole of sizes.lp)")
    bound = 1e6 * tolerance
    outcomes: list[tuple[Pair, Result]] = []
    for part in parts:
        for hole in holes:
            value = margins[(part, hole)]
            if value > bound:
                outcomes.append(((part, hole), "fit"))
            elif value < -bound:
                outcomes.append(((part, hole), "no_fit"))
    return outcomes


def cad_prior(assembly: Assembly, tolerance: float, parts: tuple[str, ...], holes: tuple[str, ...]
              ) -> list[tuple[Pair, Result]]:
    """The outcomes the nominal sections of ``assembly`` (its ``nominal_sizes.lp``) decide
    beyond ``tolerance`` [m] over ``parts`` × ``holes`` (:func:`decided`); PlannerError
    naming the folder when it has no such file."""
    if not assembly.has_file(NOMINAL_FILE):
        raise PlannerError(f"--prior cad: {assembly.folder}: no {NOMINAL_FILE} (expected an assembly folder "
                           "./run.sh import wrote)")
    return decided(nominal_margins(assembly.file(NOMINAL_FILE)), tolerance, parts, holes)


def prior_text(prior: Sequence[tuple[Pair, str]], tolerance: float, pairs: int) -> str:
    """The line that states the prior a run assumes: its tolerance [m shown as mm], how
    many of ``pairs`` pairs it decides, and which."""
    return (f"the CAD prior (tolerance {1000 * tolerance:g} mm) decides {len(prior)} of {pairs} pairs"
            + (": " + " ".join(f"{p}->{h} {r}" for (p, h), r in prior) if prior else ""))
