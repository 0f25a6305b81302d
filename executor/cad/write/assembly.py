"""``assembly.toml``: every part (the base with role ``base``, a part in a hole with role ``peg``
and its section's kind as ``shape``, ``cover``, ``head``, any other ``part``) with its tray
``start``, every hole (``h1``, ``h2``, ... by position, empty ones too) with its kind and
position, every hole of a moving part a part passes (``<owner>_hole1``, ...
:func:`executor.cad.derive.part_holes`; one on the line of a hole of the base its parts
stand in, with ``on_line``, that hole, and ``owner``), and every pin a part goes onto or no part is on
(``<owner>_pin1``, ... :func:`executor.cad.derive.pins`) as a hole at the pin's position with
the pin's section kind; and the import's :class:`Settings`. Lengths in metres."""

from __future__ import annotations

import json
from dataclasses import dataclass

from executor.cad.derive import Derived
from executor.cad.operations.frames import entry_point, pin_entry
from executor.cad.operations.view import section_kind
from executor.cad.parts import turn_text
from executor.cad.sections import rounded as _q


@dataclass(frozen=True)
class Settings:
    """What the import file states: the ``base`` part, the ``trays`` [m], part ``names``,
    the CAD's axis pointing ``up`` (:func:`executor.cad.parts.turned`), the ``turn`` [deg]
    about z the product was then given (:func:`executor.cad.parts.quarter_turned`) and the
    offset (x, y, z) [m] every part was then ``moved`` by into the cell (:func:`executor.cad.cli.placement`);
    ``left_out``: the setting that left parts of the CAD out and their ids (none: no part left out)."""

    base: str
    trays: dict[str, tuple[float, float]]
    names: dict[str, str]
    up: str = "+z"
    moved: tuple[float, float, float] = (0.0, 0.0, 0.0)
    turn: int = 0
    left_out: tuple[str, tuple[str, ...]] = ("", ())


def assembly_text(derived: Derived, settings: Settings, title: str, roles: dict[str, str]) -> str:
    """``assembly.toml``: the parts with their ``roles`` (base, peg, else the given one or
    ``part``) and trays, the holes (a pin several parts go onto, or a hole of the base
    several parts stand in, with their number as its ``capacity``)."""
    pegs = derived.hole_of
    frame = ("the CAD frame (the cell frame)" if settings.up == "+z" and not any(settings.moved) and not settings.turn
             else "the cell frame")
    if settings.up != "+z":
        frame += f", the CAD's {settings.up} turned up ({turn_text(settings.up)})"
    if settings.turn:
        frame += f", turned {settings.turn} deg about z"
    if any(settings.moved):
        frame += (", moved by ({}, {}, {}) mm from {} (the base's centre to place, the product's lowest "
                  "point to the floor, z = 0, or place's z)").format(*(f"{1000 * v:.3f}" for v in settings.moved),
                                                                   "there" if settings.turn else "the CAD frame")
    setting, dropped = settings.left_out
    lines = [f"# Imported from {title} by ./run.sh import: parts in {frame} [m].",
             *([f"# Parts of {title} left out as set ({setting}): {', '.join(dropped)}."] if dropped else []),
             f"name = {json.dumps(title)}", ""]
    for pid in sorted(derived.parts):
        role = "base" if pid == derived.base else "peg" if pid in pegs else roles.get(pid, "part")
        lines += [f"[parts.{pid}]", f"name = {json.dumps(settings.names.get(pid, derived.parts[pid].name))}",
                  f'role = "{role}"']
        x, y = settings.trays[pid]
        lines.append(f"start = [{_q(x)}, {_q(y)}]")
        if section_kind(pegs.get(pid)) is not None:
            lines.append(f'shape = "{section_kind(pegs.get(pid))}"')
        lines.append("")
    for hid, fit in [*derived.holes.items(), *derived.part_holes.items()]:
        name = f"hole of {fit.part}" if fit.part else f"hole {hid}"
        x, y, _ = entry_point(fit)
        if fit.owner is not None:
            name = f"hole of {fit.owner} ({' '.join(fit.occupants)} in it)"
        lines += [f"[holes.{hid}]", f'name = "{name}"', f'shape = "{fit.hole.kind}"',
                  f"position = [{_q(x)}, {_q(y)}]"]
        # a stack in a hole of the base (bearings and a spacer in a housing's bore)
        lines += [f"capacity = {len(fit.occupants)}"] if fit.owner is None and len(fit.occupants) > 1 else []
        # passed on the way into a hole of the base: one place with it (HoleEntry.on_line)
        lines += [f'on_line = "{fit.line}"', f'owner = "{fit.owner}"'] if fit.line is not None else []
        lines.append("")
    for pin_id, pin in derived.pins.items():
        onto = f" ({' '.join(pin.parts)} onto it)" if pin.parts else ""
        x, y, _ = pin_entry(derived, pin)
        lines += [f"[holes.{pin_id}]", f'name = "pin of {pin.owner}{onto}"',
                  f'shape = "{pin.section.kind}"', f"position = [{_q(x)}, {_q(y)}]"]
        lines += [f"capacity = {len(pin.parts)}"] if len(pin.parts) > 1 else []
        lines.append("")
    return "\n".join(lines)
