"""The hole search's settings (:class:`SearchParams`, :mod:`executor.skills.search`), apart
from the search so that the cell description (:mod:`executor.cell_description`) reads them
as a table of its own."""

from __future__ import annotations

from typing import Annotated

import msgspec

SINK_DEPTH = 0.0005
"""[m] below the surface: the tip is in a hole's entry chamfer."""
_Length = Annotated[float, msgspec.Meta(gt=0.0, le=0.05, description="a number in (0, 0.05] m")]
_Speed = Annotated[float, msgspec.Meta(gt=0.0, le=0.5, description="a number in (0, 0.5] m/s")]
_Time = Annotated[float, msgspec.Meta(gt=0.0, le=600.0, description="a number in (0, 600] s")]


class SearchParams(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """Approach speed [m/s], contact force that means "on the surface" [N], how far
    below the surface the tip is pushed while sliding [m] (× 2000 N/m = contact force),
    sink depth that means "in the hole's chamfer" [m], depth that means "past the
    chamfer" [m], margin below the lowest tip of a part resting on the top face that
    means "held below it" [m] (:func:`below_top_face`), dip that pauses the spiral
    [m] and for how long at most [s], spiral pitch [m] (± ``pitch_jitter``),
    sliding speed [m/s], search radius [m] (vision error ≤ 3 mm + grasp offset ≤ 1 mm
    + half a pitch), whether the spiral comes back in from it half a pitch inside the way
    out (the part's path then twice as dense), gain [1/s] of the slow pass's lead on the
    part's lag behind the spiral and its bound [m], time limit [s] of the first pass,
    speed [m/s] and time limit [s] of the slow pass out that follows a first pass that
    found nothing (0 s: none). The cell description's ``[search]`` table (docs/cell.md)."""

    approach_speed: _Speed = 0.025
    contact_force: Annotated[float, msgspec.Meta(gt=0.0, le=100.0, description="a number in (0, 100] N")] = 2.0
    press_depth: _Length = 0.0025
    sink_depth: _Length = SINK_DEPTH
    enter_depth: _Length = 0.0012
    rest_tolerance: _Length = 0.00025
    dip_depth: _Length = 0.0001
    dip_hold: _Time = 0.3
    pitch: _Length = 0.0012
    pitch_jitter: Annotated[float, msgspec.Meta(ge=0.0, lt=1.0, description="a number in [0, 1)")] = 0.05
    speed: _Speed = 0.045
    max_radius: _Length = 0.0046
    back_in: bool = True
    track_gain: Annotated[float, msgspec.Meta(ge=0.0, le=1000.0, description="a number in [0, 1000] 1/s")] = 30.0
    max_lead: _Length = 0.004
    max_time: _Time = 4.4
    slow_speed: _Speed = 0.015
    slow_time: Annotated[float, msgspec.Meta(ge=0.0, le=600.0, description="a number in [0, 600] s")] = 6.0
