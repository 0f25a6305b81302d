"""Precedence experiments keep the cell's own orders (``cell_before(P,Q)``: the fingers
holding P would meet Q in place, docs/cell.md#the-fingers-grip): no experiment places P
after Q, a failure such a step would explain confirms nothing, and a pair (P,Q) the truth
leaves free is reported undecidable by the cell, never guessed
(docs/precedence.md, docs/session.md#precedence-by-exploration)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from asp.precedence.demos import Demonstrations, load_demos
from asp.precedence.explore.knowledge import Evidence, Trial
from asp.precedence.explore.learner import Learned, learn_sources
from asp.precedence.explore.oracle import TruthOracle
from asp.precedence.explore.select import explore
from asp.precedence.relation import Pair, Relation, true_relation
from assembly_constraints.cli import main
from bridge.assembly import load_assembly
from bridge.precedence.experiment import ExperimentStep, PrecedenceExperiment, PrecedenceOutcome

CRANFIELD_ORDERS = (("p1", "fp"), ("p2", "fp"), ("p3", "fp"), ("p3", "sp"), ("p4", "fp"), ("p4", "sp"))
"""The orders Cranfield's round trip (export, import) writes to its cell_order.lp (tests/cad/test_import.py)."""


def breaks(sequence: list[str], orders: tuple[Pair, ...]) -> list[Pair]:
    """The orders (P, Q) the sequence breaks: Q placed, then P."""
    return [(p, q) for p, q in orders if p in sequence and q in sequence and sequence.index(q) < sequence.index(p)]


class Hand:
    """A cell with fingers: answers from ``truth`` (:class:`TruthOracle`), but a step placing
    P after a placed Q of ``orders`` fails ``blocked`` by Q (the fingers meet it), as a real
    hand's would; records every experiment it was given."""

    def __init__(self, truth: Relation, orders: tuple[Pair, ...]) -> None:
        self.truth, self.orders = TruthOracle(truth), orders
        self.ran: list[PrecedenceExperiment] = []

    def run(self, experiment: PrecedenceExperiment) -> PrecedenceOutcome:
        self.ran.append(experiment)
        parts = [step.part for step in experiment.sequence]
        outcome = self.truth.run(experiment)
        for step, part in enumerate(parts, 1):
            met = [q for p, q in self.orders if p == part and q in parts[:step - 1]]
            if met and (outcome.failed_step is None or step < outcome.failed_step):
                return PrecedenceOutcome(id=experiment.id, cell="hand", pair=experiment.pair, outcome="failed",
                                         failed_step=step, reason="blocked", blocked_by=(met[0],))
        return outcome


def _explored(evidence: Evidence, cell: Hand) -> Learned:
    for _, trial in explore(evidence, cell):
        evidence = evidence.with_trial(trial)
    return learn_sources(evidence)


PARTS = ("bp", "peg", "frame", "pin")
TRUTH = Relation.from_pairs(PARTS, [("bp", "peg"), ("bp", "frame"), ("bp", "pin")])
"""A base, a peg, a frame lying on the base around it and a pin: the product orders only
the base first; the cell's fingers need the peg in before the frame."""
DEMOS = Demonstrations(PARTS, (("bp", "peg", "frame", "pin"), ("bp", "pin", "peg", "frame")), ("d1", "d2"))


def test_a_pair_the_cell_orders_is_never_tried_against_it_and_left_undecidable() -> None:
    orders = (("peg", "frame"),)
    cell = Hand(TRUTH, orders)
    learned = _explored(Evidence(DEMOS, cell_before=orders), cell)
    assert cell.ran and not any(breaks([s.part for s in e.sequence], orders) for e in cell.ran)
    assert set(TRUTH.pairs()) <= set(learned.relation.pairs())  # sound: every true pair kept
    assert all(pair in TRUTH.pairs() for pair, support in learned.support.items() if support == "experiment")
    undecidable = dict(learned.cell_undecided)
    assert "frame went in without peg" in undecidable[("peg", "frame")]
    assert "never places peg after it (its own order peg<frame)" in undecidable[("peg", "frame")]
    assert learned.support[("peg", "frame")] == "demonstrated"  # kept as the demonstrations have it
    summary = learned.summary()
    assert "undecidable by this cell: peg<frame:" in summary
    assert "assumes: the cell's own orders (cell_order.lp: peg<frame) hold in every experiment" in summary
    # Without the orders the hand's failure (its fingers meeting the frame) is read as the product's
    cell = Hand(TRUTH, orders)
    blind = _explored(Evidence(DEMOS), cell)
    assert any(breaks([s.part for s in e.sequence], orders) for e in cell.ran)
    assert blind.support[("peg", "frame")] == "experiment" and ("peg", "frame") not in TRUTH.pairs()


def test_cranfield_with_the_orders_of_its_import_learns_its_exact_relation_keeping_them(root: Path) -> None:
    truth = true_relation(load_assembly("cranfield"))
    every = load_demos(root / "data/cranfield/demos.txt", truth.parts)
    demos = Demonstrations(every.parts, every.sequences[:2], every.origins[:2])
    cell = Hand(truth, CRANFIELD_ORDERS)
    learned = _explored(Evidence(demos, cell_before=CRANFIELD_ORDERS), cell)
    assert not [e.id for e in cell.ran if breaks([s.part for s in e.sequence], CRANFIELD_ORDERS)]
    assert learned.relation.same_as(truth) and not learned.cell_undecided  # each such pair fails without its first
    assert {learned.support[pair] for pair in CRANFIELD_ORDERS} == {"experiment"}
    # The product's free pair p2<p1 made an order of the cell: p1 goes in without p2, never p2 after it
    orders = (*CRANFIELD_ORDERS, ("p2", "p1"))
    cell = Hand(truth, orders)
    learned = _explored(Evidence(demos, cell_before=orders), cell)
    assert not [e.id for e in cell.ran if breaks([s.part for s in e.sequence], orders)]
    assert set(truth.pairs()) <= set(learned.relation.pairs())
    assert all(pair in truth.pairs() for pair, support in learned.support.items() if support == "experiment")
    undecidable = dict(learned.cell_undecided)
    assert "p1 went in without p2" in undecidable[("p2", "p1")]
    assert set(undecidable) - set(truth.pairs()) == {("p2", "p1")}  # the others hold, through it undecided
    assert ("p2", "p1") not in learned.process


@pytest.mark.parametrize("pair", [("peg", "frame"), ("pin", "peg")])
def test_a_failure_the_cells_order_explains_confirms_nothing(pair: Pair) -> None:
    """An experiment from a file that placed the peg after the frame, the peg then blocked by
    the frame: at its "B then A" step (testing peg<frame) or at its tested step (pin<peg,
    every other part in place). Its fingers meeting the frame explain it."""
    experiment = PrecedenceExperiment(id="f.1", pair=pair, sequence=tuple(map(ExperimentStep, ("bp", "frame", "peg"))))
    outcome = PrecedenceOutcome(id="f.1", cell="file", pair=pair, outcome="failed", failed_step=3, reason="blocked",
                                blocked_by=("frame",))
    trials = (Trial(experiment, outcome, "f.lp:1"),)
    demos = Demonstrations(PARTS, DEMOS.sequences[1:], DEMOS.origins[1:])  # the pin first, the peg, the frame
    assert pair in learn_sources(Evidence(demos, trials=trials)).knowledge.known  # read blind: the product's
    learned = learn_sources(Evidence(demos, trials=trials, cell_before=(("peg", "frame"),)))
    assert pair not in learned.knowledge.known and len(learned.undecided) == 1
    assert "the cell's own order explains it: the fingers holding peg meet frame in place" in learned.summary()


def test_an_order_of_an_unknown_part_is_bad_input(tmp_path: Path, root: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    product = tmp_path / "product"
    product.mkdir()
    for name in ("assembly.toml", "sizes.lp", "precedence.lp", "demos.txt"):
        shutil.copy(root / "data/cranfield" / name, product / name)
    (product / "cell_order.lp").write_text("cell_before(p1,fp).\ncell_before(p1,lid).\n")
    assert main(["precedence", "explore", "--assembly", str(product)]) == 2
    assert capsys.readouterr().err.strip() == (f"error: {product / 'cell_order.lp'}: cell_before(p1,lid): expected two "
                                               "parts of the assembly (bp p1 p2 p3 p4 sh sp pd ph fp)")
