"""The architecture, checked on the source: the planner (``asp``) and the cell (``executor``)
meet only through ``bridge``, no module imports itself back through others, and every
import of the product names a file of the checkout (the folders are the packages, no link).

Imports are read with :mod:`ast`, every one of them: module level, inside functions and
under ``TYPE_CHECKING`` alike, so a lazy import cannot hide a crossing or a cycle.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import networkx as nx

from tests.conftest import ROOT

PACKAGES = ("asp", "executor", "bridge", "assembly_constraints")
"""The repository's folders that are the product's packages, imported by these names."""
FRONT = "assembly_constraints"
FORBIDDEN = {"asp": {"executor", FRONT}, "executor": {"asp", FRONT}, "bridge": {"asp", "executor", FRONT}, FRONT: set()}
"""``assembly_constraints`` is the front (console command, Python API): it may use every
side, and no side uses it."""


def module_name(root: Path, path: Path) -> str:
    """``asp/sizes/learner.py`` → ``asp.sizes.learner``; a package's ``__init__`` is the package."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def side_of(name: str) -> str:
    """The folder a module name belongs to: ``asp.solve`` → ``asp``, ``assembly_constraints.cli`` → the front."""
    return name.split(".")[0]


@functools.cache
def imports(root: Path, path: Path) -> list[tuple[int, str, bool]]:
    """(line, absolute name, whether it must be a module) of every import of one file:
    ``import a.b`` and ``from a.b import c`` name the module ``a.b``; ``a.b.c`` is a module
    or a name defined in ``a.b``. Relative ones are resolved (parsed once per file for all
    the tests of the module)."""
    package = module_name(root, path).split(".")
    if path.name != "__init__.py":
        package = package[:-1]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name, True) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            module = ".".join([*base, *([node.module] if node.module else [])])
            found.append((node.lineno, module, True))
            found += [(node.lineno, f"{module}.{alias.name}", False) for alias in node.names]
    return found


def sources(root: Path) -> list[Path]:
    """Every module of the four folders (a symbolic link is not followed: the links test names it)."""
    return sorted(p for package in PACKAGES if (root / package).is_dir()
                  for p in (root / package).rglob("*.py") if not linked(root, p))


def linked(root: Path, path: Path) -> bool:
    """Whether a folder or file on the way from ``root`` to ``path`` is a symbolic link."""
    parts = path.relative_to(root).parts
    return any((root / Path(*parts[:n])).is_symlink() for n in range(1, len(parts) + 1))


def module_file(root: Path, name: str) -> Path | None:
    """The file of a module name in the checkout, ``a/b.py`` or ``a/b/__init__.py``, found
    without following a link (None if there is none)."""
    folder = root / Path(*name.split("."))
    for path in (folder.with_suffix(".py"), folder / "__init__.py"):
        if path.is_file() and not linked(root, path):
            return path
    return None


def unresolved(root: Path) -> list[str]:
    """``file:line imports X (reason)`` for every import of the product code that names
    something of the checkout (a top-level folder or module of ``root``) but is not a
    file of one of :data:`PACKAGES`, reached without a link."""
    local = {p.stem if p.suffix == ".py" else p.name for p in root.iterdir()
             if p.is_dir() or p.suffix == ".py"}
    bad = []
    for path in sources(root):
        for line, name, is_module in imports(root, path):
            top = name.split(".")[0]
            if top not in local:
                continue  # the standard library or an installed dependency
            where = f"{path.relative_to(root)}:{line} imports {name}"
            if top not in PACKAGES:
                bad.append(f"{where} (not product code)")
            elif module_file(root, name) is None and (is_module or module_file(root, name.rpartition(".")[0]) is None):
                bad.append(f"{where} (no file)")
    return sorted(set(bad))


def crossings(root: Path) -> set[tuple[str, str]]:
    """(folder, folder it imports) for every import from one of :data:`PACKAGES` into another."""
    return {(path.relative_to(root).parts[0], side_of(name)) for path in sources(root)
            for _, name, _ in imports(root, path)
            if side_of(name) in PACKAGES and side_of(name) != path.relative_to(root).parts[0]}


def violations(root: Path) -> list[str]:
    """``file:line imports X`` for every import that crosses the rule."""
    bad = []
    for path in sources(root):
        side = path.relative_to(root).parts[0]
        for line, name, _ in imports(root, path):
            if side_of(name) in FORBIDDEN[side]:
                bad.append(f"{path.relative_to(root)}:{line} imports {name}")
    return sorted(set(bad))


def import_graph(root: Path) -> nx.DiGraph:
    """Module → module it imports, among the project's own modules."""
    modules = {module_name(root, p): p for p in sources(root)}
    graph = nx.DiGraph()
    graph.add_nodes_from(modules)
    for name, path in modules.items():
        for _, imported, _ in imports(root, path):
            if imported in modules and imported != name and not name.startswith(imported + "."):
                graph.add_edge(name, imported)
    return graph


def test_planner_and_cell_meet_only_through_the_bridge() -> None:
    assert violations(ROOT) == []
    assert crossings(ROOT) - {(FRONT, layer) for layer in PACKAGES[:3]} == {("asp", "bridge"), ("executor", "bridge")}


def test_every_import_of_the_product_is_a_file_of_the_checkout_without_a_link() -> None:
    """What a reader opens is what Python imports: each import of ``asp/``, ``executor/``,
    ``bridge/`` and ``assembly_constraints/`` that names the checkout is a ``.py`` file or a
    package's ``__init__.py`` under the repository, no symbolic link on the way; so are the
    modules the command line imports by name (its registry)."""
    from assembly_constraints.cli import BENCHMARKS, SUBCOMMANDS

    assert [path for package in PACKAGES for path in (ROOT / package).rglob("*") if path.is_symlink()] == []
    assert unresolved(ROOT) == []
    named = {entry.partition(":")[0] for entry in [*BENCHMARKS.values(), *(m for m, _ in SUBCOMMANDS.values())]}
    assert {name for name in named if module_file(ROOT, name) is None} == set()


def test_the_rule_catches_a_planner_module_importing_the_cell(tmp_path: Path) -> None:
    for package in PACKAGES:
        (tmp_path / package).mkdir()
        (tmp_path / package / "__init__.py").write_text("")
    (tmp_path / "asp" / "planner.py").write_text("import executor\n")
    (tmp_path / "executor" / "cell.py").write_text("def f():\n    from asp.solve import solve\n")
    (tmp_path / "bridge" / "keys.py").write_text("from executor import ExecutorError\n"
                                                 "from . import messages\n")
    (tmp_path / "bridge" / "messages.py").write_text("from .keys import x\n")
    assert violations(tmp_path) == [
        "asp/planner.py:1 imports executor",
        "bridge/keys.py:1 imports executor",
        "bridge/keys.py:1 imports executor.ExecutorError",
        "executor/cell.py:2 imports asp.solve",
        "executor/cell.py:2 imports asp.solve.solve",
    ]
    assert crossings(tmp_path) == {("asp", "executor"), ("executor", "asp"), ("bridge", "executor")}
    cycles = [set(cycle) for cycle in nx.simple_cycles(import_graph(tmp_path))]
    assert cycles == [{"bridge.keys", "bridge.messages"}]


def test_the_resolution_catches_a_link_a_missing_module_and_a_test_import(tmp_path: Path) -> None:
    """The layout this replaced: the front held links to the layers and imports went
    through them, where a static reader finds no file."""
    for package in PACKAGES:
        (tmp_path / package).mkdir()
        (tmp_path / package / "__init__.py").write_text("")
    (tmp_path / "tests").mkdir()
    (tmp_path / FRONT / "asp").symlink_to("../asp", target_is_directory=True)
    (tmp_path / "asp" / "solve.py").write_text("def solve(): ...\n")
    (tmp_path / "bridge" / "keys.py").write_text("import bridge.gone\nimport tests.conftest\n")
    (tmp_path / "executor" / "cell.py").write_text(f"from {FRONT}.asp.solve import solve\nfrom asp.solve import solve\n"
                                                   "import numpy\n")
    assert (tmp_path / FRONT / "asp" / "solve.py").is_file()  # Python would import it through the link
    assert unresolved(tmp_path) == [
        "bridge/keys.py:1 imports bridge.gone (no file)",
        "bridge/keys.py:2 imports tests.conftest (not product code)",
        f"executor/cell.py:1 imports {FRONT}.asp.solve (no file)",
        f"executor/cell.py:1 imports {FRONT}.asp.solve.solve (no file)",
    ]
    assert module_file(tmp_path, "asp.solve") == tmp_path / "asp" / "solve.py"


def test_no_import_cycle_among_the_project_modules() -> None:
    cycles = sorted(sorted(cycle) for cycle in nx.simple_cycles(import_graph(ROOT)))
    assert cycles == []


def test_no_python_folder_holds_more_than_twelve_modules() -> None:
    folders = {path.parent for path in sources(ROOT)}
    crowded = {str(f.relative_to(ROOT)): n for f in folders
               if (n := len([p for p in f.glob("*.py") if p.name != "__init__.py"])) > 12}
    assert crowded == {}


def test_every_layer_error_shares_the_one_root() -> None:
    """Callers catch one layer's errors or all of them; none is converted into another."""
    from asp import PlannerError
    from bridge import BridgeError
    from bridge.errors import ToolError
    from executor import ExecutorError

    assert all(issubclass(error, ToolError) for error in (PlannerError, BridgeError, ExecutorError))
    assert not any(issubclass(a, b) for a in (PlannerError, BridgeError, ExecutorError)
                   for b in (PlannerError, BridgeError, ExecutorError) if a is not b)
