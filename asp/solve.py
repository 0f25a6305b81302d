"""The one clingo layer of the planner: locate an encoding, read and write facts, solve.

- Encodings ship in ``asp/encodings/`` (entry encodings at the top, their parts in
  ``precedence/``, ``sizes/``, ``plans/``) and are found with ``importlib.resources``
  (:func:`encoding`).
- Facts files are plain clingo programs (``learned.lp``, an assembly's ``sizes.lp``...).
  They are read by grounding them with clingo, so a file may also hold rules; what comes
  back is the set of atoms of the (unique) answer set (:func:`load_atoms`).
- Facts are written from ``clingo.Symbol`` values, never by string formatting of terms
  (:func:`fact`, :func:`format_facts`, :func:`write_facts`), and atomically.
- :func:`solve` grounds encodings with facts and calls back on every model.
"""

from __future__ import annotations

import importlib.resources
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

import clingo

from asp import PlannerError
from bridge.files import write_atomic


def encoding(name: str) -> Path:
    """Path of a shipped encoding, e.g. ``plans.lp`` or ``plans/needs_hole.lp``."""
    path = Path(str(importlib.resources.files("asp") / "encodings" / name))
    if not path.is_file():
        raise PlannerError(f"encoding '{name}': not found in {path.parent}")
    return path


def load_atoms(
    paths: Sequence[Path | str], *, encodings: Sequence[str] = (), extra: Iterable[clingo.Symbol] = ()
) -> list[clingo.Symbol]:
    """Ground the files with the named ``encodings`` (see :func:`encoding`) and ``extra``
    facts, and return the shown atoms of the one answer set.

    Raises PlannerError naming file:line when a file does not parse, does not exist,
    or has no single answer set.
    """
    messages: list[str] = []
    ctl = clingo.Control(["--models=2"], logger=lambda _code, msg: messages.append(msg.strip()))
    for path in paths:
        path = Path(path)
        if not path.is_file():
            raise PlannerError(f"{path}: no such facts file")
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            raise PlannerError(f"{path}: not a text file (expected ASP facts)") from None
        try:
            ctl.add("base", [], text.replace("\x00", ""))
        except RuntimeError:
            detail = "; ".join(m.replace("<block>", str(path)) for m in messages) or "syntax error"
            raise PlannerError(f"{path}: does not parse as ASP facts: {detail}") from None
    for name in encodings:
        ctl.load(str(encoding(name)))
    ctl.add("base", [], format_facts(extra))
    try:
        ctl.ground([("base", [])])
    except RuntimeError:
        raise PlannerError("facts do not ground: " + "; ".join(messages)) from None
    models: list[list[clingo.Symbol]] = []
    ctl.solve(on_model=lambda m: models.append(list(m.symbols(shown=True))))
    if len(models) != 1:
        names = ", ".join(str(p) for p in paths)
        raise PlannerError(f"{names}: expected facts with exactly one answer set, got {len(models)}")
    return models[0]


def atoms_by_name(atoms: Iterable[clingo.Symbol], name: str, arity: int) -> list[tuple[str, ...]]:
    """Arguments (as strings) of the atoms ``name/arity``, sorted."""
    return sorted(
        tuple(str(a) for a in atom.arguments)
        for atom in atoms
        if atom.type == clingo.SymbolType.Function
        and atom.name == name
        and len(atom.arguments) == arity
    )


def pairs_by_name(atoms: Iterable[clingo.Symbol], name: str) -> list[tuple[str, str]]:
    """Arguments (as strings) of the atoms ``name/2``, sorted."""
    return [(a, b) for a, b in atoms_by_name(atoms, name, 2)]


def fact(name: str, *args: str | int) -> clingo.Symbol:
    """A fact ``name(args...)``: strings become constants, ints numbers."""
    return clingo.Function(
        name, [clingo.Number(a) if isinstance(a, int) else clingo.Function(a) for a in args]
    )


def format_facts(atoms: Iterable[clingo.Symbol], header: str = "") -> str:
    """Facts as program text, one per line, after an optional ``%`` comment header."""
    lines = [f"% {line}" if line else "%" for line in header.splitlines()]
    lines += [f"{atom}." for atom in atoms]
    return "\n".join(lines) + "\n"


def write_facts(path: Path | str, atoms: Iterable[clingo.Symbol], header: str = "") -> None:
    """Write facts to ``path`` (see :func:`format_facts`), atomically: the old file stays
    whole unless the new one is complete (:func:`bridge.files.write_atomic`; BridgeError
    naming the path when it cannot be written)."""
    write_atomic(path, format_facts(atoms, header))


def solve(
    encodings: Sequence[str],
    atoms: Iterable[clingo.Symbol],
    arguments: Sequence[str],
    on_model: Callable[[clingo.Model], None],
    time_limit_s: float | None = None,
) -> clingo.SolveResult:
    """Ground the named encodings with the atoms as facts, solve, call ``on_model``.

    clingo's informational messages (e.g. a predicate without facts) are dropped; a
    grounding error becomes a PlannerError quoting them. A search that does not finish
    within ``time_limit_s`` [s] (None: no limit) is stopped with a PlannerError.
    """
    messages: list[str] = []
    ctl = clingo.Control(list(arguments), logger=lambda _code, msg: messages.append(msg.strip()))
    names = ", ".join(encodings)
    try:
        for name in encodings:
            ctl.load(str(encoding(name)))
        ctl.add("base", [], format_facts(atoms))
        ctl.ground([("base", [])])
    except RuntimeError:
        raise PlannerError(f"{names} does not ground: " + "; ".join(messages)) from None
    with ctl.solve(on_model=on_model, async_=True) as handle:
        if not handle.wait(time_limit_s):
            handle.cancel()
            raise PlannerError(f"{names}: the search did not finish within {time_limit_s} s")
        return handle.get()
