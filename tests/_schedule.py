"""The order of the suite on pytest-xdist's workers: whole files, the longest first.

Each test file is one unit of work (as xdist's ``loadfile``), so a module- or session-scoped
fixture (a wheel installed, a product imported, a cell taught) is set up by one worker, not by
each. A file of :data:`BY_PARAMETER` is split by its tests' parameter instead (the tests of one
corpus product, which its module fixture imports once, on first use; a row of bad input), so
the parts of a long file run on both workers. The units are ordered by their expected time, the
longest first, so the long physics units start at once and the quick ones fill the end and the
two workers finish together (longest-processing-time-first scheduling). The expected time of a
test is its last measured time (setup, call and teardown) kept in pytest's cache under
``CACHE_KEY`` by every run with the cache on, else its time in :data:`EXPECTED` (the slowest
tests of a whole run, committed, for runs without the cache: CI's clean clone, ``-p
no:cacheprovider``), else a guess from its marker. The hooks are imported by
``tests/conftest.py``.
"""

from __future__ import annotations

import json
import re
from collections import defaultdict
from pathlib import Path
from typing import Any

import pytest

CACHE_KEY = "assembly-constraints/durations"
BY_PARAMETER = ("tests/cad/test_corpus.py", "tests/test_bad_input.py")
"""Files split by their tests' parameter: the tests of a corpus product (``[name]``) share its
import (the session fixture ``corpus_import`` of ``tests/cad/conftest.py``), the rows of ``test_bad_input.py``
(a process each, about 1.3 s of CPU) share nothing."""
EXPECTED = Path(__file__).with_name("durations.json")
"""Measured times [s] of the slowest tests, by node id (``python -m tests._schedule LOG``
writes it from the ``--durations`` lines of a whole run)."""
GUESS_SLOW_S = 10.0
"""Expected time [s] of a ``slow`` test never measured (the marker's bar is 2 s; the slow
tests of the suite take 2 s to a few minutes)."""
GUESS_QUICK_S = 0.1
"""Expected time [s] of any other test never measured."""


def _unit(nodeid: str) -> str:
    """A test's unit of work: its file, or in a file of :data:`BY_PARAMETER` its file and
    parameter id (a test without one: its own unit)."""
    path = nodeid.split("::", 1)[0]
    if path not in BY_PARAMETER:
        return path
    bracket = nodeid.find("[")
    return path + nodeid[bracket:] if bracket >= 0 else nodeid


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """Files (:func:`_unit`) as units of work, in the collection's order, where ``-n`` alone
    asks for xdist's default (``load``)."""
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class Units(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return _unit(nodeid)

    config.option.loadscopereorder = False  # xdist's default puts the units with the most tests first
    return Units(config, log)


def expected_times(config: pytest.Config) -> dict[str, float]:
    """The measured time [s] of each test measured: the committed ``EXPECTED``, updated by
    this checkout's cache."""
    cache = getattr(config, "cache", None)
    measured: dict[str, float] = json.loads(EXPECTED.read_text(encoding="utf-8")) if EXPECTED.is_file() else {}
    return {**measured, **(cache.get(CACHE_KEY, {}) if cache is not None else {})}


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Units by expected time, the longest first; the tests of a unit keep their order. Every
    worker sorts the same collection by the same times, so their collections stay equal."""
    measured = expected_times(config)
    expected: dict[str, float] = defaultdict(float)
    first: dict[str, int] = {}
    for index, item in enumerate(items):
        guess = GUESS_SLOW_S if item.get_closest_marker("slow") else GUESS_QUICK_S
        expected[_unit(item.nodeid)] += measured.get(item.nodeid, guess)
        first.setdefault(_unit(item.nodeid), index)
    items.sort(key=lambda item: (-expected[_unit(item.nodeid)], first[_unit(item.nodeid)]))


class _Durations:
    """Sums each test's phases as the reports arrive (on the controller under xdist) and
    merges them into the cache at the end of the run."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        self.seconds[report.nodeid] += report.duration

    def pytest_sessionfinish(self, session: pytest.Session) -> None:
        cache = session.config.cache
        if cache is not None and self.seconds:
            cache.set(CACHE_KEY, {**cache.get(CACHE_KEY, {}), **self.seconds})


def pytest_configure(config: pytest.Config) -> None:
    """Records the durations where the cache is on, in the process that sees every report
    (not in an xdist worker)."""
    if getattr(config, "cache", None) is not None and not hasattr(config, "workerinput"):
        config.pluginmanager.register(_Durations(), "assembly-constraints-durations")


def durations_from_log(text: str) -> dict[str, float]:
    """Each test's time [s] (its phases summed) from the ``--durations`` lines of a pytest
    run's output (``12.34s call     tests/x.py::test_y``)."""
    seconds: dict[str, float] = defaultdict(float)
    for line in text.splitlines():
        found = re.fullmatch(r"\s*(\d+(?:\.\d+)?)s (?:setup|call|teardown) +(\S.*?)\s*", line)
        if found:
            seconds[found[2]] += float(found[1])
    return {nodeid: round(value, 1) for nodeid, value in sorted(seconds.items())}


if __name__ == "__main__":
    import sys

    if len(sys.argv) != 2:
        sys.exit("usage: python -m tests._schedule LOG  (a whole run's output with --durations=N)")
    EXPECTED.write_text(json.dumps(durations_from_log(Path(sys.argv[1]).read_text(encoding="utf-8")), indent=0)
                        + "\n", encoding="utf-8")
