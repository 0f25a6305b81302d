"""Named cases of ``select_best.lp`` with expected answer sets (both program parts)."""

from __future__ import annotations

import clingo
import pytest

from tests._best_reference import ENCODING as ENCODING_FILE

ENCODING = ENCODING_FILE.read_text(encoding="utf-8")


def answer_sets(part: str, facts: str) -> list[set[str]]:
    """Shown atoms of every answer set of ``facts`` + the encoding, grounding only ``part``."""
    ctl = clingo.Control(["--models=0", "--warn=none"])
    ctl.add(part, [], facts)
    ctl.add("base", [], ENCODING)
    ctl.ground([(part, [])])
    models: list[set[str]] = []
    ctl.solve(on_model=lambda m: models.append({str(s) for s in m.symbols(shown=True)}))
    return models


PARTS_2X2 = "part(a;b). hole(x;y). "


@pytest.mark.parametrize(
    "name,facts,count",
    [
        ("2x2 nothing known: all 14 biorders", PARTS_2X2 + "unknown((a;b),(x;y)).", 14),
        ("2x2 a fits x: 8 relations, 7 without the crossing",
         PARTS_2X2 + "fits(a,x). unknown(a,y). unknown(b,(x;y)).", 7),
        ("crossing fits is not a biorder: unsat",
         PARTS_2X2 + "fits(a,x). no_fit(a,y). fits(b,y). no_fit(b,x).", 0),
        ("everything known: one relation", PARTS_2X2 + "fits(a,(x;y)). no_fit(b,(x;y)).", 1),
    ],
)
def test_base_enumerates_the_possible_relations(name: str, facts: str, count: int) -> None:
    assert len(answer_sets("base", facts)) == count, name


def test_base_names_one_representative_per_class() -> None:
    models = answer_sets("base", PARTS_2X2 + "fits((a;b),(x;y)).")
    assert models == [{"rel(a,x)", "rel(a,y)", "rel(b,x)", "rel(b,y)", "row_class(a,2)", "col_class(x,2)"}]


ONE_PART = ("unknown(a,(x;y)). part_index(a,1). hole_index(x,1). hole_index(y,2). "
            "holds(1,a,x). holds(2,a,x). holds(2,a,y). ")


@pytest.mark.parametrize(
    "name,weights,selected",
    [
        ("(a,y) splits 2:2, (a,x) 3:1", "weight(0,1). weight(1,1). weight(2,2).", {"select(a,y)"}),
        ("(a,x) splits 3:2, (a,y) 1:4", "weight(0,2). weight(1,2). weight(2,1).", {"select(a,x)"}),
        ("tie 1:2 both: lowest hole index", "weight(0,1). weight(1,1). weight(2,1).", {"select(a,x)"}),
    ],
)
def test_split_selects_the_most_even_pair(name: str, weights: str, selected: set[str]) -> None:
    assert answer_sets("split", ONE_PART + weights) == [selected], name


def test_split_selects_nothing_when_all_is_known() -> None:
    assert answer_sets("split", "part_index(a,1). hole_index(x,1). holds(0,a,x). weight(0,1).") == [set()]
