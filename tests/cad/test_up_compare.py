"""``import``'s up axis read by comparing the readings with each up: without ``up``, a
product that as read would drop a part, or fall over but for its base held on the floor,
where another up, its reading doubted by no rule, would hold every part or stand it by
itself, is refused naming those ups; the product as drawn is not (docs/import.md, "The up
axis"). The readings are the derived facts turned as each up turns them
(:func:`executor.cad.upright.gravity.turned_facts`, checked against an import with that up
in ``tests/cad/test_up_gravity.py``); derived without the import's writing (its convex
pieces take seconds)."""

from __future__ import annotations

import trimesh

from executor.cad.derive import Derived, derive
from executor.cad.parts import CadPart
from executor.cad.upright import drawn_up
from executor.cad.upright.gravity import dropping, stance, turned_facts


def _box(extents: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    return trimesh.creation.box(extents, trimesh.transformations.translation_matrix(centre))


def _derived(parts: dict[str, trimesh.Trimesh], base: str) -> Derived:
    """What the import derives from ``parts`` (z up, mm) with ``base`` the fixture."""
    return derive([CadPart(pid, pid, mesh.apply_scale(1e-3), f"{pid}.stl") for pid, mesh in parts.items()], base, {})


def _ring(x: float) -> trimesh.Trimesh:
    """A 9 mm wide square bearing, 37 mm outside, its 25.4 mm bore along x, centred at ``x`` on the floor."""
    return _box((9.0, 37.0, 37.0), (x, 0.0, 18.5)).difference(_box((20.0, 25.4, 25.4), (x, 0.0, 18.5)))


def test_a_part_free_to_drop_where_another_up_holds_every_part_is_refused() -> None:
    # z up: a 150 mm rod of 25 mm square section along x with a 30 mm shoulder in its middle,
    # lying 6 mm up on two bearings against the shoulder's faces, one each side, that stand
    # on the floor (asm4_axis_bearings). Drawn x up and read z up, the rod stands on its
    # end, the lower bearing 61 mm above the floor with nothing under it on the rod
    rod = trimesh.boolean.union([_box((150.0, 25.0, 25.0), (75.0, 0.0, 18.5)),
                                 _box((10.0, 30.0, 30.0), (75.0, 0.0, 18.5))], engine="manifold")
    derived = _derived({"rod": rod, "bearing_a": _ring(65.5), "bearing_b": _ring(84.5)}, "rod")
    assert drawn_up(derived) is None
    assert stance(derived).resting is False and dropping(derived) == []
    on_end = turned_facts(derived, "+x")  # the CAD's +x up: the rod's end at x = 0 on the floor
    assert dropping(on_end) == ["bearing_a"]
    why = drawn_up(on_end)
    assert why is not None and why.startswith(
        "bearing_a would drop: free to go down and above the floor, no part under it keeping it up, where 4 other "
        'up(s) would hold every part: the CAD may be drawn with another axis up; set up = "+y" or "+x" or "-x" or '
        '"-y"'), why


def test_a_product_falling_over_on_its_held_base_where_another_up_stands_it_is_refused() -> None:
    # z up: a 40 x 30 x 40 mm block on the floor, a 200 mm bar of 20 mm square section
    # standing on it, its boss in the block's top hole. Drawn x up and read z up, the bar
    # reaches 200 mm sideways from the block's face, 10 mm above the floor, the product's
    # centre of mass beyond the block: it stands only because the cell holds its base (so
    # too read with y up, the block on its other side face)
    block = _box((40.0, 30.0, 40.0), (0.0, 0.0, 20.0)).difference(_box((10.6, 10.6, 30.0), (0.0, 0.0, 40.0)))
    bar = trimesh.boolean.union([_box((20.0, 20.0, 200.0), (0.0, 0.0, 140.0)),
                                 _box((10.0, 10.0, 15.0), (0.0, 0.0, 32.5))], engine="manifold")
    derived = _derived({"block": block, "bar": bar}, "block")
    assert drawn_up(derived) is None
    lying = turned_facts(derived, "-x")  # the CAD's -x up: the bar along +x
    assert stance(lying).resting and not stance(lying).stands and dropping(lying) == []
    why = drawn_up(lying)
    assert why is not None and "it would fall over but for its base held on the floor, where 1 other up(s) would " \
        'stand it by itself: the CAD may be drawn x up; set up = "+x" or --up +x' in why, why


def test_the_up_the_rule_suggests_is_named_before_those_laying_the_base_flat_or_steadier() -> None:
    # z up: a 120 x 30 x 50 mm block, two pegs sunk flush in blind holes from its top
    # (pearl_peg_board). Drawn z down and read z up, the pegs are left downwards out of the
    # block's bottom: upside down. Read y up the block lies on its 120 x 50 mm face, its
    # largest, steadier (59 deg from tipping over, 31 as drawn), its holes opening sideways
    block = _box((120.0, 30.0, 50.0), (0.0, 0.0, 25.0))
    parts = {}
    for k, x in enumerate((-30.0, 30.0)):
        block = block.difference(_box((10.6, 10.6, 30.0), (x, 0.0, 40.0)))
        parts[f"peg{k}"] = _box((10.0, 10.0, 24.8), (x, 0.0, 37.6))
    derived = _derived({"block": block} | parts, "block")
    assert drawn_up(derived) is None
    why = drawn_up(turned_facts(derived, "-z"))
    assert why is not None and why.endswith(
        'all of them left along -z and the other parts within 0.000 mm of its box: the CAD may be drawn upside down '
        '(z down); set up = "-z" or --up=-z (up = "+z" or --up +z if z is up)'), why
