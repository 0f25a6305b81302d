"""Where each part waits (``tray``): the trays the import settings lack, in rows from
:data:`TRAY_START` within the arm's :data:`REACH`, each part's footprint :data:`TRAY_GAP`
clear of the others and of the product (:func:`default_trays`), and why two parts overlap
where they wait (:func:`tray_overlap`). Lengths in metres."""

from __future__ import annotations

import math

import numpy as np
import trimesh

from executor.cad.covers import Mapped
from executor.cad.derive import Derived
from executor.cad.operations.plate import LEVEL
from executor.cad.write.meshes import manual_origin, part_frames

TRAY_START = (0.25, 0.40)
"""The first default tray [m] (the shipped products' trays lie 0.47 to 0.50 m from the arm's base)."""
TRAY_PITCH = 0.05
"""The least distance [m] along its row from a default tray to the one before."""
TRAY_GAP = 0.02
"""The least room [m] between a part's footprint on a default tray and any other part's
footprint on its tray or the product's where it stands."""
BASE_TRAY = (0.30, -0.40)
"""Default tray of the base [m]."""
REACH = (0.35, 0.70)
"""A base whose centre, or a default tray, lies this far [m] from the arm's base
horizontally (inclusive) is within the arm's reach: the span of the shipped products'
holes (Cranfield's at 0.55 to 0.63 m) and trays (0.47 to 0.50 m), widened; nearer or
farther is taken as out of reach (a product at x = 0 failed its fits in the sim cell)."""


Box = tuple[np.ndarray, np.ndarray]
"""A footprint: the lowest and highest (x, y) [m] of an axis-aligned rectangle."""


def footprints(derived: Derived, mapped: Mapped) -> dict[str, Box]:
    """Each part's footprint about its tray: the bounding box of its mesh in its part frame
    (a part without one: about its bounding box's bottom centre, :func:`manual_origin`)."""
    frames = part_frames(derived, mapped)
    boxes = {}
    for pid, part in derived.parts.items():
        frame = frames.get(pid, trimesh.transformations.translation_matrix(np.negative(manual_origin(part.mesh))))
        corners = trimesh.transform_points(trimesh.bounds.corners(part.mesh.bounds), frame)[:, :2]
        boxes[pid] = (corners.min(axis=0), corners.max(axis=0))
    return boxes


def product_box(derived: Derived) -> Box:
    """The footprint of the assembled product where it stands in the cell [m]."""
    bounds = np.array([part.mesh.bounds for part in derived.parts.values()])
    return bounds[:, 0, :2].min(axis=0), bounds[:, 1, :2].max(axis=0)


def _at(box: Box, tray: tuple[float, float]) -> Box:
    return box[0] + tray, box[1] + tray


def _apart(a: Box, b: Box, gap: float) -> bool:
    """Whether footprints ``a`` and ``b`` leave more than ``gap`` [m] between them along x or y."""
    return bool(np.any(np.maximum(a[0], b[0]) - np.minimum(a[1], b[1]) > gap))


def default_trays(boxes: dict[str, Box], trays: dict[str, tuple[float, float]], base: str, product: Box
                  ) -> tuple[dict[str, tuple[float, float]], list[str]]:
    """Every part's tray [m]: those in ``trays``, the base's at :data:`BASE_TRAY`, the others
    by id in rows along +x from :data:`TRAY_START`, each row below (towards -y) the one
    before: a tray at least :data:`TRAY_PITCH` after the one before in its row, its
    footprint (``boxes``) :data:`TRAY_GAP` clear of every other part's at its tray and of
    the ``product`` where it stands, its point within :data:`REACH` of the arm's base; and
    the parts that find no such tray (they wait in a row beyond the others, out of reach)."""
    trays = dict(trays)
    trays.setdefault(base, BASE_TRAY)
    taken = [product, *(_at(boxes[pid], tray) for pid, tray in trays.items())]
    x, y = TRAY_START
    edge = math.inf  # the lowest y [m] of the row before's footprints
    low = math.inf  # the lowest y [m] of this row's footprints so far
    unreached = []
    for pid in sorted(set(boxes) - set(trays)):
        box = boxes[pid]
        while True:
            y = TRAY_START[1] if math.isinf(edge) else edge - TRAY_GAP - float(box[1][1])
            if y < -REACH[1]:
                break
            x = max(x, math.sqrt(max(0.0, REACH[0] ** 2 - y * y)))
            while (blocker := next((t for t in taken if not _apart(_at(box, (x, y)), t, TRAY_GAP)), None)) is not None:
                x = float(blocker[1][0]) + TRAY_GAP - float(box[0][0]) + 1e-9
            if math.hypot(x, y) <= REACH[1]:
                break
            edge, low, x = min(low, y + float(box[0][1])), math.inf, TRAY_START[0]
        if y < -REACH[1]:
            unreached.append(pid)
            continue
        trays[pid] = (x, y)
        taken.append(_at(box, (x, y)))
        low = min(low, y + float(box[0][1]))
        x += TRAY_PITCH
    top = max(float(t[1][1]) for t in taken)
    x = TRAY_START[0]
    for pid in unreached:
        trays[pid] = (x - float(boxes[pid][0][0]), top + TRAY_GAP - float(boxes[pid][0][1]))
        x = trays[pid][0] + float(boxes[pid][1][0]) + TRAY_GAP
    return trays, unreached


def tray_overlap(boxes: dict[str, Box], trays: dict[str, tuple[float, float]]) -> str | None:
    """Why two parts overlap where they wait (their footprints ``boxes`` at their
    ``trays``), None when none do."""
    ids = sorted(boxes)
    for k, a in enumerate(ids):
        for b in ids[k + 1:]:
            box_a, box_b = _at(boxes[a], trays[a]), _at(boxes[b], trays[b])
            if np.all(np.minimum(box_a[1], box_b[1]) - np.maximum(box_a[0], box_b[0]) > LEVEL):
                return (f"parts '{a}' and '{b}' overlap where they wait on the tray (set [parts.<id>] tray in the "
                        "import settings)")
    return None
