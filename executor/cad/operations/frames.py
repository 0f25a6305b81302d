"""The frames of an imported product's features (:class:`executor.cad.derive.Derived`): a hole's
or pin's frame (z out of it along its removal direction, :func:`feature_turn`), a peg's mesh
upright in it, a hole's entry and a pin's free end in the cell frame, a pin's level and a
bored part's frame (its origin the bore's centre at its end nearest the pin's root). Lengths
in metres."""

from __future__ import annotations

import math

import numpy as np
import trimesh

from executor.cad.convex import peg_frame
from executor.cad.derive import Derived, HoleFit, PinFit
from executor.cad.sweep import opposite
from executor.world.frames import hole_rotation


def feature_turn(fit: HoleFit | PinFit) -> np.ndarray:
    """The 4 × 4 rotation from the cell frame to the frame of ``fit``'s hole or pin (z out
    of it, x and y its slice axes: :func:`executor.world.frames.hole_rotation`); the
    identity along z (a hole entered from above or below, a pin parts go down or up onto:
    the slice's axes are the cell's x and y)."""
    turn = np.eye(4)
    if fit.axis in ("+z", "-z"):
        return turn
    turn[:3, :3] = hole_rotation(opposite(fit.axis)).T
    return turn


def upright(derived: Derived, fit: HoleFit) -> trimesh.Trimesh:
    """The mesh of the peg in ``fit`` in its hole's frame (:func:`feature_turn`): its axis along z."""
    assert fit.part is not None
    mesh = derived.parts[fit.part].mesh
    return mesh if fit.axis == "+z" else mesh.copy().apply_transform(feature_turn(fit))


def entry_point(fit: HoleFit) -> tuple[float, float, float]:
    """The centre of a hole's entry in the cell frame [m] (x, y its position, z its ``top_z``;
    ``entry`` is measured along the removal direction: a hole entered from below, removal
    -z, has its entry at z = -``entry``)."""
    if fit.axis in ("+z", "-z"):  # the slice's axes are the cell's x and y (sections.frame_of)
        return fit.centre[0], fit.centre[1], fit.entry if fit.axis == "+z" else -fit.entry
    x, y, z = hole_rotation(opposite(fit.axis)) @ np.array([*fit.hole.centre, fit.entry])
    return float(x), float(y), float(z)


def along_axis(mesh: trimesh.Trimesh, pin: HoleFit | PinFit) -> np.ndarray:
    """The vertices (n, 3) [m] of ``mesh`` in the frame of ``pin`` (:func:`feature_turn`): z along
    its removal direction."""
    return mesh.vertices @ feature_turn(pin)[:3, :3].T


def _pin_top(derived: Derived, pin: PinFit) -> float:
    """A pin's top [m] in its frame (:func:`feature_turn`): its owner's farthest point along the
    pin's removal direction within its section around its axis (a pin parts go down onto:
    its highest)."""
    vertices = along_axis(derived.parts[pin.owner].mesh, pin)
    reach = math.hypot(pin.section.a, pin.section.b) / 2
    near = np.linalg.norm(vertices[:, :2] - pin.section.centre, axis=1) <= reach + 1e-9
    return float(vertices[near, 2].max())


def pin_level(derived: Derived, pin: PinFit) -> tuple[float, float]:
    """A pin's top (:func:`_pin_top`) and its height [m] above the nearest end of the parts
    going onto it (where the first rests, or, on a pin along a horizontal axis, where the
    CAD has it), in the pin's frame."""
    top = _pin_top(derived, pin)
    return top, top - min(float(along_axis(derived.parts[pid].mesh, pin)[:, 2].min()) for pid in pin.parts)


def pin_entry(derived: Derived, pin: PinFit) -> tuple[float, float, float]:
    """The centre of a pin's free end in the cell frame [m] (:func:`_pin_top`): its
    ``position`` (x, y) and, on a pin along a horizontal axis, its ``top_z``."""
    x, y, z = feature_turn(pin)[:3, :3].T @ np.array([*pin.section.centre, _pin_top(derived, pin)])
    return float(x), float(y), float(z)


def bore_frame(derived: Derived, pid: str) -> np.ndarray:
    """The 4 × 4 transform from the cell frame to the part frame of part ``pid`` with a bore:
    turned into its pin's frame (:func:`feature_turn`), its origin the centre of the bore at the
    part's end nearest the pin's root (:func:`executor.cad.convex.peg_frame`)."""
    turn = feature_turn(derived.pin_of(pid))
    return peg_frame(derived.bores[pid], derived.parts[pid].mesh.copy().apply_transform(turn)) @ turn
