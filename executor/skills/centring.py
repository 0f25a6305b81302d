"""Centring a part by contact in the feature it goes into or onto, before it is put down.

A feature with much room never touches the part on the way down: a bore much wider than
its pin (a nut over a pin with 11 mm of room), or a peg in a loose hole (a prism with
2 mm of room all round). The part ends where the hole search left it, up to the room
off the feature's axis (the search stops where the part first sinks past the entry,
the grasp's offset and tilt besides), where a peg in a tight hole is held within half the
hole's clearance. So once the search has found the feature (the part past its top), the
part goes :data:`ENGAGE` further down and probes by contact: along +x, -x, +y and -y in
turn it moves at :data:`PROBE_SPEED` until it meets the feature (a lateral force over
:data:`TOUCH_FORCE`: the bore the pin, the peg the hole's wall) or it has gone ``reach``;
midway between the two contacts of an axis is the feature's axis (exact where the free
play is mirror symmetric about that axis, as for a round pair and the regular prisms;
an axis without both contacts keeps the search's value). The probes touch with the part
itself, so its grasp offset is in the contacts and the tip position found carries it.
"""

from __future__ import annotations

import numpy as np

from executor.control.motion import Motion
from executor.world.scene import TIME_STEP

ENGAGE = 0.004
"""[m] below the feature's top the probes run at (the part's rounded edges are 1 mm)."""
PROBE_SPEED = 0.02
"""[m/s] of a probe and of the way back."""
TOUCH_FORCE = 3.0
"""[N] lateral: the part meets the feature."""
SETTLE = 0.1
"""[s] held at the centre found."""


def _probe(motion: Motion, start: np.ndarray, direction: np.ndarray, reach: float,
           quat: np.ndarray) -> tuple[np.ndarray, bool]:
    """Command the tip from ``start`` along the unit ``direction`` until the force against
    the motion exceeds :data:`TOUCH_FORCE` or it has gone ``reach`` [m]; returns the tip
    position [m] where it ended and whether it touched."""
    steps = max(1, int(reach / PROBE_SPEED / TIME_STEP))
    state = motion.read()
    for k in range(1, steps + 1):
        state = motion.step(start + direction * reach * k / steps, quat)
        if -float(np.dot(state.force, direction)) > TOUCH_FORCE:
            return state.tip_pos.copy(), True
    return state.tip_pos.copy(), False


def _go(motion: Motion, start: np.ndarray, goal: np.ndarray, quat: np.ndarray) -> None:
    """Command the tip in a straight line from ``start`` to ``goal`` [m] at :data:`PROBE_SPEED`."""
    steps = max(1, int(float(np.linalg.norm(goal - start)) / PROBE_SPEED / TIME_STEP))
    for k in range(1, steps + 1):
        motion.step(start + (goal - start) * k / steps, quat)


def centre_by_contact(motion: Motion, found: np.ndarray, quat: np.ndarray, reach: float, depth: float) -> np.ndarray:
    """The tip position [m] over the feature's axis: from ``found`` (where the search left
    the tip, just past the feature's top), :data:`ENGAGE` (at most half the feature's
    ``depth`` [m]) down, probed ``reach`` [m] each way (module docstring); the tip is held there."""
    start = found - np.array([0.0, 0.0, min(ENGAGE, depth / 2)])
    _go(motion, found, start, quat)
    centre = start.copy()
    for axis in (0, 1):
        ends = []
        for sign in (1.0, -1.0):
            direction = np.zeros(3)
            direction[axis] = sign
            end, touched = _probe(motion, start, direction, reach, quat)
            _go(motion, end, start, quat)
            if touched:
                ends.append(float(end[axis]))
        if len(ends) == 2:
            centre[axis] = sum(ends) / 2
    _go(motion, start, centre, quat)
    return motion.hold(centre, quat, SETTLE).tip_pos.copy()
