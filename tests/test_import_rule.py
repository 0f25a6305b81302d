"""The architecture, checked on the source: the planner (``asp``) and the cell (``executor``)
meet only through ``bridge``, and no module imports itself back through others.

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
"""The repository's folders; the first three are installed as ``assembly_constraints.<folder>``."""
FRONT = "assembly_constraints"
FORBIDDEN = {"asp": {"executor", FRONT}, "executor": {"asp", FRONT}, "bridge": {"asp", "executor", FRONT}, FRONT: set()}
"""``assembly_constraints`` is the front (console command, Python API): it may use every
side, and no side uses it."""


def module_name(root: Path, path: Path) -> str:
    """``asp/sizes/learner.py`` → ``assembly_constraints.asp.sizes.learner`` (its installed
    name); a package's ``__init__`` is the package."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[0] != FRONT:
        parts.insert(0, FRONT)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def side_of(name: str) -> str:
    """The folder a module name belongs to: ``assembly_constraints.asp.solve`` → ``asp``,
    ``assembly_constraints.cli`` → the front; a bare ``asp...`` name (never installed) counts
    as its folder, so it is caught as well."""
    parts = name.split(".")
    if parts[0] == FRONT:
        return parts[1] if len(parts) > 1 and parts[1] in PACKAGES[:3] else FRONT
    return parts[0]


@functools.cache
def imports(root: Path, path: Path) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import of one file; relative ones are resolved
    (parsed once per file for all the tests of the module)."""
    package = module_name(root, path).split(".")
    if path.name != "__init__.py":
        package = package[:-1]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            module = ".".join([*base, *([node.module] if node.module else [])])
            found.append((node.lineno, module))
            found += [(node.lineno, f"{module}.{alias.name}") for alias in node.names]
    return found


def sources(root: Path) -> list[Path]:
    """Every module of the four folders, once: not through the front's links to the layers."""
    return sorted(p for package in PACKAGES if (root / package).is_dir() for p in (root / package).rglob("*.py")
                  if not any((root / Path(*p.relative_to(root).parts[:n])).is_symlink()
                             for n in range(1, len(p.relative_to(root).parts))))


def violations(root: Path) -> list[str]:
    """``file:line imports X`` for every import that crosses the rule."""
    bad = []
    for path in sources(root):
        side = path.relative_to(root).parts[0]
        for line, name in imports(root, path):
            if side_of(name) in FORBIDDEN[side]:
                bad.append(f"{path.relative_to(root)}:{line} imports {name}")
    return sorted(set(bad))


def import_graph(root: Path) -> nx.DiGraph:
    """Module → module it imports, among the project's own modules."""
    modules = {module_name(root, p): p for p in sources(root)}
    graph = nx.DiGraph()
    graph.add_nodes_from(modules)
    for name, path in modules.items():
        for _, imported in imports(root, path):
            if imported in modules and imported != name and not name.startswith(imported + "."):
                graph.add_edge(name, imported)
    return graph


def test_planner_and_cell_meet_only_through_the_bridge() -> None:
    assert violations(ROOT) == []


def test_the_rule_catches_a_planner_module_importing_the_cell(tmp_path: Path) -> None:
    for package in PACKAGES[:3]:
        (tmp_path / package).mkdir()
        (tmp_path / package / "__init__.py").write_text("")
    (tmp_path / "asp" / "planner.py").write_text("import executor\n")
    (tmp_path / "executor" / "cell.py").write_text("def f():\n    from assembly_constraints.asp.solve import solve\n")
    (tmp_path / "bridge" / "keys.py").write_text("from assembly_constraints.executor import ExecutorError\n"
                                                 "from . import messages\n")
    (tmp_path / "bridge" / "messages.py").write_text("from .keys import x\n")
    assert violations(tmp_path) == [
        "asp/planner.py:1 imports executor",
        "bridge/keys.py:1 imports assembly_constraints.executor",
        "bridge/keys.py:1 imports assembly_constraints.executor.ExecutorError",
        "executor/cell.py:2 imports assembly_constraints.asp.solve",
        "executor/cell.py:2 imports assembly_constraints.asp.solve.solve",
    ]
    cycles = [set(cycle) for cycle in nx.simple_cycles(import_graph(tmp_path))]
    assert cycles == [{"assembly_constraints.bridge.keys", "assembly_constraints.bridge.messages"}]


def test_no_module_imports_a_layer_outside_the_namespace() -> None:
    """Installed, only ``assembly_constraints`` exists: a bare ``import bridge`` would fail there."""
    bare = [f"{path.relative_to(ROOT)}:{line} imports {name}" for path in sources(ROOT)
            for line, name in imports(ROOT, path) if name.split(".")[0] in PACKAGES[:3]]
    assert bare == []


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
    from assembly_constraints.asp import PlannerError
    from assembly_constraints.bridge import BridgeError
    from assembly_constraints.bridge.errors import ToolError
    from assembly_constraints.executor import ExecutorError

    assert all(issubclass(error, ToolError) for error in (PlannerError, BridgeError, ExecutorError))
    assert not any(issubclass(a, b) for a in (PlannerError, BridgeError, ExecutorError)
                   for b in (PlannerError, BridgeError, ExecutorError) if a is not b)
