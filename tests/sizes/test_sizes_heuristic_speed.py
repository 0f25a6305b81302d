"""The heuristic's derived selection (no optimisation) against brute-force scoring in Python."""

from __future__ import annotations

import clingo
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from asp.sizes.knowledge import Knowledge, Pair
from asp.sizes.learner import SizeLearner
from asp.sizes.truth_oracle import TruthOracle
from asp.solve import encoding, fact, format_facts
from tests._sizes_helpers import biorders


def paper_choice(k: Knowledge) -> Pair:
    """The reading of select_heuristic.lp's header, scored pair by pair."""
    unknown = set(k.unknown)

    def key(pair: Pair) -> tuple[int, ...]:
        p, h = pair
        lower = sum((q, p) in k.smaller and (q, h) in unknown for q in k.parts)
        upper = sum((p, q) in k.smaller and (q, h) in unknown for q in k.parts)
        fit = {x for x in k.parts if (h, x) in k.smaller and (p, x) not in k.smaller}
        fit |= {x for x in k.holes if (x, p) in k.smaller and (x, h) not in k.smaller}
        no_fit = {x for x in k.parts if (x, h) in k.smaller and (x, p) not in k.smaller}
        no_fit |= {x for x in k.holes if (p, x) in k.smaller and (h, x) not in k.smaller}
        return (lower * upper, min(len(fit), len(no_fit)),
                sum((p, x) in unknown for x in k.holes), sum((x, h) in unknown for x in k.parts),
                -k.parts.index(p), -k.holes.index(h))

    return max(unknown, key=key)


@pytest.mark.slow
@settings(max_examples=40, deadline=None)
@given(biorders(max_parts=7, max_holes=7))
def test_every_choice_of_a_session_is_the_best_scored_pair(truth: TruthOracle) -> None:
    learner = SizeLearner(truth.parts, truth.holes, "heuristic")
    while (pair := learner.next_experiment()) is not None:
        assert pair == paper_choice(learner.knowledge)
        learner.record(*pair, truth.ask(*pair))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4), st.sampled_from(["fit", "no_fit"])),
                max_size=14))
@pytest.mark.slow
def test_noisy_observations_give_one_model_with_the_best_scored_pair(
        observations: list[tuple[int, int, str]]) -> None:
    parts, holes = [f"p{i}" for i in range(1, 6)], [f"h{j}" for j in range(1, 6)]
    atoms = [fact("part", p) for p in parts] + [fact("hole", h) for h in holes]
    atoms += [fact("part_index", p, i) for i, p in enumerate(parts, 1)]
    atoms += [fact("hole_index", h, j) for j, h in enumerate(holes, 1)]
    latest = {(parts[i], holes[j]): r for i, j, r in observations}
    atoms += [fact("observed", p, h, r) for (p, h), r in latest.items()]
    ctl = clingo.Control(["0", "--warn=none"])
    ctl.add("base", [], format_facts(atoms))
    for name in ("select_heuristic.lp",):
        ctl.load(str(encoding(name)))
    ctl.ground([("base", [])])
    models: list[list[clingo.Symbol]] = []
    ctl.solve(on_model=lambda m: models.append(m.symbols(shown=True)))
    assert len(models) == 1
    knowledge = Knowledge.from_symbols(parts, holes, models[0])
    selected = [(str(s.arguments[0]), str(s.arguments[1])) for s in models[0] if s.name == "select"]
    assert selected == ([paper_choice(knowledge)] if knowledge.unknown else [])


def test_the_heuristic_scores_products_of_more_than_thirty_one_ids() -> None:
    # 2**B for the gain bits would wrap at B = 31 and above: 16 parts and 16 holes reach it
    parts, holes = [f"p{i}" for i in range(1, 17)], [f"h{j}" for j in range(1, 17)]
    sizes = {name: (7 * k) % 17 for k, name in enumerate(parts + holes)}
    truth = TruthOracle(parts, holes, [(p, h) for p in parts for h in holes if sizes[p] < sizes[h]])
    learner = SizeLearner(parts, holes, "heuristic")
    for _ in range(4):
        pair = learner.next_experiment()
        assert pair is not None and pair == paper_choice(learner.knowledge)
        learner.record(*pair, truth.ask(*pair))
