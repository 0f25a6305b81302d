"""Rectangular cross-sections: the ``passes`` rules, the plate mesh of a turned
rect hole measured from its vertices, the tool yaw that aligns a part, the yaw error of
the vision, the parts' ``shape``/``section`` of ``assembly.toml``, and the task board's
``sizes.lp`` that the geometry writes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bridge.assembly import load_assembly
from bridge.cell_settings import Magnitudes
from executor.world.arm import quat_to_matrix, tool_quat, turn_quats_z, turn_z
from executor.world.frames import aligned_yaw
from executor.world.geometry import (
    HoleSpec,
    PartSpec,
    feature_passes,
    load_geometry,
    part_urdf_text,
    passes,
    plate_obj_text,
    sizes_lp_text,
)
from executor.world.perturbation import CellBias


def _peg(kind: str, a: float, b: float = 0.0) -> PartSpec:
    return PartSpec("q", kind, a, shape="q", length=0.05, mass=0.05, start=(0.0, 0.0), demo_hole="h", width=b)


def _hole(kind: str, a: float, b: float = 0.0, yaw: float = 0.0) -> HoleSpec:
    return HoleSpec("h", kind, a, (0.0, 0.0), yaw=yaw, width=b, top_z=0.1, depth=0.025)


def test_a_rect_passes_a_rect_when_aligned_long_side_along_long_side() -> None:
    peg = _peg("rect", 0.012, 0.008)
    assert passes(peg, _hole("rect", 0.0123, 0.0083))
    assert passes(peg, _hole("rect", 0.0163, 0.0103))
    assert not passes(peg, _hole("rect", 0.0119, 0.0103))  # the long side is too long
    assert not passes(peg, _hole("rect", 0.0163, 0.0079))  # the short side is too long
    assert not passes(peg, _hole("rect", 0.0123, 0.0080))  # no clearance is no fit
    assert passes(peg, _hole("rect", 0.0123, 0.0083, yaw=math.radians(30)))  # the skill aligns the yaw


def test_a_rect_passes_a_round_hole_by_its_diagonal_and_a_round_peg_a_rect_by_its_short_side() -> None:
    peg = _peg("rect", 0.012, 0.008)  # diagonal 14.42 mm
    assert passes(peg, _hole("round", 0.0145))
    assert not passes(peg, _hole("round", 0.0144))
    round_peg = _peg("round", 0.008)
    assert passes(round_peg, _hole("rect", 0.0123, 0.0083))
    assert not passes(round_peg, _hole("rect", 0.0163, 0.0079))
    assert passes(round_peg, _hole("square", 0.0081))


def test_a_section_s_circumradius_is_half_the_narrowest_round_hole_it_passes() -> None:
    # The reach the hole search measures a placed part over the hole within, and the
    # centring probes' reach on a pin: a round, a rect and a polygon (a right triangle
    # whose farthest vertex is 13 mm from its frame's origin).
    triangle = PartSpec("q", "polygon", 0.017, shape="q", length=0.05, mass=0.05, start=(0.0, 0.0),
                        demo_hole="h", width=0.012, outline=((-0.005, -0.012), (0.012, 0.0), (-0.005, 0.0)))
    for peg, radius in ((_peg("round", 0.008), 0.004), (_peg("rect", 0.012, 0.008), math.hypot(6, 4) / 1000),
                        (triangle, 0.013)):
        assert peg.circumradius == pytest.approx(radius, abs=1e-12)
    for peg in (_peg("round", 0.008), _peg("rect", 0.012, 0.008)):
        assert passes(peg, _hole("round", 2 * peg.circumradius + 1e-5))
        assert not passes(peg, _hole("round", 2 * peg.circumradius - 1e-5))


def test_room_0_passes_only_a_part_the_hole_states_a_zero_clearance_fit_with_and_never_an_interference() -> None:
    stated = HoleSpec("h", "round", 0.01, (0.0, 0.0), top_z=0.1, depth=0.025, zero_clearance=("q",))
    assert feature_passes(_peg("round", 0.01), stated)  # room 0, stated
    assert not feature_passes(_peg("round", 0.01), _hole("round", 0.01))  # room 0, not stated
    assert not feature_passes(_peg("round", 0.0100001), stated)  # 0.1 um of interference
    assert feature_passes(_peg("round", 0.0099), _hole("round", 0.01))


def test_a_square_is_a_rect_with_equal_sides() -> None:
    square = _peg("square", 0.010)
    as_rect = _peg("rect", 0.010, 0.010)
    for hole in (_hole("round", 0.0142), _hole("round", 0.0141), _hole("square", 0.0101), _hole("square", 0.0099),
                 _hole("rect", 0.0123, 0.0101), _hole("rect", 0.0123, 0.0099)):
        assert passes(square, hole) == passes(as_rect, hole), hole
    assert passes(_peg("rect", 0.012, 0.008), _hole("square", 0.0121))  # a rect in a square: its long side


def _boss_vertices(text: str, hole: str) -> np.ndarray:
    """The vertices (N, 3) [m] of ``o boss_<hole>`` in a plate OBJ."""
    out, inside = [], False
    for line in text.splitlines():
        if line.startswith("o "):
            inside = line == f"o boss_{hole}"
        elif inside and line.startswith("v "):
            out.append([float(v) for v in line.split()[1:]])
    return np.array(out)


@pytest.mark.parametrize("hole", ["slot8", "slot12", "slot16"])
def test_the_mesh_of_a_turned_rect_hole_has_its_sides_and_yaw(hole: str) -> None:
    """Measured from the generated vertices: the wall at the bottom and the chamfer's
    mouth at the top are rectangles of the hole's sides (mouth: + 2 × chamfer) along the
    hole's turned axes, their corners among the vertices; the boss is turned with them."""
    geometry = load_geometry("taskboard")
    spec, plate = geometry.holes[hole], geometry.plate
    a, b = spec.sides
    tile, chamfer = plate.tile_size, plate.chamfer
    top, bottom = plate.top_z, plate.top_z - plate.tile_thickness
    vertices = _boss_vertices(plate_obj_text(geometry), hole)
    local = turn_z(vertices - np.array([*spec.position, 0.0]), -spec.yaw)  # in the hole's frame
    boss = np.max(np.abs(local[:, :2]), axis=1) > tile / 2 - 1e-5
    assert np.allclose(np.max(np.abs(local[boss, :2]), axis=0), tile / 2, atol=2e-6)
    for z, (half_a, half_b) in ((bottom, (a / 2, b / 2)), (top, (a / 2 + chamfer, b / 2 + chamfer))):
        ring = local[~boss & np.isclose(local[:, 2], z, atol=1e-7), :2]
        assert ring.size
        # every point on the rectangle's boundary, its extents the half sides, its corners present
        assert np.allclose(np.max(np.abs(ring) / [half_a, half_b], axis=1), 1.0, atol=1e-3)
        assert np.allclose(np.max(np.abs(ring), axis=0), [half_a, half_b], atol=2e-6)
        assert np.min(np.linalg.norm(np.abs(ring) - [half_a, half_b], axis=1)) < 2e-6
    if spec.yaw:  # in the cell's frame the wall's extents are not the sides: the hole is turned
        wall = vertices[~boss & np.isclose(vertices[:, 2], bottom, atol=1e-7), :2] - spec.position
        assert not np.allclose(np.max(np.abs(wall), axis=0), [a / 2, b / 2], atol=1e-4)


def test_a_rect_peg_is_a_box_of_its_sides() -> None:
    geometry = load_geometry("taskboard")
    assert '<box size="0.016000 0.010000 0.050000"/>' in part_urdf_text(geometry.parts["rect16"])
    assert '<box size="0.004000 0.004000 0.050000"/>' in part_urdf_text(geometry.parts["rect4"])


def test_the_tool_yaw_aligns_the_part_by_the_pairs_symmetry() -> None:
    deg = math.radians
    assert aligned_yaw("rect", "rect", deg(-45)) == pytest.approx(deg(-45))
    assert aligned_yaw("rect", "rect", deg(120)) == pytest.approx(deg(-60))  # half a turn is the same slot
    assert aligned_yaw("square", "rect", deg(60)) == pytest.approx(deg(-30))  # a square: a quarter turn
    assert aligned_yaw("round", "rect", deg(30)) == 0.0 and aligned_yaw("rect", "round", deg(30)) == 0.0
    assert aligned_yaw("square", "square", 0.0) == 0.0
    for yaw in (deg(30), deg(-45), deg(90)):
        x_axis = quat_to_matrix(tool_quat(yaw))[:, 0]  # the held part's x axis
        assert np.allclose(x_axis, [math.cos(yaw), math.sin(yaw), 0.0])
    quats = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    assert np.allclose(turn_quats_z(turn_quats_z(quats, 0.7), -0.7), quats)
    assert turn_quats_z(quats, 0.0) is quats and np.array_equal(tool_quat(0.0), [1.0, 0.0, 0.0, 0.0])


def test_the_yaw_error_of_the_vision_is_bias_plus_noise_and_leaves_the_other_draws_alone() -> None:
    model = Magnitudes()
    bias = CellBias(model, 3)
    limit = math.radians(model.vision_yaw_max)
    yaws = []
    for seed in range(200):
        plain = bias.draw(np.random.default_rng(seed), "rect16", "slot16")
        turned = bias.draw(np.random.default_rng(seed), "rect16", "slot16", oriented=True)
        assert plain.vision_yaw == 0.0
        assert np.array_equal(plain.vision_error, turned.vision_error) and plain.search_seed == turned.search_seed
        yaws.append(turned.vision_yaw)
    yaws_deg = np.degrees(yaws)
    assert np.max(np.abs(yaws)) <= limit + 1e-12
    assert abs(np.mean(yaws_deg) - math.degrees(bias.yaw_of_hole("slot16"))) < 0.15
    assert abs(np.degrees(bias.yaw_of_hole("slot16"))) <= model.vision_yaw_bias
    assert 0.35 < np.std(yaws_deg) < 0.65  # σ 0.5°


def test_parts_carry_their_shape_and_section() -> None:
    parts = {p.id: p for p in load_assembly("taskboard").parts}
    assert (parts["round8"].shape, parts["round8"].section) == ("round", "round")
    assert (parts["rect4"].shape, parts["rect4"].section) == ("square", "square")
    assert (parts["rect12"].shape, parts["rect12"].section) == ("rect", "rect12")  # its own by default
    assert (parts["base"].shape, parts["base"].section) == (None, None)
    geometry = load_geometry("taskboard")
    assert all(geometry.parts[p].kind == parts[p].shape for p in geometry.parts)
    cranfield = {p.id: p for p in load_assembly("cranfield").parts}
    assert (cranfield["p3"].shape, cranfield["bp"].shape) == ("square", None)
    assert all(load_geometry("cranfield").parts[p].kind == cranfield[p].shape for p in ("p1", "p3", "sh"))


def test_the_taskboard_sizes_lp_is_what_its_geometry_makes(root) -> None:
    assert (root / "data/taskboard/sizes.lp").read_text() == sizes_lp_text("taskboard")


def test_the_taskboard_is_no_biorder_and_each_peg_fits_its_own_hole() -> None:
    geometry = load_geometry("taskboard")
    parts, holes = geometry.parts, geometry.holes
    for size in (4, 8, 12, 16):
        assert passes(parts[f"round{size}"], holes[f"hole{size}"])
        assert passes(parts[f"rect{size}"], holes[f"slot{size}"])
        for pid, hid in ((f"round{size}", f"hole{size}"), (f"rect{size}", f"slot{size}")):
            gaps = np.subtract(holes[hid].sides, parts[pid].sides)
            assert np.allclose(gaps, 0.0003, atol=1e-9), (pid, hid)
    # Ferrers' condition fails: round12 fits hole12, rect12 fits slot12, neither the other's.
    assert not passes(parts["round12"], holes["slot12"]) and not passes(parts["rect12"], holes["hole12"])
