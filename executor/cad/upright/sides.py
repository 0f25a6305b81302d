"""The product lying on its side or upside down, read from its base's features and the
parts' boxes (docs/import.md, "The up axis"): :func:`lying`."""

from __future__ import annotations

import numpy as np

from executor.cad.derive import Derived
from executor.cad.upright.gravity import mm as _mm

STANDING = 3.0
"""A base at least this many times as tall (along z) as it is thick along a horizontal
axis stands on its edge (:func:`lying`)."""
ONE_SIDED = 0.25
"""The other parts stand out of the base's box along one way only when along each of the
five other ways (the opposite one, the four across) they stand out of it by at most this
fraction of that way's, and lie within its box when they stand out of it by at most this
fraction of its thickness (:func:`lying`): parts set on one face of the base."""

def lying(derived: Derived) -> tuple[str, list[str]] | None:
    """Why the product looks drawn with another axis than z up by its base's features and
    the parts' boxes, and the ups (``"+y"``, ...) that suggests, best first; None when it
    does not.

    Drawn with x or y up (a tilt is found before deriving, :func:`executor.cad.upright.drawn_tilted`): the
    base is thinnest along that axis, more than half of its holes and pins open along it
    (either way: a through hole's parts leave both ways; where the base has none, the
    product's: the holes of the other parts and their pins), and the base stands on its
    edge (:data:`STANDING` times as tall as it is thick along that axis) or the other
    parts are set on one face of it along that axis (:func:`_one_face`). Drawn upside down
    (z down): more than half of those holes and pins open along z and the other parts are
    set on the base's bottom face (:func:`_one_face` along -z), or the other parts stand
    out of the base's box above it by at most :data:`ONE_SIDED` of what they do below it
    and every hole and pin along z is left downwards, or they do stand out below it and
    more of them leave the product downwards than upwards (their removal directions); not
    when every hole and pin along z is left upwards and so is every part along z, the base
    keeping each from going down (screws through the base from above, their heads on it,
    their shanks standing out under it into a part not drawn; a peg through a through hole
    can leave either way). The
    way up it suggests is the one the other parts stand out of the base's box farther
    along, else the way they leave its holes and pins (both where neither tells)."""
    low, high = derived.parts[derived.base].mesh.bounds
    extents = high - low
    removals = [fit.axis for fit in derived.holes.values()]
    removals += [pin.axis for pin in derived.pins.values() if pin.owner == derived.base]
    whose = "its"
    if not removals:
        removals = [fit.axis for fit in derived.part_holes.values()] + [pin.axis for pin in derived.pins.values()]
        whose = "the product's"
    openings = [axis[1] for axis in removals]
    corners = np.vstack([part.mesh.bounds for part in derived.parts.values()])
    out = np.array([[corners[:, j].max() - high[j], low[j] - corners[:, j].min()] for j in range(3)])
    for k, name in enumerate("xyz"):
        along = openings.count(name)
        if 2 * along <= len(openings) or (name != "z" and extents[k] > min(extents)):
            continue
        features = f" and {along} of {whose} {len(openings)} holes and pins open along {name}"
        if whose != "its":
            features = f", has no holes or pins,{features}"
        leave = sorted({axis[0] for axis in removals if axis[1] == name})
        face = _one_face(out, k, leave, float(extents[k]))
        if name == "z":
            above, below = (float(v) for v in out[2])
            ways = list(derived.axis.values())
            down, up = ways.count("-z"), ways.count("+z")
            if (face is None or face[0] != ["-"]) and above <= ONE_SIDED * below:
                if leave == ["-"]:
                    face = ["-"], f", all of them left along -z and the other parts at most {_mm(above)} mm above it"
                elif down > up and below > 0:
                    face = ["-"], (f", {down} of the other parts left along -z ({up} along +z) and standing out of "
                                   f"it {_mm(below)} mm below it, {_mm(above)} mm above it")
            held = all(derived.base in derived.blockers.get((pid, "-z"), set())
                       for pid, way in derived.axis.items() if way == "+z")
            if face is None or face[0] != ["-"] or (leave == ["+"] and up > 0 and down == 0 and held):
                continue  # parts through it from above standing out under it (screws into what is not drawn)
            return f"the base {derived.base} is {_mm(float(extents[2]))} mm tall{features}{face[1]}", ["-z"]
        if extents[2] >= STANDING * extents[k]:
            above, below = out[k]
            ways = ["+"] if above > below else ["-"] if below > above else leave if len(leave) == 1 else ["+", "-"]
            why = "" if len(ways) > 1 else f", the other parts standing out of it along {ways[0]}{name}" \
                if above != below else f", all of them left along {ways[0]}{name}"
        elif face is not None:
            ways, why = face
        else:
            continue
        return (f"the base {derived.base} is thinnest along {name} ({_mm(float(extents[k]))} mm, "
                f"{_mm(float(extents[2]))} mm tall){features}{why}", [f"{way}{name}" for way in ways])
    return None


def _one_face(out: np.ndarray, k: int, leave: list[str], thickness: float) -> tuple[list[str], str] | None:
    """The way (``["+"]`` or ``["-"]``) of axis ``k`` the other parts are set on the base
    from, and the words saying why, or None. ``out`` [m], (3, 2): how far they stand out of
    the base's box along +x, -x, +y, ...; they stand out of it along one way of ``k``, along
    the opposite way by at most :data:`ONE_SIDED` of that and across by at most that, or
    they lie within :data:`ONE_SIDED` of its ``thickness`` [m] along ``k`` of its box and
    every hole and pin along ``k`` is left the same way (``leave``: the ways they are left)."""
    name = "xyz"[k]
    above, below = (float(v) for v in out[k])
    way, farthest, opposite = ("+", above, below) if above >= below else ("-", below, above)
    across = float(np.delete(out, k, axis=0).max())
    if farthest > 0 and opposite <= ONE_SIDED * farthest and across <= farthest:
        return [way], (f", the other parts standing out of it along {way}{name} ({_mm(farthest)} mm; at most "
                       f"{_mm(opposite)} mm the other way and {_mm(across)} mm across)")
    if len(leave) == 1 and float(out.max()) <= ONE_SIDED * thickness:
        return leave, (f", all of them left along {leave[0]}{name} and the other parts within "
                       f"{_mm(float(out.max()))} mm of its box")
    return None




def from_below(derived: Derived) -> tuple[str, list[str]] | None:
    """Why the product looks drawn upside down by how its parts go in, and the up that
    suggests (``["-z"]``); None when it does not: every other part goes in from below,
    leaving the product along -z only (its way up blocked). Assumed: a product drawn with
    its up has a part at least that goes in from above or sideways (one assembled wholly
    from below, a table's legs screwed into its top from under it, is refused: state ``up``)."""
    others = [pid for pid in derived.parts if pid != derived.base]
    if not others or any(derived.axis.get(pid) != "-z" or not derived.blockers.get((pid, "+z")) for pid in others):
        return None
    return (f"every one of the {len(others)} other parts goes in from below (leaves the product along -z only)",
            ["-z"])
