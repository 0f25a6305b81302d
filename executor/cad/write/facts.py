"""The product's facts for the planner, clingo symbols written as text:

- ``sizes.lp`` (:func:`sizes_text`): ``fits(P,H)`` for every peg and hole whose nominal
  sections pass, and every part with a bore and pin when the pin's section passes the bore's
  (:func:`executor.cad.operations.rooms.margins`), or when they are a nominal zero-clearance
  fit (:data:`RULE`, named in a comment), or when the sweep admits them
  (:func:`executor.cad.derive.swept_fits`: a taper in its taper), closed world;
- ``nominal_sizes.lp`` (:func:`nominal_text`): ``nominal_margin(P,H,M)``, the room M [µm] of
  each peg's nominal section in each hole's (0: a nominal zero-clearance fit), the input of
  ``sizes learn --prior cad``;
- ``geometric_precedence.lp`` (:func:`precedence_text`): ``part/1`` and ``must_precede/2``
  (transitively closed) from the disassembly, the features and the rules of placing, each
  direct pair's reason in a comment (:data:`REASONS`), the input of ``precedence learn
  --prior`` and ``precedence count``;
- ``cell_order.lp`` (:func:`cell_order_text`): ``cell_before(P,Q)`` where the fingers' grip of
  peg P needs it in before part Q, the cell's own orders every plan of the product honours.
"""

from __future__ import annotations

import clingo
import networkx as nx

from executor.cad.derive import Derived
from executor.cad.operations.precedence import order
from executor.cad.operations.rooms import margins, nominal_fits
from executor.cad.operations.tools import finger_order_text, finger_orders


def _symbols(symbols: list[clingo.Symbol]) -> str:
    return " ".join(f"{symbol}." for symbol in symbols)


def sizes_text(derived: Derived) -> str:
    """``sizes.lp``: ``fits(P,H)`` for every peg whose nominal section passes a hole's
    (:func:`executor.cad.operations.rooms.margins`) or is a nominal zero-clearance fit in it
    (:func:`executor.cad.operations.rooms.nominal_fits`, named in a comment as the assumption it is)."""
    rooms, nominal = margins(derived), nominal_fits(derived)
    lines = ["% Which part fits which hole from the nominal cross-sections (closed world), by ./run.sh import.",
             *_nominal_comments(nominal),
             _symbols([clingo.Function("part", [clingo.Function(p)]) for p in rooms]),
             _symbols([clingo.Function("hole", [clingo.Function(h)])
                       for h in [*derived.holes, *derived.part_holes, *derived.pins]])]
    for pid, holes in rooms.items():
        fits = [clingo.Function("fits", [clingo.Function(pid), clingo.Function(hid)]) for hid, room in holes.items()
                if room > 0 or (pid, hid) in nominal]
        if fits:
            lines.append(_symbols(fits))
    return "\n".join(lines) + "\n"


RULE = ("a round peg at least as wide as a round hole's inscribed circle, their vertex circles' radii within 10 {um}, "
        "or a peg and hole of a polygon section (or both rect or square) that pass with an overlap of at most "
        "0.5 {um} all round, or a round section and a polygon whose edges its vertex circle crosses are chords of "
        "it (their ends on it within 10 {um}, at most 35 deg apart), "
        "is taken for one nominal section: a fit, room 0")
"""The stated assumption of nominal zero-clearance fits ({um}: the micrometre's symbol)."""


def nominal_assumption(derived: Derived) -> list[str]:
    """The assumption of the nominal zero-clearance fits, as ``import`` prints it (none without one)."""
    nominal = nominal_fits(derived)
    return [f"nominal zero-clearance fits: {RULE.format(um='µm')} ({len(nominal)} pairs, vertex circles up to "
            f"{1e6 * max(map(abs, nominal.values())):.1f} µm apart)"] if nominal else []


def _nominal_comments(nominal: dict[tuple[str, str], float]) -> list[str]:
    """``sizes.lp``'s and ``nominal_sizes.lp``'s comment naming the nominal zero-clearance fits."""
    if not nominal:
        return []
    return [f"% Assumed: {RULE.format(um='um')}: "
            + ", ".join(f"{p}->{h} ({round(1e6 * t, 1) + 0.0:+.1f} um)" for (p, h), t in nominal.items()) + "."]


def nominal_text(derived: Derived) -> str:
    """``nominal_margin(P,H,M)``: the room [µm, rounded] of each peg in each hole
    (:func:`executor.cad.operations.rooms.margins`)."""
    lines = ["% The nominal room of every peg in every hole [um] (negative: it does not pass), by ./run.sh import;",
             "% the input of sizes learn --prior cad.", *_nominal_comments(nominal_fits(derived))]
    for pid, rooms in margins(derived).items():
        lines.append(_symbols([clingo.Function("nominal_margin", [
            clingo.Function(pid), clingo.Function(hid), clingo.Number(round(1e6 * room))])
            for hid, room in rooms.items()]))
    return "\n".join(lines) + "\n"


REASONS = {
    "blocks": "A cannot go in once B is there (B, or parts always placed before B, block each way the base leaves A)",
    "base": "A is the base and B touches it",
    "feature": "B goes into or onto a feature of A (a hole, a pin): the cell inserts it there, so A is in place "
               "first (the insertion's precondition, not the blocking's)",
    "supports": "B rests on A and not on the base (the support rule, an assumption of the import)",
    "locates": "A alone keeps B from moving sideways (the locating rule, an assumption of the import)",
}
"""Why a pair of ``geometric_precedence.lp`` holds, as its comments say."""


def precedence_text(derived: Derived) -> str:
    """``geometric_precedence.lp``: its pairs with their reasons (comments), ``part/1`` and
    the closed ``must_precede/2``."""
    closure = sorted(nx.transitive_closure_dag(order(derived)).edges)
    used = [reason for reason in REASONS if reason in derived.reasons.values()]
    lines = ["% Geometric precedence by disassembly (./run.sh import), transitively closed: must_precede(A,B) when",
             *(f"% {reason}: {REASONS[reason]}" + (";" if k + 1 < len(used) else ".") for k, reason in enumerate(used)),
             *(f"% {a}->{b}: {reason}" for (a, b), reason in sorted(derived.reasons.items())),
             _symbols([clingo.Function("part", [clingo.Function(p)]) for p in sorted(derived.parts)])]
    lines += [_symbols([clingo.Function("must_precede", [clingo.Function(a), clingo.Function(b)])])
              for a, b in closure]
    return "\n".join(lines) + "\n"


def cell_order_text(cell: Derived) -> str | None:
    """``cell_order.lp``: ``cell_before(P,Q)`` for each order the fingers' grip needs
    (:func:`executor.cad.operations.tools.finger_orders`), each with its reason in a comment;
    None where there is none. The cell's own constraint, not the product's precedence."""
    orders = finger_orders(cell)
    if not orders:
        return None
    lines = ["% The cell's own orders (./run.sh import): cell_before(P,Q) when the fingers hold peg P so deep",
             "% that part Q, in place before it, would meet them (P must go in before Q). Not the product's",
             "% precedence: the plans of this product honour them (plan --assembly, session, assemble).",
             *(f"% {finger_order_text(order)}" for order in orders)]
    lines += [_symbols([clingo.Function("cell_before", [clingo.Function(p), clingo.Function(q)])])
              for p, q, _, _ in orders]
    return "\n".join(lines) + "\n"
