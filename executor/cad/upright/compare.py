"""A product as read compared with its readings with the other ups that no rule doubts
(docs/import.md, "The up axis"): it looks drawn with another up where one of them holds
its parts, stands or rests its base on the floor where it does not (:func:`compared`).

Assumed: a product drawn with its up holds every part where it is drawn, stands on the
floor by itself and rests its base on the floor, wherever another up, its reading doubted
by no rule, would (a product may be drawn with a part free to drop, or balancing on the
parts under its base, where no other up does better)."""

from __future__ import annotations

from executor.cad.derive import Derived
from executor.cad.upright.gravity import Stance, mm, raised

TIE = 1.0
"""[deg] a base off the floor is doubted where another up rests it there more than this
steadier (:func:`compared`); ups whose readings stand within this of the steadiest one's
tipping angle are named together (:func:`executor.cad.upright.drawn_up`)."""


def compared(derived: Derived, stance: Stance, others: dict[str, Stance]) -> tuple[str, list[str]] | None:
    """Why the product read as ``derived`` (its ``stance``, :func:`executor.cad.upright.gravity.stance`)
    looks drawn with another up, and the ups of ``others`` (the stances of its readings with
    other ups that no rule doubts) that hold where it does not; None where none does. The
    first that holds of:

    - some of its parts would drop (:func:`executor.cad.upright.gravity.dropping`), and with
      those ups none would;
    - its base rests on the floor (the cell holds it) and the product would fall over (its
      centre of mass outside what it stands on by more than
      :data:`executor.cad.upright.gravity.TIPPED`), and with those ups it stands by itself
      and none of its parts would drop;
    - its base stands off the floor on the parts under it, and those ups rest it on the
      floor standing steadier by more than :data:`TIE` (steadiest first)."""
    if stance.drops:
        ups = [up for up, other in others.items() if not other.drops]
        if ups:
            return (f"{', '.join(stance.drops)} would drop: free to go down and above the floor, no part under "
                    f"{'them' if len(stance.drops) > 1 else 'it'} keeping {'them' if len(stance.drops) > 1 else 'it'}"
                    f" up, where {len(ups)} other up(s) would hold every part", ups)
    if stance.resting and not stance.stands:
        ups = [up for up, other in others.items() if other.stands and not other.drops]
        if ups:
            return (f"the product's centre of mass lies {mm(stance.outside)} mm outside what it stands on "
                    f"({-stance.angle:.1f} deg past its edge): it would fall over but for its base held on the floor, "
                    f"where {len(ups)} other up(s) would stand it by itself", ups)
    if not stance.resting:
        steadier = {up: other.angle for up, other in others.items() if other.resting}
        ups = sorted((up for up, steady in steadier.items() if steady > stance.angle + TIE),
                     key=lambda up: -steadier[up])
        if ups:
            return (f"the base {derived.base} stands {mm(raised(derived))} mm above the product's lowest point on the "
                    f"parts under it, the product {stance.angle:.1f} deg from tipping over, where {len(ups)} other "
                    f"up(s) would rest the base on the floor steadier (up to {steadier[ups[0]]:.1f} deg)", ups)
    return None
