"""``bench engines``: the same pairs inserted in PyBullet and in franky-sim's MuJoCo scene."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("mujoco")


@pytest.mark.slow
def test_bench_engines_inserts_where_the_part_fits_and_stops_where_not_in_both(run_main) -> None:
    done = run_main("bench", "engines", "--assembly", "spare", "--pair", "p3:r1", "--pair", "p3:s1", "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    rows = {(row["part"], row["hole"]): row for row in report["rows"]}
    assert rows.keys() == {("p3", "r1"), ("p3", "s1")}
    for engine in ("pybullet", "mujoco"):
        # The square peg (12 mm) goes 12 mm down the square hole (13.3 mm) and stops on force
        # at the round one's entry (13.3 mm: its diagonal is 17 mm).
        assert rows["p3", "s1"][engine]["fits"] and rows["p3", "s1"][engine]["depth"] > 0.010
        assert not rows["p3", "r1"][engine]["fits"] and rows["p3", "r1"][engine]["depth"] < 0.002
        assert rows["p3", "r1"][engine]["force"] > 10.0
    assert report["engines_differ"] == [] and report["differ_from_geometry"] == {"pybullet": [], "mujoco": []}
    rates = report["steps_per_s"]
    assert all(rates[engine][clock] > 0 for engine in ("pybullet", "mujoco") for clock in ("wall", "cpu"))


@pytest.mark.slow
def test_bench_engines_refuses_an_unknown_pair(run_main) -> None:
    done = run_main("bench", "engines", "--assembly", "spare", "--pair", "p3:zz")
    assert done.returncode == 2 and "--pair p3:zz: expected a part of" in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.slow
def test_mujoco_stops_a_peg_on_an_interference_under_a_millimetre() -> None:
    """An 8 mm round peg on a 8.3 x 7.3 mm slot (0.35 mm too wide on each side) stops at the
    entry; an 8 x 7 mm rect peg goes in (MuJoCo's default contacts let the round one through)."""
    from executor.campaign.engines import FIT_DEPTH, mujoco_insertion
    from executor.world.geometry import load_geometry

    geometry = load_geometry("taskboard")
    slot = geometry.holes["slot8"]
    stopped = mujoco_insertion(geometry, geometry.parts["round8"], slot)
    assert not stopped.fits and stopped.depth < 0.002 and stopped.force > 10.0
    assert mujoco_insertion(geometry, geometry.parts["rect8"], slot).depth > FIT_DEPTH


@pytest.mark.slow
def test_pybullet_stops_a_part_on_a_tenth_of_a_millimetre_of_interference() -> None:
    """A d 11 mm peg on a d 10.8 mm hole and a 5 g 4 mm square peg (diagonal 5.66 mm) on a
    4.3 mm round hole stop on force near the entry: the stop reads the friction that holds a
    part squeezed into the wall, and the solver's iterations keep the drive from pushing a
    light part through (docs/results/franka.md); the d 11 peg goes down its own hole."""
    from executor.campaign.engines import FIT_DEPTH, pybullet_insertion
    from executor.world.geometry import load_geometry

    for assembly, part, hole in (("graded", "p2", "h1"), ("taskboard", "rect4", "hole4")):
        geometry = load_geometry(assembly)
        stopped = pybullet_insertion(geometry, geometry.parts[part], geometry.holes[hole])
        assert not stopped.fits and stopped.depth < 0.002 and stopped.force > 10.0, (part, hole, stopped)
    graded = load_geometry("graded")
    assert pybullet_insertion(graded, graded.parts["p2"], graded.holes["h2"]).depth > FIT_DEPTH
