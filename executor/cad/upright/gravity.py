"""Whether a product read with a given up could rest on the floor as assembled
(docs/import.md, "The up axis"): its centre of mass over what it stands on
(:func:`tipping`), its base held up (:func:`base_unheld`), its parts held where they are
drawn (:func:`dropping`), those three as one :class:`Stance`; and the facts of a product
turned as another up reads them (:func:`turned_facts`), to check the up a refusal names.

Assumed: a product drawn with its up stands on the floor by itself as assembled, or rests
its base on the floor, where the cell holds it; its parts of one density; its base rests
on the floor or on parts that keep it from going down, save on parts hanging from it
(screws through it into a fixture not drawn)."""

from __future__ import annotations

import dataclasses
import math
from typing import TypeVar

import numpy as np
import shapely

from executor.cad.derive import Derived
from executor.cad.derive.derived import HoleFit, PinFit
from executor.cad.parts import turn_points
from executor.cad.sweep import DIRECTIONS

CONTACT = 1e-3
"""[m] how far above the product's lowest point a point touches the floor: the parts' points
within it make what the product stands on."""
TIPPED = 2.0
"""[deg] a product whose centre of mass lies outside what it stands on by more than this
angle, seen from the floor (:func:`tipping`), falls over: read with that up, it could not
stand as drawn."""


_Feature = TypeVar("_Feature", HoleFit, PinFit)


def turned_facts(derived: Derived, up: str) -> Derived:
    """The facts of ``derived`` as the import would read them with the CAD's axis ``up``
    turned to +z (:func:`executor.cad.parts.turn_points`): the parts' meshes, the removal
    directions (the parts' axes and their blockers' keys, the holes' and pins' axes) and the
    features' centres turned; ``derived`` is not changed."""
    if up == "+z":
        return derived
    parts = {pid: dataclasses.replace(part, mesh=part.mesh.copy()) for pid, part in derived.parts.items()}
    for pid, part in parts.items():
        part.mesh.vertices = turn_points(np.asarray(derived.parts[pid].mesh.vertices), up)

    def way(name: str) -> str:
        if name not in DIRECTIONS:
            return name  # a tilted fit's own axis: no rule reads it
        image = turn_points(np.array(DIRECTIONS[name]), up)
        k = int(np.argmax(np.abs(image)))
        return ("+" if image[k] > 0 else "-") + "xyz"[k]

    def feature(fit: _Feature) -> _Feature:
        x, y, z = (float(v) for v in turn_points(np.array(fit.centre), up))
        return dataclasses.replace(fit, axis=way(fit.axis), centre=(x, y, z))

    return dataclasses.replace(
        derived, parts=parts, axis={pid: way(name) for pid, name in derived.axis.items()},
        blockers={(pid, way(name)): who for (pid, name), who in derived.blockers.items()},
        holes={hid: feature(fit) for hid, fit in derived.holes.items()},
        part_holes={hid: feature(fit) for hid, fit in derived.part_holes.items()},
        pins={pid: feature(pin) for pid, pin in derived.pins.items()})


def tipping(derived: Derived) -> tuple[float, float]:
    """How the product stands on the floor as read: the angle [deg] from the vertical
    through its centre of mass (the parts' meshes' volumes' centres, one density) to the
    nearest edge of what it stands on (the convex hull of its points within
    :data:`CONTACT` of its lowest), seen from the centre of mass; positive inside, negative
    outside (it falls over); and how far [m] the centre of mass lies outside (0 inside)."""
    meshes = [part.mesh for part in derived.parts.values()]
    volumes = np.array([abs(float(mesh.volume)) for mesh in meshes])
    centre = np.sum([v * np.asarray(mesh.center_mass) for v, mesh in zip(volumes, meshes, strict=True)],
                    axis=0) / volumes.sum()
    lowest = min(float(mesh.bounds[0][2]) for mesh in meshes)
    touching = np.vstack([mesh.vertices[mesh.vertices[:, 2] <= lowest + CONTACT, :2] for mesh in meshes])
    hull = shapely.convex_hull(shapely.multipoints(touching))
    point = shapely.Point(centre[:2])
    inside = hull.geom_type == "Polygon" and bool(hull.covers(point))
    edge = float(hull.exterior.distance(point)) if hull.geom_type == "Polygon" else float(hull.distance(point))
    angle = math.degrees(math.atan2(edge, float(centre[2]) - lowest))
    return (angle, 0.0) if inside else (-angle, edge)


def falls_over(derived: Derived) -> str | None:
    """Why the product as read would fall over (:func:`tipping`: its centre of mass outside
    what it stands on by more than :data:`TIPPED`), None when it stands, or when its base
    rests on the floor (:func:`resting`): the cell holds the base on its table, so a base
    on the floor need not balance, nor the parts reaching out from it (a sub-assembly
    drawn without the frame it is bolted to: a housing plate on a narrow foot, its shaft
    and coupling beyond it)."""
    angle, outside = tipping(derived)
    if angle >= -TIPPED or resting(derived):
        return None
    return (f"the product's centre of mass lies {mm(outside)} mm outside what it stands on ({-angle:.1f} deg "
            "past its edge): it would fall over")


def raised(derived: Derived) -> float:
    """How far [m] the base's lowest point lies above the product's."""
    lowest = min(float(part.mesh.bounds[0][2]) for part in derived.parts.values())
    return float(derived.parts[derived.base].mesh.bounds[0][2]) - lowest


def resting(derived: Derived) -> bool:
    """Whether the base rests on the floor: its lowest point within :data:`CONTACT` of the product's."""
    return raised(derived) <= CONTACT


def base_unheld(derived: Derived) -> str | None:
    """Why the base as read would slide down, None when it would not: its lowest point lies
    more than :data:`CONTACT` above the product's, no other part keeps it from going down
    (it is no blocker of any part going up), and not every part standing under it hangs
    from it (kept by it from going down: screws through it into a fixture not drawn)."""
    meshes = {pid: part.mesh for pid, part in derived.parts.items()}
    base = derived.base
    bottom = float(meshes[base].bounds[0][2])
    above = bottom - min(float(mesh.bounds[0][2]) for mesh in meshes.values())
    if above <= CONTACT or any(base in derived.blockers.get((pid, "+z"), set()) for pid in meshes if pid != base):
        return None
    under = sorted(pid for pid, mesh in meshes.items() if pid != base and float(mesh.bounds[0][2]) < bottom - CONTACT)
    loose = [pid for pid in under if base not in derived.blockers.get((pid, "-z"), set())]
    if not loose:
        return None
    return (f"the base {base} stands {mm(above)} mm above the product's lowest point and no part keeps it from "
            f"going down: it would slide down {', '.join(loose)}")


def dropping(derived: Derived) -> list[str]:
    """The parts that as read would drop (their moving bodies', :attr:`Derived.bodies`):
    free to go down (nothing blocks the body along -z: it leaves the product that way),
    its lowest point more than :data:`CONTACT` above the product's (not on the floor), and
    no part of it in a screwed pair or a press fit with a part outside it (held by its
    thread or its interference, where the model lets it slide)."""
    lowest = min(float(part.mesh.bounds[0][2]) for part in derived.parts.values())
    pairs = [{slide.shaft, slide.bore} for slide in derived.slides if slide.pitch or slide.interference]
    found: list[str] = []
    for root, members in derived.bodies.items():
        bottom = min(float(derived.parts[pid].mesh.bounds[0][2]) for pid in members)
        held = any(pair & members and pair - members for pair in pairs)
        if derived.blockers.get((root, "-z")) or bottom <= lowest + CONTACT or held:
            continue
        found += sorted(members)
    return sorted(found)


@dataclasses.dataclass(frozen=True)
class Stance:
    """How a product as read rests on the floor: its base on it (:func:`resting`), how far
    it stands from tipping over (:func:`tipping`: the angle [deg], negative past its edge,
    and how far [m] its centre of mass lies outside), and its parts that would drop
    (:func:`dropping`)."""

    resting: bool
    angle: float
    outside: float
    drops: tuple[str, ...]

    @property
    def stands(self) -> bool:
        """Whether it stands by itself: its centre of mass outside what it stands on by at most :data:`TIPPED`."""
        return self.angle >= -TIPPED


def stance(derived: Derived) -> Stance:
    """The :class:`Stance` of the product read as ``derived``."""
    angle, outside = tipping(derived)
    return Stance(resting(derived), angle, outside, tuple(dropping(derived)))


def mm(value: float) -> str:
    """Metres as millimetres with 3 decimals (no "-0.000")."""
    millimetres = 1000 * value
    return f"{millimetres if abs(millimetres) >= 5e-4 else 0.0:.3f}"
