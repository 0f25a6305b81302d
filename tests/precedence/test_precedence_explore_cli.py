"""``precedence explore``, ``precedence learn --experiments`` and ``bench precedence-explore``
on the battery example (5 parts), through the command line."""

from __future__ import annotations

from pathlib import Path

import pytest

from asp.precedence.relation import load_relation, true_relation
from asp.solve import load_atoms
from bridge.assembly import load_assembly


@pytest.mark.slow
def test_explore_writes_experiments_that_learn_reads_back_a_conflict_exits_2(tmp_path: Path, root: Path,
                                                                           run_main) -> None:
    experiments, out = tmp_path / "experiments.lp", tmp_path / "learned.lp"
    done = run_main("precedence", "explore", "--assembly", "battery", "--experiments", str(experiments),
                   "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert set(load_relation([out]).pairs()) == set(true_relation(load_assembly("battery")).pairs())
    supports = {str(a) for a in load_atoms([out]) if a.name == "support"}
    assert supports and all(s.endswith(",experiment)") for s in supports)
    again = run_main("precedence", "learn", "--assembly", "battery", "--experiments", str(experiments))
    assert again.returncode == 0, again.stderr
    assert again.stdout.splitlines()[0] == next(line for line in done.stdout.splitlines()
                                                if line.startswith("learned "))
    assert "admitted: 6" in again.stdout  # the battery's relation admits 6 sequences
    # a demonstration against the prior: one line naming both, exit 2
    prior = tmp_path / "geometric_precedence.lp"
    prior.write_text("part(o). part(r1). part(r2). part(i1). part(i2).\nmust_precede(i1,i2).\n% i1->i2: blocks\n")
    done = run_main("precedence", "learn", "--assembly", "battery", "--experiments", str(experiments),
                   "--prior", str(prior))
    assert done.returncode == 2
    assert done.stderr.strip() == (f"error: conflict on i1<i2: demonstration {root}/data/battery/demos.txt:2 places i2 "
                                   f"before i1, but i1 must precede i2: i1<i2 by {prior} (blocks)")


@pytest.mark.slow
def test_bench_on_a_small_product_reaches_the_relation_with_no_wrong_pair(run_main) -> None:
    done = run_main("bench", "precedence-explore", "--assembly", "battery", "--seeds", "3", "--bound-seconds", "1",
                   "--demo-trials", "20", timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("exact 3/3, wrong pairs 0") == 2  # both policies
    assert "information bound at the start" in done.stdout and "demonstrations alone" in done.stdout
    assert "; exact); informative experiments minus the bound per seed: median" in done.stdout  # counted, not cut short
