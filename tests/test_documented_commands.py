"""Every ``./run.sh ...`` command that README.md and docs/*.md show (in their code blocks)
is run by a test on a small input: either a test elsewhere in the suite runs that
subcommand (found by reading the tests' source), or :data:`SMOKE` here runs it through to
its output. A documented command that is neither, or that names no subcommand of the tool,
fails :func:`test_every_documented_command_is_run_by_a_test`, so the docs and the tests
cannot drift apart unseen."""

from __future__ import annotations

import functools
import json
import re
from pathlib import Path
from typing import Any

import pytest

from assembly_constraints.cli import BENCHMARKS, SUBCOMMANDS, main
from tests.conftest import ROOT

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
_WORD = re.compile(r"[a-z][a-z-]*$")  # a subcommand's word; the first other word ends the key

RUN_SH_OWN = {
    ("test",): "run.sh's own: the suite itself (this test is part of it)",
    ("lint",): "run.sh's own: ruff and mypy, run by ./run.sh test before pytest",
}
"""Documented commands of ``run.sh`` itself rather than of the tool, and why no test runs them."""

ALIASES: dict[tuple[str, ...], tuple[tuple[str, ...], str]] = {(): (("session",), "--assemble")}
"""``./run.sh`` alone is ``session --assemble`` (run.sh's main job): the words and an option
the test must also give."""


def documented_commands() -> dict[tuple[str, ...], list[str]]:
    """The subcommand words of every ``./run.sh`` line in a code block of the docs →
    where each is shown (``docs/x.md:12``)."""
    commands: dict[tuple[str, ...], list[str]] = {}
    for path in DOCS:
        in_block = False
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if line.lstrip().startswith("```"):
                in_block = not in_block
            elif in_block and line.lstrip().startswith("./run.sh"):
                key: list[str] = []
                for word in line.split("#")[0].split()[1:]:
                    if not _WORD.match(word):
                        break
                    key.append(word)
                commands.setdefault(tuple(key), []).append(f"{path.relative_to(ROOT)}:{number}")
    return commands


_DEFINITION = re.compile(r"^(?=(?:    )?(?:@|def |class ))", re.M)  # where a top-level or class member starts
_TEST = re.compile(r"(?:    )?def test")


@functools.cache
def _test_modules() -> list[tuple[str, list[str]]]:
    """(source, the sources of its test functions) of every other test module (a function's
    source runs from its ``def`` to the next top-level or class member: its decorators are
    not part of it)."""
    found = []
    for path in sorted((ROOT / "tests").rglob("test_*.py")):
        if path == Path(__file__):
            continue  # this module's commands are SMOKE's (its own checks name made-up ones)
        source = path.read_text()
        functions = [chunk for chunk in _DEFINITION.split(source) if _TEST.match(chunk)]
        found.append((source, functions))
    return found


def _module(key: tuple[str, ...]) -> str | None:
    """The module of a one-word subcommand or of a benchmark (the registry's), else None."""
    if key[:1] == ("bench",) and len(key) == 2:
        return BENCHMARKS.get(key[1])
    return SUBCOMMANDS[key[0]][0].partition(":")[0] if len(key) == 1 and key[0] in SUBCOMMANDS else None


def runs(source: str, key: tuple[str, ...]) -> bool:
    """Whether a test function (its ``source``) runs the command ``key``: its words in order
    as string literals (``run_cli("bench", "executor", ...)``, ``main(["precedence", "learn",
    ...])``), or the fixtures that add them (``run_executor``, ``run_session``)."""
    quote = r"[\"']"
    if re.search(quote + (quote + r"\s*,\s*" + quote).join(map(re.escape, key)) + quote, source):
        return True
    if key[0] == "executor" and len(key) == 2 and re.search(rf"run_executor\(\s*{quote}{key[1]}{quote}", source):
        return True
    return key == ("session",) and re.search(r"\brun_session\(|\bTRUTH_SESSION\b", source) is not None


def imports(module_source: str, key: tuple[str, ...]) -> bool:
    """Whether a test module imports the module of the benchmark or one-word subcommand ``key``."""
    module = _module(key)
    return module is not None and re.search(rf"^from {re.escape(module)} import", module_source, re.M) is not None


def _run_by_a_test(words: tuple[str, ...], option: str) -> bool:
    """Whether :data:`SMOKE` or a test function runs ``words`` (with ``option``), or, without
    an option, a test module imports its module."""
    if any(argv[:len(words)] == words and option in ("", *argv) for argv in _smoke_argvs()):
        return True
    return any((not option and imports(module, words))
               or (runs(module, words)  # the module first: most do not name the command at all
                   and any(runs(source, words) and (not option or f'"{option}"' in source) for source in functions))
               for module, functions in _test_modules())


def test_every_documented_command_is_run_by_a_test() -> None:
    unknown, unrun = [], []
    for key, shown in documented_commands().items():
        if key in RUN_SH_OWN:
            continue
        words, option = ALIASES.get(key, (key, ""))
        if words[0] not in SUBCOMMANDS or (words[0] == "bench" and words[1:2] and words[1] not in BENCHMARKS):
            unknown.append(f"./run.sh {' '.join(key)} ({shown[0]})")
        elif not _run_by_a_test(words, option):
            unrun.append(f"./run.sh {' '.join((*words, option)).strip()} ({', '.join(shown[:3])})")
    assert not unknown, f"documented commands the tool does not have: {unknown}"
    assert not unrun, f"documented commands no test runs (add one to SMOKE or a test of their own): {unrun}"


def test_the_scan_finds_a_command_only_where_a_test_runs_it() -> None:
    """The reader of the tests: the words must be in order and adjacent."""
    assert runs('run_cli("bench", "sizes", "--json")', ("bench", "sizes"))
    assert not runs('run_cli("bench", "plan", "sizes")', ("bench", "sizes"))
    assert not runs('run_cli("sizes", "learn")', ("bench", "sizes"))
    assert runs('run_executor("trial", "--part")', ("executor", "trial"))
    assert imports("from asp.bench.mesh import one_run\n", ("bench", "mesh"))
    assert not imports("from asp.bench.mesh import one_run\n", ("bench", "session"))
    assert _run_by_a_test(("precedence", "enumerate"), "") and not _run_by_a_test(("precedence", "nosuch"), "")
    assert documented_commands()[("precedence", "enumerate")]  # the docs' code blocks are read


SMOKE: list[Any] = [
    (("precedence", "enumerate", "--assembly", "cranfield", "--limit", "2"), "bp p1 p2 p3 p4 sh sp ph pd fp"),
    (("bench", "sizes", "--sizes", "3", "--policies", "random", "--decisions", "3", "--evaluate", "", "--json"),
     "json:decisions"),
    (("bench", "dominance", "--sizes", "2x2", "--time-limit", "5"), "biorders"),
    pytest.param(("bench", "precedence", "--repeat", "1", "--guided-trials", "1"), "guided demonstration",
                 marks=pytest.mark.slow),
    pytest.param(("bench", "plan", "--repeat", "1", "--parts", "4", "--holes", "3", "--products", "1",
                  "--time-limit", "10"), "optimal plans", marks=pytest.mark.slow),
    # a bound the wall time keeps on a loaded machine: the exit code is the target's verdict
    pytest.param(("bench", "import", "--product", "plate", "--parts", "6", "--repeat", "1", "--target", "600"),
                 "geometric precedence: median",
                 marks=pytest.mark.slow),
    pytest.param(("bench", "session", "--round-trips", "5", "--repeat", "1", "--skip-sessions", "--json"),
                 "json:overhead", marks=pytest.mark.slow),
    pytest.param(("executor", "margins", "--trials", "1", "--pairs", "p1:r1"), "p1:r1", marks=pytest.mark.slow),
]
"""Documented commands no other test runs, each on a small input, with what its output
must hold (``json:KEY``: the output is JSON with that key); a ``pytest.param`` when slow."""


def _smoke_argvs() -> list[tuple[str, ...]]:
    return [entry.values[0] if hasattr(entry, "values") else entry[0] for entry in SMOKE]


@pytest.mark.parametrize(("argv", "expected"), SMOKE)
def test_a_documented_command_runs_through_to_its_output(argv: tuple[str, ...], expected: str,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    assert main(list(argv)) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    if expected.startswith("json:"):
        assert expected[5:] in json.loads(out), out
    else:
        assert expected in out, out
