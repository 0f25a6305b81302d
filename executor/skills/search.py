"""Stochastic hole search around the vision estimate (paper 3.2 step 1).

The tip comes down on the estimate until it touches the plate (or drops straight into
the hole), then slides over the surface under a light contact force along an
Archimedean spiral whose start angle, direction and pitch are drawn at random, out to
``max_radius`` and back in to the estimate half a pitch inside the way out; if that found
nothing, out once more at a third of the speed, the command leading the spiral by the
part's measured lag (friction drags it behind).  The hole is found when the tip sinks into
the hole's entry chamfer and, pushed down it, past it: a part that is too big never sinks,
so the search gives up and the insertion is tried back at the estimate (and fails there).

A push that stops short of the chamfer's end is a find only when the part is held below
the hole's top face (wedged in the chamfer): a tilted part whose low edge has dipped over
a sharp rim (a hole without entry chamfer) sinks as far but rests on the top face by the
rim, up to the hole's room off its centre, and the spiral goes on (:func:`below_top_face`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from executor.control.admittance import Admittance, AdmittanceParams
from executor.control.motion import Motion
from executor.skills.search_params import SearchParams
from executor.world.arm import ArmState
from executor.world.scene import TIME_STEP

_NO_SHIFT = np.zeros(2)


@dataclass
class SearchResult:
    """``found``: the tip sank into a hole at ``hole_xy`` [m]; ``path`` (N×3) [m]."""

    found: bool
    hole_xy: np.ndarray
    surface_z: float
    path: np.ndarray


def _slide_in(motion: Motion, xy: np.ndarray, touched_z: float, quat_xyzw: np.ndarray, p: SearchParams,
              path: list[np.ndarray]) -> np.ndarray:
    """The part's edge is in the hole's chamfer: press harder (2 × press depth) with the
    commanded position complying to the lateral force, until the tip is ``enter_depth``
    below the surface (past the chamfer) or ``dip_hold`` is over.  Returns the tip
    position [m]."""
    comply = Admittance(AdmittanceParams())
    s = motion.read()
    for _ in range(int(p.dip_hold / TIME_STEP)):
        shift = comply.update(s.force, np.zeros(3), TIME_STEP)[0]
        s = motion.step(np.array([xy[0] + shift[0], xy[1] + shift[1], touched_z - 2 * p.press_depth]), quat_xyzw)
        if s.tip_pos[2] < touched_z - p.enter_depth:
            break
    path.append(s.tip_pos.copy())
    return s.tip_pos


def below_top_face(tip_z: float, touched_z: float, surface_z: float, p: SearchParams) -> bool:
    """Whether a part whose push ended with its tip at ``tip_z`` [m] is held below the
    top face at ``surface_z`` [m] (in the hole's chamfer or past it) rather than resting
    on it.  The hole axis is z: on a hole entered sideways these heights are the hole
    frame's.

    Resting on the top face (a tilted part over a sharp rim, its low edge dipped into the
    hole), the part's support is a point of its bottom at the face's height, so its tip is
    at most the height of its bottom's highest point above the tip below the face.  The
    touch measured that height: the tip rested ``touched_z - surface_z`` above the face on
    the part's lowest point, and the highest point is as high above the tip as the lowest
    is below it (a tilted flat bottom, a footprint symmetric about the tip).  A tip more
    than that plus ``rest_tolerance`` (the grasp offset's asymmetry, the compliance's
    turn) below the face is held by something under it; past ``enter_depth`` below the
    touch it is in the hole in any case.  A part that sank on the way down touched
    nothing: ``touched_z`` is then ``surface_z``, its lift unmeasured (taken as 0)."""
    lift = max(touched_z - surface_z, 0.0)
    return tip_z < touched_z - p.enter_depth or tip_z < surface_z - lift - p.rest_tolerance


@dataclass
class _Contact:
    """The part on the plate: its tip ``touched_z`` [m] where it came to rest on the top
    face at ``surface_z`` [m], the arm's last reading and the path so far."""

    touched_z: float
    surface_z: float
    state: ArmState
    path: list[np.ndarray]


def _spiral(motion: Motion, est_xy: np.ndarray, contact: _Contact, quat_xyzw: np.ndarray, rng: np.random.Generator,
            p: SearchParams, speed: float, back_in: bool, max_time: float, lead_gain: float) -> np.ndarray | None:
    """One spiral pass under contact at ``speed`` [m/s] from ``est_xy`` [m] out to
    ``max_radius`` (and back in half a pitch inside the way out if ``back_in``), for at
    most ``max_time`` [s] counting the pushes, the command leading the spiral by the
    part's lag measured along its way (integral gain ``lead_gain`` [1/s], 0: none).
    Returns the tip position [m] of a find, else None (``contact.state`` then the last
    reading, the part back near the estimate if ``back_in``)."""
    s, touched_z = contact.state, contact.touched_z
    target_z = contact.surface_z - p.press_depth
    # r = pitch·θ/2π at a constant sliding speed, from a random start angle and direction.
    angle0 = rng.uniform(0, 2 * math.pi)
    direction = rng.choice([-1.0, 1.0])
    pitch = p.pitch * (1 + rng.uniform(-p.pitch_jitter, p.pitch_jitter))
    theta, elapsed, paused, may_pause = 0.0, 0.0, 0, True
    lead, heading = 0.0, np.zeros(2)  # [m] the command ahead of the spiral along its way (unit heading)
    inward = False  # back in to the estimate, half a pitch inside the way out
    sink_from = touched_z  # [m] the height a sink is measured from: below a rest on a rim, in its dip
    comply = Admittance(AdmittanceParams())
    offset = np.zeros(2)
    try:
        while elapsed < max_time:
            radius = pitch * theta / (2 * math.pi) - (pitch / 2 if inward else 0.0)
            if radius > p.max_radius and back_in:
                inward = True
                radius -= pitch / 2
            if radius > p.max_radius or radius < 0:
                return None
            dipped = s.tip_pos[2] < touched_z - p.dip_depth
            if not dipped:
                sink_from = touched_z
            if dipped and may_pause and paused < p.dip_hold / TIME_STEP:
                paused += 1
                shift = comply.update(s.force, np.zeros(3), TIME_STEP)[0][:2]
            else:
                may_pause = not dipped
                paused = 0
                comply.reset()
                shift = _NO_SHIFT
                # The part drags behind under friction: lead the command by the lag measured along the way.
                lag = float((est_xy + offset - s.tip_pos[:2]) @ heading)
                lead = min(max(lead + lead_gain * lag * TIME_STEP, 0.0), p.max_lead)
                theta += (-1 if inward else 1) * speed * TIME_STEP / max(radius, pitch / 2)
                angle = angle0 + direction * theta
                ahead = radius * np.array([math.cos(angle), math.sin(angle)])
                heading = (ahead - offset) / max(float(np.linalg.norm(ahead - offset)), 1e-9)
                offset = ahead
            xy = est_xy + offset + lead * heading + shift
            s = motion.step(np.array([xy[0], xy[1], target_z]), quat_xyzw)
            elapsed += TIME_STEP
            if motion.steps % 10 == 0:
                contact.path.append(s.tip_pos.copy())
            if s.tip_pos[2] < sink_from - p.sink_depth:
                pushed_at = motion.steps
                tip = _slide_in(motion, xy, touched_z, quat_xyzw, p, contact.path)
                if below_top_face(float(tip[2]), touched_z, contact.surface_z, p):
                    return tip
                elapsed += (motion.steps - pushed_at) * TIME_STEP
                sink_from, may_pause = float(tip[2]), False
                s = motion.read()
        return None
    finally:
        contact.state = s


def hole_search(motion: Motion, est_xy: np.ndarray, surface_z: float, start_z: float, quat_xyzw: np.ndarray,
                rng: np.random.Generator, params: SearchParams) -> SearchResult:
    """Search for the hole near ``est_xy`` [m] on a plate whose top is at ``surface_z`` [m],
    with the settings ``params`` (the cell description's ``search``).

    While sliding, a dip of the tip (``dip_depth`` below the touched surface: an edge of
    the part is over the hole) pauses the spiral for up to ``dip_hold``; meanwhile the
    commanded position complies to the lateral contact force (admittance).  A sink of
    ``sink_depth`` means the part is in the hole's chamfer: it is then pushed down the
    chamfer into the hole (``_slide_in``) and the hole is found where it ends, if the
    part is held below the top face there (:func:`below_top_face`); else it rests on a
    rim, and the spiral goes on out of that dip, where a further sink of ``sink_depth``
    below the rest counts again.  At ``max_radius`` the spiral turns back in along
    r = pitch·θ/2π − pitch/2 (``back_in``).  A pass that found nothing is followed by one
    at ``slow_speed`` out to ``max_radius`` (``slow_time``; 0: none): a tight hole on a
    sharp rim (room of 0.17 mm) drops a part that passes over it slowly, and a fast one
    skates across.  On that pass the command leads the spiral by the part's lag behind
    it, measured along the way (gain ``track_gain``, at most ``max_lead``): dragged with
    2 to 6 N of friction at 2000 N/m, the part trails 1 to 4 mm and sweeps a spiral that
    much smaller, sparse near its centre (the fast pass is not led: on a chamfer it finds
    the hole as it is).  The pushes count in the passes' times."""
    p = params
    path: list[np.ndarray] = []
    target_z = surface_z - p.press_depth
    # 1. Approach: straight down on the estimate.
    z = start_z
    while True:
        z = max(target_z, z - p.approach_speed * TIME_STEP)
        s = motion.step(np.array([est_xy[0], est_xy[1], z]), quat_xyzw)
        if s.tip_pos[2] < surface_z - p.sink_depth:
            tip = _slide_in(motion, est_xy, surface_z, quat_xyzw, p, path)
            return SearchResult(True, tip[:2].copy(), surface_z, np.array(path))
        if s.force[2] > p.contact_force or (z == target_z and abs(s.tip_vel[2]) < 1e-3):
            break
    # 2. Spirals under contact: fast out and back, then slow out.
    contact = _Contact(float(s.tip_pos[2]), surface_z, s, path)
    found = _spiral(motion, est_xy, contact, quat_xyzw, rng, p, p.speed, p.back_in, p.max_time, 0.0)
    if found is None and p.slow_time > 0:
        found = _spiral(motion, est_xy, contact, quat_xyzw, rng, p, p.slow_speed, False, p.slow_time, p.track_gain)
    if found is not None:
        return SearchResult(True, found[:2].copy(), surface_z, np.array(path))
    return SearchResult(False, np.asarray(est_xy, dtype=float).copy(), surface_z, np.array(path).reshape(-1, 3))
