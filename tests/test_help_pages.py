"""One command line: every subcommand's help page follows the same conventions.

The test walks the parser tree from ``assembly-constraints`` down (every subcommand and
nested subcommand, as each module builds its parser) and checks on each page: the program
name, help text on every option, choices shown, no documentation markup or internal
module names, one meaning of ``--assembly``, list options that reject malformed lists;
and that a missing subcommand exits 2.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from assembly_constraints.cli import main
from bridge.assembly import DATA_DIR
from bridge.cli_types import ASSEMBLY_HELP, PROGRAM
from tests.conftest import child_env

MARKUP = re.compile(r"``|`|\*\*|:mod:|:class:|:func:|\.\/run\.sh|\b(?:asp|executor|bridge)\.[a-z_]+\b|\w+\.py\b"
                    r"|\b[A-Z][a-z][A-Za-z]*\.[a-z_]{2,}\b")
"""Documentation markup (literals, roles, strong emphasis), the wrapper's name, and module
or method names a user never types (a ``MODULE:CLASS`` example such as
``executor.replay:ReplayBackend`` is allowed below)."""
OTHER_PROGRAMS = re.compile(r"run\.sh|\bpython3? -m\b|\bassembly_constraints\b")
"""Names of the program other than ``assembly-constraints``: the repository's wrapper, the
module run by Python, the package name."""
ALLOWED = ("executor.replay:ReplayBackend",)


class _Captured(Exception):
    def __init__(self, parser: argparse.ArgumentParser) -> None:
        self.parser = parser


def capture(path: list[str], monkeypatch: pytest.MonkeyPatch) -> argparse.ArgumentParser:
    """The parser ``assembly-constraints PATH`` builds (caught as it starts parsing)."""
    prog = " ".join([PROGRAM, *path])
    original = argparse.ArgumentParser.parse_known_args

    def parse_known_args(self, args=None, namespace=None):  # noqa: ANN001, ANN202
        if self.prog == prog:
            raise _Captured(self)
        return original(self, args, namespace)

    with monkeypatch.context() as patch:
        patch.setattr(argparse.ArgumentParser, "parse_known_args", parse_known_args)
        try:
            main(path)
        except _Captured as captured:
            return captured.parser
    raise AssertionError(f"{prog}: no parser with this program name was used")


def subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    return {name: sub for action in parser._actions if isinstance(action, argparse._SubParsersAction)
            for name, sub in action.choices.items()}


def walk(monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[list[str], argparse.ArgumentParser]]:
    """(path, parser) of every help page, top first."""
    pending: list[list[str]] = [[]]
    while pending:
        path = pending.pop(0)
        parser = capture(path, monkeypatch)
        yield path, parser
        if any(action.nargs == argparse.REMAINDER for action in parser._actions):  # delegates the rest
            pending += [[*path, name] for action in parser._actions if not action.option_strings
                        for name in action.choices or ()]
        for name, sub in subparsers(parser).items():
            if sub.add_help:
                yield [*path, name], sub
            else:  # a placeholder: the module it names builds the real parser
                pending.append([*path, name])


@pytest.fixture(scope="module")
def pages() -> list[tuple[list[str], argparse.ArgumentParser]]:
    with pytest.MonkeyPatch.context() as monkeypatch:
        return list(walk(monkeypatch))


def test_the_walk_reaches_every_subcommand(pages) -> None:
    names = {" ".join(path) for path, _ in pages}
    assert {"", "session", "precedence learn", "executor serve", "executor campaign", "bench executor",
            "bench dominance", "protocol", "view", "sizes evaluate", "plan"} <= names


def test_every_page_names_the_program(pages) -> None:
    for path, parser in pages:
        assert parser.prog == " ".join([PROGRAM, *path])
        assert parser.format_usage().startswith(f"usage: {PROGRAM}")


def _options(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    return [a for a in parser._actions
            if not isinstance(a, (argparse._HelpAction, argparse._VersionAction, argparse._SubParsersAction))]


def test_every_option_has_help_and_shows_its_choices(pages) -> None:
    missing, hidden = [], []
    for path, parser in pages:
        for action in _options(parser):
            where = f"{' '.join(path)} {'/'.join(action.option_strings) or action.dest}"
            if not action.help or action.help == argparse.SUPPRESS:
                missing.append(where)
            elif action.choices is not None and action.metavar is not None and not all(
                    str(choice) in f"{action.metavar} {action.help}" for choice in action.choices):
                hidden.append(where)
    assert missing == [] and hidden == []


def test_no_markup_or_internal_words_on_any_page(pages) -> None:
    found = []
    for path, parser in pages:
        texts = [parser.description or "", parser.epilog or ""] + [a.help or "" for a in parser._actions]
        texts += [choice.help or "" for action in parser._actions if isinstance(action, argparse._SubParsersAction)
                  for choice in action._choices_actions]  # the one-line help of each subcommand
        for text in texts:
            for allowed in ALLOWED:
                text = text.replace(allowed, "")
            found += [f"{' '.join(path)}: {match.group()!r} in {text[:60]!r}" for match in MARKUP.finditer(text)]
    assert found == []


def test_every_page_as_printed_names_one_program_in_plain_text(pages) -> None:
    """The whole page as ``--help`` prints it (usage, description, option groups, options,
    epilog): every usage line names the program, no other name of it, no markup."""
    found = []
    for path, parser in pages:
        text = parser.format_help()
        for allowed in ALLOWED:
            text = text.replace(allowed, "")
        where = " ".join([PROGRAM, *path])
        found += [f"{where}: usage names {name!r}" for name in re.findall(r"usage: (\S+)", text) if name != PROGRAM]
        found += [f"{where}: {match.group()!r}" for pattern in (MARKUP, OTHER_PROGRAMS)
                  for match in pattern.finditer(text)]
    assert found == []


def test_assembly_has_one_meaning_everywhere(pages) -> None:
    helps = {" ".join(path): action.help for path, parser in pages for action in parser._actions
             if "--assembly" in action.option_strings}
    assert len(helps) >= 10
    assert {path: text for path, text in helps.items() if not (text or "").startswith(ASSEMBLY_HELP)} == {}
    shipped = {folder.name for folder in DATA_DIR.iterdir() if (folder / "assembly.toml").is_file()}
    assert shipped and {name for name in shipped if name not in ASSEMBLY_HELP} == set()  # every one named


def test_list_options_reject_malformed_lists(pages) -> None:
    lists = [(path, action) for path, parser in pages for action in _options(parser)
             if action.metavar and "," in str(action.metavar) and not str(action.metavar).startswith("{")]
    assert len(lists) >= 5
    for path, action in lists:
        assert callable(action.type), f"{' '.join(path)} {action.option_strings}: not parsed as a list"
        with pytest.raises(argparse.ArgumentTypeError):
            action.type("1,,2")


def test_a_missing_subcommand_exits_2(pages, capsys: pytest.CaptureFixture[str]) -> None:
    paths = [path for path, parser in pages
             if subparsers(parser) or any(action.nargs == argparse.REMAINDER for action in parser._actions)]
    assert len(paths) >= 5
    for path in paths:
        try:
            code = main(path)
        except SystemExit as exc:
            code = exc.code
        assert code == 2, f"{PROGRAM} {' '.join(path)} exited {code}"
        assert capsys.readouterr().err.startswith("error: ")


@pytest.mark.slow
def test_verbose_and_quiet_set_the_log_level(tmp_path: Path) -> None:
    """The default shows progress and hints as plain lines (here the hint of precedence
    suggest) and warnings (here a demonstration that alone removes constraints); -q hides
    both; -v shows as much as the default and more."""
    demos = tmp_path / "demos.txt"
    demos.write_text("a b c\na b c\na b c\nb a c\n")

    def stderr(*args: str) -> str:
        done = subprocess.run([sys.executable, "-m", "assembly_constraints", *args], cwd=tmp_path, env=child_env(),
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        return done.stderr

    hint = stderr("precedence", "suggest", str(demos))
    assert "still undecided" in hint and not hint.startswith("info")
    assert stderr("-v", "precedence", "suggest", str(demos)) == hint
    assert stderr("-q", "precedence", "suggest", str(demos)) == ""
    assert "warning: " in stderr("precedence", "learn", str(demos))
    assert stderr("-q", "precedence", "learn", str(demos)) == ""
