"""Demonstrations: feasible assembly sequences shown by a human (paper 2.1).

Text format (``demos.txt``): one sequence per line, part ids separated by spaces or
commas; ``#`` starts a comment; blank lines are ignored. The parts are those of the
assembly when one is given, otherwise the ids of the first sequence. Every sequence
must name every part exactly once. A part may say where it went: ``p1@r1`` (part p1
placed in hole r1; paper 4.2, last paragraph): a fit seen in a demonstration, which the
size learner starts from. The hole must be one of the assembly's holes when they are
given, and one demonstration puts at most one part into a hole.

The same data is accepted as ASP facts (a file ending in ``.lp``): ``demo(D,I,P)``,
demonstration ``D`` places part ``P`` at position ``I`` (1-based), or ``demo(D,I,P,H)``,
into hole ``H``; plus optional ``part/1``. Every error raises :class:`asp.PlannerError`
naming file:line (or the demonstration) and what was expected.

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
from bridge.assembly import is_id
from bridge.inputs import read_bytes, shorten

_SEPARATOR = re.compile(r"[\s,]+")
_CONTROL = re.compile(r"[\x00-\x08\x0e-\x1f\x7f]")
_EXPECTED = "(part ids separated by spaces or commas)"
MAX_DEMONSTRATIONS = 1000
"""At most this many demonstrated sequences per file (the paper uses up to 30; replaying
1000 sequences of 64 parts through `suggest` takes about 4 s)."""


@dataclass(frozen=True)
class Demonstrations:
    """Sequences over ``parts``; ``origins[k]`` names where sequence k came from (file:line);
    ``holes[k][i]`` is the hole the i-th part of sequence k went into, or None (``holes``
    empty: none said)."""

    parts: tuple[str, ...]
    sequences: tuple[tuple[str, ...], ...]
    origins: tuple[str, ...]
    holes: tuple[tuple[str | None, ...], ...] = ()

    def placements(self) -> list[tuple[str, str]]:
        """Every (part, hole) some demonstration placed, in the order first seen."""
        seen = [(part, hole) for sequence, holes in zip(self.sequences, self.holes)
                for part, hole in zip(sequence, holes) if hole is not None]
        return list(dict.fromkeys(seen))


def _listed(ids: Sequence[str]) -> str:
    """Ids separated by spaces, cut short for a message."""
    return shorten(" ".join(ids), 200)


def _check_sequence(where: str, ids: Sequence[str], parts: Sequence[str], parts_origin: str) -> None:
    if len(ids) > MAX_IDS:
        raise PlannerError(f"{where}: {len(ids)} ids; expected at most {MAX_IDS} parts")
    seen: set[str] = set()
    for part in ids:
        if not is_id(part):
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


def _check_holes(where: str, ids: Sequence[str], holes: Sequence[str | None], known: Sequence[str] | None) -> None:
    """The holes of one sequence: ids, of the assembly's holes (``known``; None: any), each used once."""
    used: dict[str, str] = {}
    for part, hole in zip(ids, holes):
        if hole is None:
            continue
        if not is_id(hole):
            raise PlannerError(f"{where}: '{shorten(part)}@{shorten(hole)}': '{shorten(hole)}' is not a hole id "
                               "(expected part@hole, a lower-case ASP constant after @)")
        if known is not None and hole not in known:
            raise PlannerError(f"{where}: '{part}@{shorten(hole)}': unknown hole '{shorten(hole)}'; expected one "
                               f"of the assembly's holes: {_listed(known)}")
        if hole in used:
            raise PlannerError(f"{where}: '{part}@{hole}': hole {hole} already holds {used[hole]} in this "
                               "demonstration; one part per hole")
        used[hole] = part


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


def parse_demos(text: str, source: str, parts: Sequence[str] | None = None,
                holes: Sequence[str] | None = None) -> Demonstrations:
    """Parse demonstrations text; ``source`` names the file in messages.

    ``parts``: the assembly's part ids; None takes the ids of the first sequence.
    ``holes``: the assembly's hole ids that ``part@hole`` may name; None: any id.
    """
    sequences: list[tuple[str, ...]] = []
    placed: list[tuple[str | None, ...]] = []
    origins: list[str] = []
    known = tuple(parts) if parts is not None else None
    parts_origin = "the assembly's parts"
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        where = f"{source}:{number}"
        tokens = [t.partition("@") for t in _SEPARATOR.split(line) if t]
        if not tokens:
            raise PlannerError(f"{where}: only separators, expected a sequence {_EXPECTED}")
        ids = [part for part, _at, _hole in tokens]
        where_to = [hole if at else None for _part, at, hole in tokens]
        if known is None:
            _check_sequence(where, ids, ids, "the ids of the line")
            known, parts_origin = tuple(ids), f"the parts of the first sequence ({source}:{number})"
        _check_sequence(where, ids, known, parts_origin)
        _check_holes(where, ids, where_to, holes)
        sequences.append(tuple(ids))
        placed.append(tuple(where_to))
        origins.append(where)
        _check_count(source, len(sequences))
    if not sequences:
        raise PlannerError(f"{source}: empty, expected at least one sequence (part ids separated by spaces or commas)")
    assert known is not None
    return Demonstrations(known, tuple(sequences), tuple(origins), tuple(placed))


def _demos_from_facts(path: Path, parts: Sequence[str] | None, holes: Sequence[str] | None) -> Demonstrations:
    atoms = load_atoms([path])
    demos = [a.arguments for a in atoms if a.match("demo", 3) or a.match("demo", 4)]
    if not demos:
        raise PlannerError(f"{path}: expected demo(D,I,P) facts (demonstration D places part P at step I) "
                           "or demo(D,I,P,H) (into hole H)")
    declared = [p for (p,) in atoms_by_name(atoms, "part", 1)]
    count = len(parts if parts is not None else declared or {str(args[2]) for args in demos})
    if count > MAX_IDS:
        raise PlannerError(f"{path}: {count} parts; expected at most {MAX_IDS}")
    by_demo: dict[str, dict[int, str]] = {}
    hole_of: dict[tuple[str, int], str] = {}
    for demo, step, symbol, *hole in demos:
        where = f"{path}: demo({','.join(shorten(a) for a in (demo, step, symbol, *hole))})"
        if step.type != clingo.SymbolType.Number or not 1 <= step.number <= count:
            raise PlannerError(f"{where}: the step must be an integer from 1 to {count} (the number of parts)")
        steps = by_demo.setdefault(str(demo), {})
        _check_count(path, len(by_demo))
        if step.number in steps:
            raise PlannerError(f"{where}: demonstration {demo} already places {steps[step.number]} "
                               f"at step {step.number}")
        steps[step.number] = str(symbol)
        if hole:
            _check_holes(where, [str(symbol)], [str(hole[0])], holes)
            hole_of[(str(demo), step.number)] = str(hole[0])
    known = list(parts) if parts is not None else None
    sequences, origins, placed = [], [], []
    for label, steps in sorted(by_demo.items(), key=lambda item: _demo_order(item[0])):
        where = f"{path}: demonstration {label}"
        gaps = [i for i in range(1, max(steps) + 1) if i not in steps]
        if gaps:
            raise PlannerError(f"{where}: no part at step {gaps[0]}; expected steps 1..{max(steps)}")
        ids = [steps[i] for i in range(1, max(steps) + 1)]
        if known is None:
            known = ids
        _check_sequence(where, ids, known, "the parts")
        where_to = [hole_of.get((label, i)) for i in range(1, max(steps) + 1)]
        _check_holes(where, ids, where_to, holes)
        sequences.append(tuple(ids))
        placed.append(tuple(where_to))
        origins.append(where)
    assert known is not None
    if declared and set(declared) != set(known):
        raise PlannerError(f"{path}: part/1 facts {_listed(declared)} differ from the demonstrated parts "
                           f"{_listed(known)}")
    return Demonstrations(tuple(known), tuple(sequences), tuple(origins), tuple(placed))


def _demo_order(name: str) -> tuple[int, int | str]:
    return (0, int(name)) if name.isdigit() else (1, name)


def load_demos(path: Path | str, parts: Sequence[str] | None = None,
               holes: Sequence[str] | None = None) -> Demonstrations:
    """Read demonstrations from a text file or (``*.lp``) ``demo/3``, ``demo/4`` facts;
    ``parts``, ``holes``: the assembly's (see :func:`parse_demos`)."""
    path = Path(path)
    if path.suffix == ".lp":
        return _demos_from_facts(path, parts, holes)
    return parse_demos(_text(path), str(path), parts, holes)


def demo_facts(demos: Demonstrations) -> list[clingo.Symbol]:
    """``part/1`` and ``demo(D,I,P)`` facts (D and I 1-based) for the demonstrations,
    ``demo(D,I,P,H)`` for a part placed into hole H."""
    atoms = [fact("part", p) for p in demos.parts]
    for d, sequence in enumerate(demos.sequences, start=1):
        holes = demos.holes[d - 1] if demos.holes else (None,) * len(sequence)
        atoms += [fact("demo", d, i, p) if h is None else fact("demo", d, i, p, h)
                  for i, (p, h) in enumerate(zip(sequence, holes), start=1)]
    return atoms
