"""Demonstrations: feasible assembly sequences shown by a human (paper 2.1).

Text format (``demos.txt``): one sequence per line, part ids separated by spaces or
commas; ``#`` starts a comment; blank lines are ignored. The parts are those of the
assembly when one is given, otherwise the ids of the first sequence. Every sequence
must name every part exactly once.

The same data is accepted as ASP facts (a file ending in ``.lp``): ``demo(D,I,P)``,
demonstration ``D`` places part ``P`` at position ``I`` (1-based), plus optional
``part/1``. Every error raises :class:`asp.PlannerError` naming file:line (or the
demonstration) and what was expected.

Bounds: a file of at most :data:`bridge.inputs.MAX_INPUT_BYTES`, at most
:data:`asp.MAX_IDS` parts and :data:`MAX_DEMONSTRATIONS` sequences; a step number of
``demo/3`` is at most the number of parts. Echoed ids are cut to 40 characters.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import clingo

from asp import MAX_IDS, PlannerError
from asp.solve import atoms_by_name, fact, load_atoms
from bridge.assembly import ID_PATTERN
from bridge.inputs import read_bytes, shorten

_ID = re.compile(ID_PATTERN)
_SEPARATOR = re.compile(r"[\s,]+")
_CONTROL = re.compile(r"[\x00-\x08\x0e-\x1f\x7f]")
_EXPECTED = "(part ids separated by spaces or commas)"
MAX_DEMONSTRATIONS = 1000
"""At most this many demonstrated sequences per file (the paper uses up to 30; replaying
1000 sequences of 64 parts through `suggest` takes about 4 s)."""


@dataclass(frozen=True)
class Demonstrations:
    """Sequences over ``parts``; ``origins[k]`` names where sequence k came from (file:line)."""

    parts: tuple[str, ...]
    sequences: tuple[tuple[str, ...], ...]
    origins: tuple[str, ...]


def _listed(ids: Sequence[str]) -> str:
    """Ids separated by spaces, cut short for a message."""
    return shorten(" ".join(ids), 200)


def _check_sequence(where: str, ids: Sequence[str], parts: Sequence[str], parts_origin: str) -> None:
    if len(ids) > MAX_IDS:
        raise PlannerError(f"{where}: {len(ids)} ids; expected at most {MAX_IDS} parts")
    seen: set[str] = set()
    for part in ids:
        if not _ID.match(part):
            raise PlannerError(f"{where}: '{shorten(part)}' is not a part id "
                               "(expected a lower-case ASP constant of at most 64 characters)")
        if part not in parts:
            raise PlannerError(f"{where}: unknown id '{shorten(part)}'; expected one of {parts_origin}: "
                               f"{_listed(parts)}")
        if part in seen:
            raise PlannerError(f"{where}: id '{part}' is repeated; each part is placed exactly once")
        seen.add(part)
    missing = [p for p in parts if p not in seen]
    if missing:
        raise PlannerError(
            f"{where}: missing id(s) {_listed(missing)}: the line has {len(ids)} ids, expected "
            f"{len(parts)} (every sequence places every part; {parts_origin}: {_listed(parts)})"
        )


def _check_count(source: object, count: int) -> None:
    if count > MAX_DEMONSTRATIONS:
        raise PlannerError(f"{source}: more than {MAX_DEMONSTRATIONS} demonstrations; expected at most "
                           f"{MAX_DEMONSTRATIONS}")


def _text(path: Path) -> str:
    data = read_bytes(path, "demonstrations file", error=PlannerError)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise PlannerError(f"{path}:{line}: binary data, expected text {_EXPECTED}") from None
    control = _CONTROL.search(text)
    if control:
        line = text[: control.start()].count("\n") + 1
        raise PlannerError(f"{path}:{line}: binary data (control character {control.group()!r}), "
                           f"expected text {_EXPECTED}")
    return text


def parse_demos(text: str, source: str, parts: Sequence[str] | None = None) -> Demonstrations:
    """Parse demonstrations text; ``source`` names the file in messages.

    ``parts``: the assembly's part ids; None takes the ids of the first sequence.
    """
    sequences: list[tuple[str, ...]] = []
    origins: list[str] = []
    known = tuple(parts) if parts is not None else None
    parts_origin = "the assembly's parts"
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        where = f"{source}:{number}"
        ids = [t for t in _SEPARATOR.split(line) if t]
        if not ids:
            raise PlannerError(f"{where}: only separators, expected a sequence {_EXPECTED}")
        if known is None:
            _check_sequence(where, ids, ids, "the ids of the line")
            known, parts_origin = tuple(ids), f"the parts of the first sequence ({source}:{number})"
        _check_sequence(where, ids, known, parts_origin)
        sequences.append(tuple(ids))
        origins.append(where)
        _check_count(source, len(sequences))
    if not sequences:
        raise PlannerError(f"{source}: empty, expected at least one sequence (part ids separated by spaces or commas)")
    assert known is not None
    return Demonstrations(known, tuple(sequences), tuple(origins))


def _demos_from_facts(path: Path, parts: Sequence[str] | None) -> Demonstrations:
    atoms = load_atoms([path])
    if not any(a.match("demo", 3) for a in atoms):
        raise PlannerError(f"{path}: expected demo(D,I,P) facts (demonstration D places part P at step I)")
    declared = [p for (p,) in atoms_by_name(atoms, "part", 1)]
    demos = [a.arguments for a in atoms if a.match("demo", 3)]
    count = len(parts if parts is not None else declared or {str(symbol) for _, _, symbol in demos})
    if count > MAX_IDS:
        raise PlannerError(f"{path}: {count} parts; expected at most {MAX_IDS}")
    by_demo: dict[str, dict[int, str]] = {}
    for demo, step, symbol in demos:
        where = f"{path}: demo({shorten(demo)},{shorten(step)},{shorten(symbol)})"
        if step.type != clingo.SymbolType.Number or not 1 <= step.number <= count:
            raise PlannerError(f"{where}: the step must be an integer from 1 to {count} (the number of parts)")
        steps = by_demo.setdefault(str(demo), {})
        _check_count(path, len(by_demo))
        if step.number in steps:
            raise PlannerError(f"{where}: demonstration {demo} already places {steps[step.number]} "
                               f"at step {step.number}")
        steps[step.number] = str(symbol)
    known = list(parts) if parts is not None else None
    sequences, origins = [], []
    for label, steps in sorted(by_demo.items(), key=lambda item: _demo_order(item[0])):
        where = f"{path}: demonstration {label}"
        gaps = [i for i in range(1, max(steps) + 1) if i not in steps]
        if gaps:
            raise PlannerError(f"{where}: no part at step {gaps[0]}; expected steps 1..{max(steps)}")
        ids = [steps[i] for i in range(1, max(steps) + 1)]
        if known is None:
            known = ids
        _check_sequence(where, ids, known, "the parts")
        sequences.append(tuple(ids))
        origins.append(where)
    assert known is not None
    if declared and set(declared) != set(known):
        raise PlannerError(f"{path}: part/1 facts {_listed(declared)} differ from the demonstrated parts "
                           f"{_listed(known)}")
    return Demonstrations(tuple(known), tuple(sequences), tuple(origins))


def _demo_order(name: str) -> tuple[int, int | str]:
    return (0, int(name)) if name.isdigit() else (1, name)


def load_demos(path: Path | str, parts: Sequence[str] | None = None) -> Demonstrations:
    """Read demonstrations from a text file or (``*.lp``) ``demo/3`` facts."""
    path = Path(path)
    if path.suffix == ".lp":
        return _demos_from_facts(path, parts)
    return parse_demos(_text(path), str(path), parts)


def demo_facts(demos: Demonstrations) -> list[clingo.Symbol]:
    """``part/1`` and ``demo(D,I,P)`` facts (D and I 1-based) for the demonstrations."""
    atoms = [fact("part", p) for p in demos.parts]
    for d, sequence in enumerate(demos.sequences, start=1):
        atoms += [fact("demo", d, i, p) for i, p in enumerate(sequence, start=1)]
    return atoms
