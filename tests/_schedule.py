"""The order of the suite on pytest-xdist's workers: whole files, the longest first.

Each test file is one unit of work (xdist's ``loadfile``), so a module- or session-scoped
fixture (a wheel installed, a product imported, a cell taught) is set up by one worker, not by
each. The files are ordered by their expected time, the longest first, so the long physics
files start at once and the quick files fill the end and the two workers finish together
(longest-processing-time-first scheduling). The expected time of a test is its last measured
time (setup, call and teardown, kept in pytest's cache under ``CACHE_KEY`` by every run with
the cache on), else a guess from its marker. The hooks are imported by ``tests/conftest.py``.
"""

from __future__ import annotations

from collections import defaultdict
from typing import Any

import pytest

CACHE_KEY = "assembly-constraints/durations"
GUESS_SLOW_S = 10.0
"""Expected time [s] of a ``slow`` test never measured (the marker's bar is 2 s; the slow
tests of the suite take 2 s to a few minutes)."""
GUESS_QUICK_S = 0.1
"""Expected time [s] of any other test never measured."""


def _file(nodeid: str) -> str:
    return nodeid.split("::", 1)[0]


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """Whole files as units of work, where ``-n`` alone asks for xdist's default (``load``)."""
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadFileScheduling
    return LoadFileScheduling(config, log)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Files by expected time, the longest first; the tests of a file keep their order. Every
    worker sorts the same collection by the same cache, so their collections stay equal."""
    cache = getattr(config, "cache", None)
    measured: dict[str, float] = cache.get(CACHE_KEY, {}) if cache is not None else {}
    expected: dict[str, float] = defaultdict(float)
    for item in items:
        guess = GUESS_SLOW_S if item.get_closest_marker("slow") else GUESS_QUICK_S
        expected[_file(item.nodeid)] += measured.get(item.nodeid, guess)
    first: dict[str, int] = {}
    for index, item in enumerate(items):
        first.setdefault(_file(item.nodeid), index)
    items.sort(key=lambda item: (-expected[_file(item.nodeid)], first[_file(item.nodeid)]))


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
