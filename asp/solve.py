"""The one clingo layer of the planner: locate an encoding, read and write facts, solve.

- Encodings ship in ``asp/encodings/`` (entry encodings at the top, their parts in
  ``precedence/``, ``sizes/``, ``plans/``) and are found with ``importlib.resources``
  (:func:`encoding`).
- Facts files are plain clingo programs (``learned.lp``, an assembly's ``sizes.lp``...).
  They are read by grounding them with clingo, so a file may also hold rules; what comes
  back is the set of atoms of the (unique) answer set (:func:`load_atoms`).
- Data files that must hold ground facts only (a CAD prior's ``nominal_sizes.lp``) are read
  as data, never grounded: :func:`read_ground_facts` parses them with clingo's parser and
  refuses any rule, variable, interval, pool or operation, and more facts than a bound, so
  ``n(1..50000000).`` is one line of error, not an unbounded grounding.
- Facts are written from ``clingo.Symbol`` values, never by string formatting of terms
  (:func:`fact`, :func:`format_facts`, :func:`write_facts`), and atomically.
- Facts reach clingo as symbols through its backend (:func:`add_facts`), never as
  program text: an id read from a file or a message is one constant whatever its
  characters, so it cannot add rules or facts of its own.
- :func:`solve` grounds encodings with facts and calls back on every model.
"""

from __future__ import annotations

import importlib.resources
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path

import clingo
import clingo.ast

from asp import MAX_IDS, PlannerError
from bridge.assembly import is_id
from bridge.files import write_atomic
from bridge.inputs import read_bytes, shorten

_CONSTANT = re.compile(r"_*[a-z][A-Za-z0-9_']*")
_STRINGS_AND_COMMENTS = re.compile(r'"(?:\\.|[^"\\\n])*"|%\*.*?\*%|%[^\n]*', re.DOTALL)
_NON_ASCII = re.compile(r"[^\x00-\x7f]")


def _check_ascii(path: Path, text: str) -> None:
    """PlannerError naming file:line at a non-ASCII character outside strings and comments.

    Never valid ASP there, and clingo's own message would quote a piece of the character:
    its Python logger then fails to decode it and the process aborts."""
    code = _STRINGS_AND_COMMENTS.sub(lambda match: "\n" * match.group().count("\n"), text)
    found = _NON_ASCII.search(code)
    if found:
        line = code[: found.start()].count("\n") + 1
        raise PlannerError(f"{path}:{line}: character {found.group()!r} outside a string or comment; "
                           "expected ASP facts (ASCII ids such as p1)")


def encoding(name: str) -> Path:
    """Path of a shipped encoding, e.g. ``plans.lp`` or ``plans/needs_hole.lp``."""
    path = Path(str(importlib.resources.files("asp") / "encodings" / name))
    if not path.is_file():
        raise PlannerError(f"encoding '{name}': not found in {path.parent}")
    return path


def load_atoms(
    paths: Sequence[Path | str], *, encodings: Sequence[str] = (), extra: Iterable[clingo.Symbol] = (),
    shown_only: bool = True,
) -> list[clingo.Symbol]:
    """Ground the files with the named ``encodings`` (see :func:`encoding`) and ``extra``
    facts, and return the shown atoms of the one answer set (all its atoms when not
    ``shown_only``: an encoding's ``#show`` then hides nothing from checks).

    Raises PlannerError naming file:line when a file does not exist, cannot be read, is
    larger than :data:`bridge.inputs.MAX_INPUT_BYTES`, does not parse, or has no single
    answer set (clingo's messages are cut to one short line each).
    """
    messages: list[str] = []
    ctl = clingo.Control(["--models=2"], logger=lambda _code, msg: messages.append(msg.strip()))
    for path in paths:
        path = Path(path)
        text = _facts_text(path, "ASP facts")
        try:
            ctl.add("base", [], text.replace("\x00", ""))
        except RuntimeError:
            detail = "; ".join(shorten(m.replace("<block>", str(path)), 160) for m in messages[:2]) or "syntax error"
            raise PlannerError(f"{path}: does not parse as ASP facts: {detail}") from None
    for name in encodings:
        ctl.load(str(encoding(name)))
    add_facts(ctl, extra)
    try:
        ctl.ground([("base", [])])
    except RuntimeError:
        raise PlannerError("facts do not ground: " + "; ".join(shorten(m, 160) for m in messages[:2])) from None
    models: list[list[clingo.Symbol]] = []
    ctl.solve(on_model=lambda m: models.append(list(m.symbols(shown=shown_only, atoms=not shown_only))))
    if len(models) != 1:
        names = ", ".join(str(p) for p in paths)
        raise PlannerError(f"{names}: expected facts with exactly one answer set, got {len(models)}")
    return models[0]


def _ground_term(term: clingo.ast.AST) -> clingo.Symbol | None:
    """The symbol of a ground term (a constant, number, string, ``-N`` or a function of
    ground terms); None for anything else (variable, interval, pool, operation)."""
    if term.ast_type == clingo.ast.ASTType.SymbolicTerm:
        return term.symbol
    if (term.ast_type == clingo.ast.ASTType.UnaryOperation and term.operator_type == clingo.ast.UnaryOperator.Minus
            and term.argument.ast_type == clingo.ast.ASTType.SymbolicTerm
            and term.argument.symbol.type == clingo.SymbolType.Number):
        return clingo.Number(-term.argument.symbol.number)
    if term.ast_type == clingo.ast.ASTType.Function and not term.external:
        arguments = [_ground_term(argument) for argument in term.arguments]
        if all(argument is not None for argument in arguments):
            return clingo.Function(term.name, [a for a in arguments if a is not None])
    return None


def _facts_text(path: Path, expected: str) -> str:
    """The text of the facts file ``path`` (read under :func:`read_bytes`'s rules, UTF-8,
    checked by :func:`_check_ascii`); PlannerError naming the file and ``expected`` otherwise."""
    data = read_bytes(path, "facts file", error=PlannerError)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise PlannerError(f"{path}: not a text file (expected {expected})") from None
    _check_ascii(path, text)
    return text


def read_ground_facts(path: Path, expected: str, *, max_facts: int) -> list[tuple[int, clingo.Symbol]]:
    """The facts of ``path`` with their line numbers, read as data (parsed, never grounded).

    PlannerError naming ``path:line`` and ``expected`` (e.g. ``"nominal_margin(Part,Hole,
    Micrometres) facts"``) at anything but a ground fact (a rule, a directive, a variable,
    an interval ``1..N``, a pool ``a;b``, an arithmetic term), and when the file holds more
    than ``max_facts`` facts; the file itself is read under :func:`read_bytes`'s rules."""
    text = _facts_text(path, expected)
    facts: list[tuple[int, clingo.Symbol]] = []
    refused: list[str] = []

    def statement(node: clingo.ast.AST) -> None:
        if refused:
            return
        line = node.location.begin.line
        if node.ast_type == clingo.ast.ASTType.Comment or (
                node.ast_type == clingo.ast.ASTType.Program and node.name == "base" and not node.parameters):
            return  # a comment, or the implicit "#program base." every parse starts with
        head = node.head if node.ast_type == clingo.ast.ASTType.Rule and not node.body else None
        atom = (head.atom if head is not None and head.ast_type == clingo.ast.ASTType.Literal
                and head.sign == clingo.ast.Sign.NoSign
                and head.atom.ast_type == clingo.ast.ASTType.SymbolicAtom else None)
        symbol = _ground_term(atom.symbol) if atom is not None else None
        if symbol is None or symbol.type != clingo.SymbolType.Function:
            refused.append(f"{path}:{line}: {shorten(str(node), 60)}: expected {expected} only (ground facts, "
                           "no rules, variables, intervals, pools or arithmetic)")
        elif len(facts) == max_facts:
            refused.append(f"{path}:{line}: more than {max_facts} facts; expected at most {max_facts}")
        else:
            facts.append((line, symbol))

    messages: list[str] = []
    try:
        clingo.ast.parse_string(text.replace("\x00", ""), statement,
                                logger=lambda _code, msg: messages.append(msg.strip()))
    except RuntimeError:
        detail = "; ".join(shorten(m.replace("<string>", str(path)), 160) for m in messages[:2]) or "syntax error"
        raise PlannerError(f"{path}: does not parse as ASP facts: {detail}") from None
    if refused:
        raise PlannerError(refused[0])
    return facts


def check_facts(atoms: Iterable[clingo.Symbol], signatures: Mapping[str, int], source: str) -> None:
    """Check the atoms of the predicates named in ``signatures`` (name → arity), whose
    arguments are all ids: PlannerError naming ``source`` and the atom when one has another
    arity (e.g. ``must_precede/3``, expected ``must_precede/2``), an argument that is not an
    id (a lower-case ASP constant such as ``p1``, not ``"ä"`` or ``3``), or when there are
    more than :data:`asp.MAX_IDS` ``part/1`` or ``hole/1`` atoms."""
    counts: dict[str, int] = {}
    for atom in atoms:
        if atom.type != clingo.SymbolType.Function or atom.name not in signatures:
            continue
        arity = signatures[atom.name]
        if len(atom.arguments) != arity:
            raise PlannerError(f"{source}: {shorten(atom, 60)}: {atom.name}/{len(atom.arguments)}, "
                               f"expected {atom.name}/{arity}")
        for argument in atom.arguments:
            if (argument.type != clingo.SymbolType.Function or argument.arguments or not argument.positive
                    or not is_id(argument.name)):
                raise PlannerError(f"{source}: {shorten(atom, 60)}: '{shorten(argument)}' is not an id "
                                   "(expected lower-case ASP constants such as p1)")
        counts[atom.name] = counts.get(atom.name, 0) + 1
    for name in ("part", "hole"):
        if counts.get(name, 0) > MAX_IDS:
            raise PlannerError(f"{source}: {counts[name]} {name}/1 facts; expected at most {MAX_IDS}")


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


def add_facts(ctl: clingo.Control, atoms: Iterable[clingo.Symbol]) -> None:
    """Add the atoms to ``ctl`` as facts through its backend, before grounding: the
    grounder sees them like facts of the program, but no symbol is ever parsed as
    program text."""
    with ctl.backend() as backend:
        for atom in atoms:
            backend.add_rule([backend.add_atom(atom)])


def _unprintable(symbol: clingo.Symbol) -> str | None:
    """The first name in ``symbol`` that is no ASP constant (clingo prints a function's name
    as it is, so such a name would become program text), else None."""
    if symbol.type != clingo.SymbolType.Function:
        return None  # numbers, #inf/#sup, and strings (printed quoted and escaped)
    if symbol.name and (symbol.name == "not" or not _CONSTANT.fullmatch(symbol.name)):
        return symbol.name
    return next((name for name in map(_unprintable, symbol.arguments) if name is not None), None)


def format_facts(atoms: Iterable[clingo.Symbol], header: str = "") -> str:
    """Facts as program text, one per line, after an optional ``%`` comment header;
    PlannerError for a symbol with a name that is no ASP constant (it would not read back
    as the same fact)."""
    lines = [f"% {line}" if line else "%" for line in header.splitlines()]
    for atom in atoms:
        bad = _unprintable(atom)
        if bad is not None:
            raise PlannerError(f"cannot write the fact {shorten(repr(str(atom)), 60)}: {shorten(repr(bad))} is not "
                               "an ASP constant")
        lines.append(f"{atom}.")
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
        add_facts(ctl, atoms)
        ctl.ground([("base", [])])
    except RuntimeError:
        raise PlannerError(f"{names} does not ground: " + "; ".join(messages)) from None
    with ctl.solve(on_model=on_model, async_=True) as handle:
        if not handle.wait(time_limit_s):
            handle.cancel()
            raise PlannerError(f"{names}: the search did not finish within {time_limit_s} s")
        return handle.get()
