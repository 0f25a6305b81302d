"""The reference docs against the checkout: every repository path they (and the data
files' comments) name and every relative link exists (a link's ``#anchor`` too), and they
describe the present, not how it came about (no dated history, no process words; history
is ``CHANGELOG.md``'s)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.conftest import ROOT

TOP_FOLDERS = ("asp", "executor", "bridge", "data", "tests", "docs", "examples", "assembly_constraints")
TOP_FILES = ("run.sh", "setup.py", "pyproject.toml", "constraints.txt", "CHANGELOG.md", "LICENSE", "README.md")

# A repository path in prose or code spans: a top-level folder and what follows it, not part of
# a longer path or an entity path (``/executor/c1/...``), nor a placeholder (``data/<name>``).
FOLDERS = "|".join(TOP_FOLDERS)
REPO_PATH = re.compile(rf"(?<![\w/.$<{{-])(?<!\]\()((?:{FOLDERS})/[\w./-]*)")
WRITTEN_BY_EXAMPLES = {"data/myproduct"}  # ``import --out data/myproduct``: the docs' examples create it
LINK = re.compile(r"\]\(([^)\s]+)\)")
HEADING = re.compile(r"^(#+)\s+(.*?)\s*$", re.MULTILINE)

# What the docs must not say (the bracket keeps this file's own text and bytecode from matching).
HISTORY = re.compile(rb"ag[e]nt|session [0-9]|issue [0-9]|until [0-9]+ [A-Z][a-z]+ 20", re.IGNORECASE)


def pages() -> list[Path]:
    """The Markdown the project ships: the README, the changelog, ``docs/`` and the data folders' READMEs."""
    return sorted([ROOT / "README.md", ROOT / "CHANGELOG.md", *ROOT.glob("docs/**/*.md"), *ROOT.glob("data/*/*.md")])


def described_files() -> list[Path]:
    """The pages and the data files whose comments name repository paths (``geometry.toml``
    names the code that reads it)."""
    data = [f for suffix in ("toml", "lp", "txt") for f in ROOT.glob(f"data/*/*.{suffix}")]
    return sorted([*pages(), *data])


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"[`*_]", "", heading).strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    return {anchor(match.group(2)) for match in HEADING.finditer(page.read_text(encoding="utf-8"))}


def named_paths(text: str) -> set[str]:
    """The repository paths a page names, trailing punctuation dropped (``data/cranfield.`` ends a sentence)."""
    return {match.group(1).rstrip(".-") for match in REPO_PATH.finditer(text)}


def test_the_path_pattern_finds_paths_and_skips_entity_paths_and_placeholders() -> None:
    text = ("see `executor/cad/` and docs/results.md. Not `/executor/c1/arm` nor data/<name>/ nor $RUN/c1.rrd "
            "nor a link's relative [target](examples/cell.toml)")
    assert named_paths(text) == {"executor/cad/", "docs/results.md", "data/"}


@pytest.mark.parametrize("page", described_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_repository_path_a_page_names_exists(page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    missing = sorted(p for p in named_paths(text) if not (ROOT / p).exists()
                     and not any(p.startswith(made) for made in WRITTEN_BY_EXAMPLES))
    assert not missing, f"{page.relative_to(ROOT)} names paths that do not exist: {missing}"


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_and_its_anchor_exists(page: Path) -> None:
    broken = []
    for target in LINK.findall(page.read_text(encoding="utf-8")):
        if re.match(r"[a-z]+:", target):  # https:, mailto:
            continue
        path, _, fragment = target.partition("#")
        linked = (page.parent / path).resolve() if path else page
        if not linked.exists():
            broken.append(target)
        elif fragment and linked.suffix == ".md" and fragment not in anchors(linked):
            broken.append(target)
    assert not broken, f"{page.relative_to(ROOT)} links to what does not exist: {broken}"


def test_the_top_level_files_the_docs_name_exist() -> None:
    assert all((ROOT / name).is_file() for name in TOP_FILES)


def test_docs_readme_and_tests_state_the_present() -> None:
    """No dated history (a sentence that starts "until" and a date), no issue or session numbers, no process words."""
    files = [ROOT / "README.md", *(ROOT / "docs").rglob("*"), *(ROOT / "tests").rglob("*")]
    found = [f"{path.relative_to(ROOT)}: {match.group().decode(errors='replace')!r}"
             for path in files if path.is_file() and "__pycache__" not in path.parts
             for match in HISTORY.finditer(path.read_bytes())]
    assert not found, found
