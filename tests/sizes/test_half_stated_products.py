"""A product that states its cross-sections in part of its files: the one loader derives
each part's and hole's kind from every statement (``shape`` in ``assembly.toml``, the
kinds of ``geometry.toml``) and refuses statements that disagree; the size model puts a
part whose section no statement gives on no other part's line."""

from __future__ import annotations

from pathlib import Path

import pytest

from assembly_constraints.asp.sizes.learner import LearningOptions, SizeLearner, learn_sizes
from assembly_constraints.asp.sizes.models import build_model, model_for
from assembly_constraints.asp.sizes.truth_oracle import Result
from assembly_constraints.bridge import BridgeError
from assembly_constraints.bridge.assembly import load_assembly
from assembly_constraints.executor.world.geometry import load_geometry, passes
from tests.session.test_mixed_sections import HOLES, PEGS, _product


class _CrossSections:
    """Answers from the cross-sections of ``geometry.toml``, as the truth cells do."""

    def __init__(self, product: Path) -> None:
        geometry = load_geometry(str(product))
        self.fits = {(p, h) for p in PEGS for h in HOLES if passes(geometry.parts[p], geometry.holes[h])}

    def ask(self, part: str, hole: str) -> Result:
        return "fit" if (part, hole) in self.fits else "no_fit"


@pytest.mark.parametrize("policy", ["random", "heuristic"])
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("hole_shapes", [True, False])
def test_kinds_stated_only_in_geometry_give_exactly_the_true_fits(tmp_path: Path, policy: str, seed: int,
                                                                  hole_shapes: bool) -> None:
    """Round and square pegs, their kinds in geometry.toml only (the holes' there too, or
    also in assembly.toml): learned on one size line they would give fits that do not
    exist (a 13 mm square peg's diagonal is 18.4 mm)."""
    product = _product(tmp_path / "mixed", part_shapes=False, hole_shapes=hole_shapes)
    assembly = load_assembly(str(product))
    assert assembly.sections() == {"pa": "round", "pb": "square", "pc": "round", "pd": "square"}
    assert {hole.id: hole.shape for hole in assembly.holes} == {h: kind for h, (kind, _) in HOLES.items()}
    model = model_for(list(PEGS), None, assembly.size_model, assembly.sections())
    assert model.assumption() == "size model sections: one size line per cross-section (round: pa pc; square: pb pd)"
    truth = _CrossSections(product)
    result = learn_sizes(list(PEGS), list(HOLES), truth, policy, seed, options=LearningOptions(model=model))
    assert result.knowledge.fits == frozenset(truth.fits)


def test_a_part_of_unknown_section_shares_no_line() -> None:
    """``c`` states no cross-section: what ``a`` and ``b`` (round) show entails nothing about it."""
    model = build_model("sections", ["a", "b", "c"], {"a": "round", "b": "round"})
    assert model.sections["c"] not in ("round", model.sections["a"])
    assert model.assumption().endswith("(round: a b; no cross-section stated, each on its own line: c)")
    learner = SizeLearner(["a", "b", "c"], ["h1", "h2"], "systematic", options=LearningOptions(model=model))
    learner.record("c", "h1", "fit")
    learner.record("a", "h1", "no_fit")  # on one line: a is bigger than c
    learner.record("a", "h2", "fit")  # ... so c would fit h2
    learner.record("b", "h2", "no_fit")  # b is bigger than a: it fits no hole a does not
    knowledge = learner.knowledge
    assert ("c", "h2") not in knowledge.fits and ("c", "h2") not in knowledge.no_fit
    assert ("b", "h1") in knowledge.no_fit  # within the round line the closure still works
    own = build_model("sections", ["a", "c"], {"a": "of_c"})  # a stated label never merges with an own line
    assert own.sections["c"] != own.sections["a"] == "of_c"


def test_statements_that_disagree_are_refused_naming_both_files(tmp_path: Path) -> None:
    product = _product(tmp_path / "mixed", part_shapes=False, hole_shapes=False)
    text = (product / "assembly.toml").read_text()
    (product / "assembly.toml").write_text(text.replace('role = "peg"\n', 'role = "peg"\nshape = "round"\n'))
    with pytest.raises(BridgeError) as refused:
        load_assembly(str(product))
    message = str(refused.value)
    assert message == (f"{product / 'assembly.toml'}: part 'pb' has shape \"round\" but geometry.toml gives it "
                       "kind \"square\"")


def test_a_section_label_needs_a_rect_from_some_statement(tmp_path: Path) -> None:
    """``section`` is a rect's: accepted when geometry.toml makes the part a rect, refused
    (one line) when no statement does."""
    product = _product(tmp_path / "mixed", part_shapes=False, hole_shapes=False)
    text = (product / "assembly.toml").read_text()
    (product / "assembly.toml").write_text(text.replace('name = "square peg pb"', 'name = "square peg pb"\n'
                                                        'section = "big"'))
    with pytest.raises(BridgeError, match=r"\[parts.pb\] section: only a part of shape \"rect\" has one \(a square"):
        load_assembly(str(product))
    geometry = (product / "geometry.toml").read_text()
    table = '[part_shapes.pb]\nparts = ["pb"]\nkind = "square"\nsize = 0.013\n'
    assert table in geometry
    (product / "geometry.toml").write_text(geometry.replace(table, table.replace('"square"', '"rect"').replace(
        "0.013", "[0.013, 0.006]")))
    assert load_assembly(str(product)).sections()["pb"] == "big"
    (product / "geometry.toml").unlink()
    with pytest.raises(BridgeError, match=r"\(a part without a shape is its own section\)"):
        load_assembly(str(product))
