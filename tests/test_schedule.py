"""The order of the suite on xdist's workers (``tests/_schedule.py``): the units of work, the
committed durations read from a run's output, and xdist's real scheduler handing the units out
in the collection's order (longest first), not by how many tests they hold."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from tests._schedule import _unit, durations_from_log, pytest_xdist_make_scheduler

CORPUS = "tests/cad/test_corpus.py"


def test_a_unit_is_a_file_or_a_corpus_product() -> None:
    assert _unit("tests/sizes/test_x.py::test_a[p1-2]") == "tests/sizes/test_x.py"
    assert _unit(f"{CORPUS}::test_fits[occt_as1]") == _unit(f"{CORPUS}::test_bolts[occt_as1]") == f"{CORPUS}[occt_as1]"
    assert _unit(f"{CORPUS}::test_each_truth[occt_as1]") != _unit(f"{CORPUS}::test_each_truth[occt_pump]")
    assert _unit(f"{CORPUS}::test_alone") == f"{CORPUS}::test_alone"


def test_durations_sum_a_tests_phases_from_a_runs_output() -> None:
    log = """============================= slowest 5 durations =============================
84.47s call     tests/cad/test_covers.py::test_cranfield
5.64s setup    tests/cad/test_covers.py::test_cranfield
12.00s call     tests/test_bad_input.py::test_row[trial-a b]
1547 passed in 1088.31s (0:18:08)
"""
    assert durations_from_log(log) == {"tests/cad/test_covers.py::test_cranfield": 90.1,
                                       "tests/test_bad_input.py::test_row[trial-a b]": 12.0}


class _Node:
    """A worker as xdist's scheduler sees it: the indexes of the tests it is sent."""

    def __init__(self, name: str) -> None:
        self.gateway = SimpleNamespace(id=name)
        self.shutting_down = False
        self.sent: list[int] = []

    def send_runtest_some(self, indexes: list[int]) -> None:
        self.sent.extend(indexes)

    def shutdown(self) -> None:
        self.shutting_down = True


def test_xdist_hands_out_the_units_in_the_collections_order() -> None:
    # the collection as the hooks sorted it: the long physics file first, then one of many quick tests
    collection = ["tests/test_physics.py::test_long", *(f"tests/test_rows.py::test_row[{k}]" for k in range(5))]
    option = SimpleNamespace(dist="load", tx=["2*popen"], loadscopereorder=True)
    config: Any = SimpleNamespace(option=option, getvalue=lambda name: getattr(option, name))
    scheduler = pytest_xdist_make_scheduler(config, None)
    nodes = [_Node("gw0"), _Node("gw1")]
    for node in nodes:
        scheduler.add_node(node)
        scheduler.add_node_collection(node, collection)
    scheduler.schedule()
    assert nodes[0].sent[0] == 0  # xdist's default order would have started with the file of five tests
    assert sorted(nodes[1].sent) == [1, 2, 3, 4, 5]
