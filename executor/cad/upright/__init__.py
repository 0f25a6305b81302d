"""Whether a product read with the CAD's +z up looks drawn with another axis up
(docs/import.md, "The up axis"): tilted (:func:`drawn_tilted`, before deriving), lying on its
side or upside down, or unable to rest on the floor as read (:func:`drawn_up`, after
deriving), and the up to set."""

from __future__ import annotations

import math

import numpy as np
import trimesh

from executor.cad.derive import Derived
from executor.cad.upright.compare import TIE, compared
from executor.cad.upright.gravity import Stance, base_unheld, falls_over, stance, turned_facts
from executor.cad.upright.sides import from_below, lying

TILT = 1.0
"""The base's largest flat faces are tilted when their normal lies more than this [deg]
from the z axis and from the horizontal plane (:func:`drawn_tilted`): no quarter turn sets them square."""
TILTED_SHARE = 0.15
"""...and they make at least this fraction of its surface (:func:`drawn_tilted`): not one
strip of a coarsely tessellated rod (a 24-gon's pair of opposite facets: 8 %)."""
STANDING_SHARE = 0.5
"""...unless its horizontal faces (within :data:`TILT`) make at least this fraction of the
area of those largest faces, one of them at its lowest point, facing down (:func:`drawn_tilted`):
a coarse prism lying on a face (a hexagonal or octagonal bar: its horizontal pair as large
as each tilted pair, less its holes) stands on it as drawn, where a product tilted by
another angle than quarter turns rests on an edge or a corner, unless a face of its base
lies at that angle."""
NAMING = ("+y", "+x", "-x", "-y", "-z")
"""The order the ups named are listed in where the preferences of :func:`drawn_up` leave
several (after the rule's suggestion): +y first, the up of SolidWorks, Fusion 360,
Inventor and glTF, the commonest other than z; then those of
:data:`executor.cad.parts.UP_AXES`. A prior on how CAD is drawn, not a measure: the ups
left are those whose readings no rule tells apart (a horizontal unit turned about its
shaft)."""
FLOOR = 1e-6
"""[m] how far above the base's lowest point a face it stands on may start (:func:`drawn_tilted`)."""
def drawn_up(derived: Derived) -> str | None:
    """Why the product looks drawn with another axis than z up, and the up to set; None
    when it does not. Doubted (:func:`_doubt`): its base's features and the parts' boxes
    say it lies on its side or upside down (:func:`executor.cad.upright.sides.lying`), or
    it is assembled wholly from below (:func:`executor.cad.upright.sides.from_below`), or
    read as drawn it would fall over (:func:`executor.cad.upright.gravity.falls_over`) or
    its base would slide down the parts under it
    (:func:`executor.cad.upright.gravity.base_unheld`); or, compared with its readings with
    the other ups that are not doubted
    (:func:`executor.cad.upright.gravity.turned_facts`), one of them holds its parts, stands
    it or rests its base on the floor where it does not
    (:func:`executor.cad.upright.compare.compared`). The ups named are those whose readings
    are not doubted and hold as well as the others (no other doubts them by
    :func:`executor.cad.upright.compare.compared`; where each is doubted so, all those not
    doubted), narrowed in turn, where that leaves some and drops some, to those that rest
    the base on the floor (:func:`executor.cad.upright.gravity.resting`), that the rule
    suggests, that lay its largest flat faces level (:func:`largest_faces`) and that stand
    steadiest (their tipping angles, :func:`executor.cad.upright.gravity.tipping`, within
    :data:`TIE` of the steadiest's); the rule's first, then in the order of :data:`NAMING`;
    where no reading is undoubted, the rule's (a
    gravity rule, which suggests none, then refuses nothing)."""
    found = _doubt(derived)
    own = stance(derived)
    if found is None and own.resting and own.stands and not own.drops:
        return None
    readings = {up: turned_facts(derived, up) for up in NAMING}
    refused = {up: _doubt(reading) for up, reading in readings.items()}
    undoubted = [up for up in NAMING if refused[up] is None]
    stances = {up: stance(readings[up]) for up in undoubted}
    found = found or compared(derived, own, stances)
    if found is None:
        return None
    why, suggested = found
    if not suggested and not undoubted:
        return None  # a gravity rule names no up of its own: it refuses only where another up reads it undoubted
    holding = [up for up in undoubted
               if compared(readings[up], stances[up], {o: s for o, s in stances.items() if o != up}) is None]
    ups, chosen = _narrowed(holding or undoubted, readings, stances, suggested)
    ups = sorted(ups, key=lambda up: up not in suggested)
    for up in suggested:
        doubt = refused[up]
        if doubt is not None:
            why += f"; read with up = \"{up}\" it would be doubted too ({doubt[0]})"
            break
    if ups and ups != suggested and chosen:
        why += f"; read with {_listed(ups)} {chosen}"
    return f"{why}: the CAD may be drawn {_described(ups or suggested)}; set up = {_settings(ups or suggested)}" \
        ' (up = "+z" or --up +z if z is up)'


def _narrowed(ups: list[str], readings: dict[str, Derived], stances: dict[str, Stance],
              suggested: list[str]) -> tuple[list[str], str]:
    """The ``ups`` whose ``readings`` (their ``stances``) are not doubted narrowed by the
    preferences of :func:`drawn_up` (each where it leaves some and drops some), and the
    words of the last that narrowed them ("": none did)."""
    chosen = ""

    def narrow(kept: list[str], words: str) -> None:
        nonlocal ups, chosen
        if kept and len(kept) < len(ups):
            ups, chosen = kept, words

    narrow([up for up in ups if stances[up].resting], "its base resting on the floor")
    narrow([up for up in ups if up in suggested], "as the rule suggests")
    narrow([up for up in ups if _flat(readings[up])], "its base's largest flat faces level")
    best = max((stances[up].angle for up in ups), default=0.0)
    narrow([up for up in ups if stances[up].angle >= best - TIE],
           f"standing steadiest ({best:.1f} deg from tipping over)")
    return ups, chosen


def _listed(ups: list[str]) -> str:
    """``up = "+y"`` or ``up = "+y" or "-y"``."""
    return "up = " + " or ".join(f'"{up}"' for up in ups)


def _flat(derived: Derived) -> bool:
    """Whether the base's largest flat faces (:func:`largest_faces`) lie horizontal, within :data:`TILT`."""
    normal, _ = largest_faces(derived.parts[derived.base].mesh)
    return float(normal[2]) >= math.cos(math.radians(TILT))


def _doubt(derived: Derived) -> tuple[str, list[str]] | None:
    """Why the product read as ``derived`` is doubted and the ups the reason suggests
    (none: the gravity rules suggest none themselves), None when it is not (:func:`drawn_up`)."""
    for features in (lying, from_below):
        found = features(derived)
        if found is not None:
            return found
    for rule in (falls_over, base_unheld):
        why = rule(derived)
        if why is not None:
            return why, []
    return None


def _described(ups: list[str]) -> str:
    """How the CAD may be drawn, by the ``ups`` named: ``y up``, ``upside down (z down)``."""
    if ups == ["-z"]:
        return "upside down (z down)"
    axes = {up[1] for up in ups}
    return f"{axes.pop()} up" if len(axes) == 1 else "with another axis up"


def _settings(ups: list[str]) -> str:
    """The settings naming ``ups``: ``"+y" or --up +y``, ``"+y" or "-y" (--up +y or --up=-y)``."""
    settings = " or ".join(f'"{up}"' for up in ups)
    flags = " or ".join(f"--up {up}" if up[0] == "+" else f"--up={up}" for up in ups)
    return f"{settings} or {flags}" if len(ups) == 1 else f"{settings} ({flags})"


def drawn_tilted(mesh: trimesh.Trimesh, base: str) -> str | None:
    """Why the product whose base ``base`` has ``mesh`` looks drawn tilted, None when it
    does not: the normal that the largest area of the base's faces shares (its largest flat
    faces, normals alike to 0.001, a face and its opposite as one: the normal taken with z
    >= 0) lies more than :data:`TILT` from the z axis and from the horizontal plane, they
    make :data:`TILTED_SHARE` of its surface or more, and the base does not stand on
    horizontal faces (:func:`_standing`)."""
    normal, area = largest_faces(mesh)
    from_z = math.degrees(math.acos(min(1.0, float(normal[2]))))
    if min(from_z, 90.0 - from_z) <= TILT or area < TILTED_SHARE * mesh.area or _standing(mesh, area):
        return None
    facing = ", ".join(f"{v:.3f}" for v in normal + 0.0)
    return (f"the base {base}'s largest flat faces ({100 * area / mesh.area:.0f} % of its surface) face "
            f"({facing}), {from_z:.1f} deg from the z axis: the CAD may be drawn tilted; turn it in the CAD so that "
            'one of its axes points up (up turns by quarter turns only), or set up = "+z" or --up +z to import it as '
            "drawn")


def largest_faces(mesh: trimesh.Trimesh) -> tuple[np.ndarray, float]:
    """The unit normal that the largest area of ``mesh``'s faces shares (normals alike to
    0.001, a face and its opposite as one: the normal taken with z >= 0) and that area [m²]."""
    normals = mesh.face_normals * np.where(mesh.face_normals[:, 2:] < 0, -1.0, 1.0)  # a face's plane: z >= 0
    keys, index = np.unique(np.round(normals, 3) + 0.0, axis=0, return_inverse=True)
    areas = np.bincount(index.ravel(), mesh.area_faces)
    largest = int(np.argmax(areas))
    return keys[largest] / np.linalg.norm(keys[largest]), float(areas[largest])


def _standing(mesh: trimesh.Trimesh, largest: float) -> bool:
    """Whether the base ``mesh`` stands on horizontal faces as drawn: its faces within
    :data:`TILT` of horizontal make :data:`STANDING_SHARE` of ``largest`` [m²] (the area of
    its largest flat faces) or more, and one of them faces down from its lowest point
    (within :data:`FLOOR`)."""
    up = mesh.face_normals[:, 2]
    flat = np.abs(up) >= math.cos(math.radians(TILT))
    low = mesh.vertices[mesh.faces][:, :, 2].min(axis=1) <= mesh.bounds[0][2] + FLOOR
    return float(mesh.area_faces[flat].sum()) >= STANDING_SHARE * largest and bool(np.any(flat & low & (up < 0)))

