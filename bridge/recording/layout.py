"""The Rerun layout both sides share: the application id, the entity roots and the blueprints.

Planner and cells log into one recording id of application :data:`APPLICATION_ID`, the
planner under ``planner/...``, cell ``<id>`` under ``executor/<id>/...``. A blueprint is
made for what a recording holds (:class:`Contents`): the planner's tab when the planner
logged, one tab per cell that logged more than its scene and an assembly, one assembly tab
per cell that executed a plan, nothing else.

Rerun 0.41 has one time panel for the whole viewer: its timeline (``TimePanel(timeline=)``)
is the x axis of every plot and the time of every other view; no view or tab has a
timeline of its own (``TimePanelBlueprint``'s fields: ``state``, ``timeline``,
``playback_speed``, ``fps``, ``play_state``, ``loop_mode``, ``time_selection``; the views
take ``time_ranges`` on a timeline but are drawn at the panel's). So every entity a
blueprint shows is logged on the timeline the blueprint opens on: a session's opens on
:data:`SESSION_TIMELINE` (``log_time``, the wall clock, on which the planner and every
cell log: the knowledge changes when an experiment ends, beside the arm that ran it), a
single trial's and an assembly's on ``sim_time``. The paper's Fig. 17 (force against the
DMP phase) is drawn as a 2D plot of one chosen attempt, visible on every timeline.

A blueprint cannot set the time the viewer opens at (the time panel has no cursor field).
Opened ``paused``, the viewer keeps the cursor where the first data it receives starts and
a time the user picks stays; so the starts are made meaningful: the planner logs the
knowledge learning starts from (the demonstrated fits, every other pair unknown) as
``experiment`` 0 when it starts, and a simulated cell logs its arm at rest with its scene
at ``sim_time`` 0 when it starts (docs/recordings.md: what a user sees). Recording
files and ``view.rbl`` open paused (:data:`OPENS`); a stream watched live follows the newest
data (``play_state="following"``). A running viewer's cursor is moved through Rerun's
viewer control instead (:class:`TimePoint`, ``view --screenshot --at``).

A view's ``time_ranges`` and per-entity overrides do take effect: the cell's 3D views
draw the tool tip over the last :data:`TRAIL_S` of each timeline, a trail of the recent
tool path behind the tip, while every other entity is drawn at the cursor; the cell's
close-up follows the held part (``EyeControls3D(tracking_entity=)``), whose tip is the
tool tip, where that trail is centimetres wide rather than a pixel.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import rerun as rr
import rerun.blueprint as rrb

from bridge.files import check_writable

APPLICATION_ID = "assembly_constraints"
PLANNER_ROOT = "planner"
SESSION_TIMELINE = "log_time"
"""Wall-clock timeline [ns since the epoch] every time-varying entity of a session carries."""
SIM_TIMELINE = "sim_time"
"""A cell's simulated time [s], increasing across its attempts."""
TIMELINE_KINDS = {"experiment": "sequence", "plan_step": "sequence", "execution": "sequence",
                  SIM_TIMELINE: "duration", SESSION_TIMELINE: "timestamp"}
"""Every timeline the planner and the cells log on, and its kind: ``sequence`` (a count),
``duration`` [s] or ``timestamp`` [s since the epoch]."""
TRAIL_S = 1.0
"""Length of the tool tip's trail in the cell's 3D view [s of sim time, or of wall time on ``log_time``]."""

CELL_EYE = rrb.EyeControls3D(position=(1.7, 1.2, 1.05), look_target=(0.35, 0.15, 0.3), eye_up=(0.0, 0.0, 1.0))
"""The cell's default camera [m]: the arm's base at the origin, the plate around x = 0.6 m,
the tray around y = 0.4 m (``executor.world``): seen from beyond the tray, all three in view."""
HELD_PART = "arm/part/held"
"""Entity of the part in the hand, below a cell's root (``executor.rerun_arm``)."""
HELD_PART_COLOR = (205, 155, 50)
"""The held part's colour (RGB): solid in the cell's views, see-through in the tool view."""
HELD_PART_SOLIDS = (rr.Asset3D, rr.Cylinders3D, rr.Boxes3D)
"""The archetypes the held part may be drawn with (a mesh, a round or a square part)."""
SEE_THROUGH_ALPHA = 80
"""Opacity (of 255) of the held part in the tool view: the tool path inside it shows."""
HOLE_RIMS = "scene/hole_rims"
"""Entity of the holes' rims at the plate's top, below a cell's root: where the tool view
shows the holes without the plate that would hide the tip in them."""
CLOSE_UP_TARGET_M = (0.59, 0.0, 0.1)
"""Where the close-up looks before a part is taken [m]: over the plate's centre."""
CLOSE_UP_OFFSET_M = (0.07, 0.05, 0.12)
"""The direction the close-up looks from [m]: from the tray's side, 54° above the horizontal,
so a search path on a boss top is seen from above. The viewer sets its distance when it
starts following the held part: 1.5 times the radius of the part's bounding sphere (Rerun
0.41's ``eye.rs``), a few centimetres for Cranfield's pegs."""
FIG17_WIDTH = 80.0
"""Fig. 17's plot units from phase 0 to phase 1 (``executor.rerun_plots`` draws it)."""
FIG17_HEIGHT = 80.0
"""Fig. 17's plot units from −|F|max to +|F|max."""
FIG17_MARGIN = 14.0
"""Plot units around Fig. 17's axes where its labels are: the phase below, |F|max left of the
force axis, the colour key above (the view shows them all, whatever its size)."""
PlayState = Literal["following", "paused"]
OPENS: PlayState = "paused"
"""How a recording file or ``view.rbl`` opens: paused at the start of its timeline."""


@dataclass(frozen=True)
class TimePoint:
    """A time on one of :data:`TIMELINE_KINDS`: ``value`` a count (sequence), or seconds
    (duration, timestamp since the epoch)."""

    timeline: str
    value: float

    @classmethod
    def parse(cls, text: str) -> TimePoint:
        """``TIMELINE=VALUE`` (``experiment=1``, ``sim_time=2.5``); ValueError saying what is
        expected otherwise."""
        timeline, equals, value = text.partition("=")
        kind = TIMELINE_KINDS.get(timeline.strip())
        if not equals or kind is None:
            raise ValueError(f"{text!r}: expected TIMELINE=VALUE with TIMELINE one of {', '.join(TIMELINE_KINDS)}")
        try:
            number = int(value) if kind == "sequence" else float(value)
        except ValueError:
            expected = "a whole number" if kind == "sequence" else "a number of seconds"
            raise ValueError(f"{text!r}: {timeline.strip()} is a {kind} timeline, expected {expected}") from None
        if number < 0 or number != number or number in (float("inf"), float("-inf")):
            raise ValueError(f"{text!r}: expected a finite time >= 0")
        return cls(timeline.strip(), number)

    @property
    def kind(self) -> str:
        """``sequence``, ``duration`` or ``timestamp`` (:data:`TIMELINE_KINDS`)."""
        return TIMELINE_KINDS[self.timeline]

    @property
    def viewer_time(self) -> int:
        """The time as the viewer counts it: the sequence number, else nanoseconds."""
        return int(self.value) if self.kind == "sequence" else round(self.value * 1e9)

    def __str__(self) -> str:
        return f"{self.timeline}={self.value:g}"


def cell_root(cell_id: str) -> str:
    """Entity root of one cell's log: ``executor/<cell_id>``."""
    return f"executor/{cell_id}"


def assembly_root(cell_id: str) -> str:
    """Entity root of a cell's assembly (plan execution): ``executor/<cell_id>/assembly``."""
    return f"{cell_root(cell_id)}/assembly"


def fig17_path(cell_id: str, attempt: str) -> str:
    """Entity of one attempt's Fig. 17 plot: ``executor/<cell>/by_phase/<attempt>``, where
    ``attempt`` is ``<outcome>/<key>`` (``fit/e0003_p1_r1_s7_a1``)."""
    return f"{cell_root(cell_id)}/by_phase/{attempt}"


@dataclass(frozen=True)
class Contents:
    """What a recording holds, as far as its blueprint is concerned.

    ``planner``: the planner logged (a session); ``cells``: cells that logged more than their
    static scene, their arm and an assembly (attempts, or a truth cell's outcomes; the arm
    alone is the one at rest every simulated cell logs when it starts);
    ``assembly_cells``: cells that executed a plan; ``fig17``: ``(cell, attempt)`` pairs,
    the attempt (``<outcome>/<key>``, :func:`fig17_path`) whose Fig. 17 plot the cell's tab
    shows (every attempt's when the cell has none here).
    """

    planner: bool = False
    cells: tuple[str, ...] = ()
    assembly_cells: tuple[str, ...] = ()
    fig17: tuple[tuple[str, str], ...] = ()

    @property
    def timeline(self) -> str:
        """The timeline the viewer opens on: ``log_time`` for a session, else ``sim_time``."""
        return SESSION_TIMELINE if self.planner else SIM_TIMELINE

    @classmethod
    def of(cls, entity_paths: Iterable[str]) -> Contents:
        """The contents of a recording from its entity paths (``/executor/c1/outcome``, ...);
        each cell's Fig. 17 shows its first fitting attempt, else its first attempt."""
        paths = sorted(p.strip("/") for p in entity_paths)
        cells = sorted({p.split("/")[1] for p in paths if p.startswith("executor/") and p.count("/") >= 2
                        and p.split("/")[2] not in ("assembly", "scene", "arm")})
        assembly = sorted({p.split("/")[1] for p in paths if p.startswith("executor/") and "/assembly/" in p})
        chosen = []
        for cell in cells:
            prefix = f"{cell_root(cell)}/by_phase/"
            attempts = {"/".join(p[len(prefix):].split("/")[:2]) for p in paths if p.startswith(prefix)}
            by_key = sorted((a for a in attempts if a.count("/") == 1), key=lambda a: a.split("/")[1])
            first = [a for a in by_key if a.startswith("fit/")][:1] or by_key[:1]
            chosen += [(cell, attempt) for attempt in first]
        return cls(any(p.startswith(f"{PLANNER_ROOT}/") for p in paths), tuple(cells), tuple(assembly), tuple(chosen))


def _graph(origin: str, name: str) -> rrb.GraphView:
    """A graph view that keeps the logged node positions (every layout force off)."""
    forces = rrb.archetypes
    return rrb.GraphView(
        origin=origin, name=name,
        force_link=forces.ForceLink(enabled=False), force_many_body=forces.ForceManyBody(enabled=False),
        force_position=forces.ForcePosition(enabled=False),
        force_collision_radius=forces.ForceCollisionRadius(enabled=False),
        force_center=forces.ForceCenter(enabled=False),
    )


def planner_views() -> rrb.Container:
    """The planner's tab: knowledge matrix and table, experiment log, layered graphs, assignment."""
    return rrb.Horizontal(
        rrb.Vertical(
            rrb.TensorView(origin=f"{PLANNER_ROOT}/knowledge", name="knowledge: -1 unknown, 0 no fit, 1 fit",
                           view_fit="fill"),
            rrb.TextDocumentView(origin=f"{PLANNER_ROOT}/knowledge_table", name="knowledge: part × hole"),
            rrb.TextLogView(origin=f"{PLANNER_ROOT}/experiments", name="experiments"),
            row_shares=[2, 2, 1],
        ),
        rrb.Vertical(
            _graph(f"{PLANNER_ROOT}/precedence", "must precede (reduction, by levels)"),
            _graph(f"{PLANNER_ROOT}/smaller", "smaller than (reduction, by levels)"),
        ),
        rrb.Vertical(
            _graph(f"{PLANNER_ROOT}/assignment", "assignment part → hole"),
            rrb.TextDocumentView(origin=f"{PLANNER_ROOT}/assignment", name="assignment table"),
        ),
        column_shares=[2, 2, 1],
        name="planner",
    )


_WHOLE = rrb.TimeRange(start=rrb.TimeRangeBoundary.infinite(), end=rrb.TimeRangeBoundary.infinite())


def _plot(origin: str, name: str, legend: bool = True) -> rrb.TimeSeriesView:
    """A plot of the whole timeline (not a window around the time cursor) with its legend
    in the top-left corner (hidden when ``legend`` is False)."""
    return rrb.TimeSeriesView(origin=origin, name=name, axis_x=rrb.TimeAxis(view_range=_WHOLE),
                              plot_legend=rrb.PlotLegend(corner="LeftTop", visible=legend))


def _trail() -> rrb.VisibleTimeRanges:
    """The last :data:`TRAIL_S` up to the cursor, on the cell's timelines that advance with
    its steps (``sim_time``, ``log_time``); the whole experiment on ``experiment``."""
    recent = [rrb.VisibleTimeRange(timeline, start=rrb.TimeRangeBoundary.cursor_relative(seconds=-TRAIL_S),
                                   end=rrb.TimeRangeBoundary.cursor_relative())
              for timeline in (SIM_TIMELINE, SESSION_TIMELINE)]
    experiment = rrb.VisibleTimeRange("experiment", start=rrb.TimeRangeBoundary.cursor_relative(),
                                      end=rrb.TimeRangeBoundary.cursor_relative())
    return rrb.VisibleTimeRanges([*recent, experiment])


def _cell_3d(root: str, name: str, eye: rrb.EyeControls3D) -> rrb.Spatial3DView:
    """A 3D view of the cell under ``root`` (scene, arm, tool with the tip's trail, search
    path) seen through ``eye``."""
    return rrb.Spatial3DView(
        origin=root, name=name,
        contents=["$origin/scene/**", "$origin/arm/**", "$origin/tool/**", "$origin/search/**"],
        eye_controls=eye, overrides={f"/{root}/tool/tip": _trail()},
    )


def _tool_3d(root: str, name: str, eye: rrb.EyeControls3D) -> rrb.Spatial3DView:
    """The tool alone under ``root`` seen through ``eye``: the tip with its trail, the force
    arrow, the tool and search paths, the holes' rims and the held part see-through
    (:data:`SEE_THROUGH_ALPHA`); the arm, the plate and the solid part, which hide the tip
    inside the part and the hole, are left out."""
    see_through = [*HELD_PART_COLOR, SEE_THROUGH_ALPHA]
    solids = [solid.visualizer() for solid in (  # one per kind of HELD_PART_SOLIDS
        rr.Asset3D.from_fields(albedo_factor=see_through), rr.Cylinders3D.from_fields(colors=[see_through]),
        rr.Boxes3D.from_fields(colors=[see_through]))]
    return rrb.Spatial3DView(
        origin=root, name=name,
        contents=["$origin/tool/**", "$origin/search/**", f"$origin/{HOLE_RIMS}", f"$origin/{HELD_PART}"],
        eye_controls=eye, overrides={f"/{root}/tool/tip": _trail(), f"/{root}/{HELD_PART}": solids},
    )


def cell_views(cell_id: str, fig17: str | None = None) -> rrb.Container:
    """A cell's tab: the 3D cell (arm, scene, tool tip with its trail (:func:`_trail`) and
    force, the attempt's tool path, search path) above a close-up of the same that follows
    the held part, whose tip is the tool tip (:data:`HELD_PART`, :data:`CLOSE_UP_OFFSET_M`;
    over the plate, :data:`CLOSE_UP_TARGET_M`, before a part is taken), beside it the tool
    alone through the same camera (:func:`_tool_3d`); the Fig. 17 plot of attempt ``fig17``
    (``<outcome>/<key>``, :func:`fig17_path`; None: every attempt) above the outcome log;
    force, torque and the deviations of eqs. 6 and 7 per attempt, their colours named in
    the titles (a legend covers the plot's data: Rerun draws it inside, in a corner)."""
    root = cell_root(cell_id)
    attempt = fig17.replace("/", " ") if fig17 else "every attempt"
    eye = tuple(t + d for t, d in zip(CLOSE_UP_TARGET_M, CLOSE_UP_OFFSET_M))
    close_up = rrb.EyeControls3D(position=eye, look_target=CLOSE_UP_TARGET_M, eye_up=(0.0, 0.0, 1.0),
                                 tracking_entity=f"/{root}/{HELD_PART}")
    return rrb.Horizontal(
        rrb.Vertical(
            _cell_3d(root, f"{cell_id}: cell", CELL_EYE),
            rrb.Horizontal(
                _cell_3d(root, f"{cell_id}: close-up on the held part", close_up),
                _tool_3d(root, f"{cell_id}: tool, part see-through", close_up),
            ),
        ),
        rrb.Vertical(
            rrb.Spatial2DView(origin=f"{root}/by_phase", contents=[f"$origin/{fig17}/**" if fig17 else "$origin/**"],
                              name=f"Fig. 17 {attempt}: F_mes, F_des [N] over DMP phase",
                              visual_bounds=rrb.VisualBounds2D(
                                  x_range=[-1.6 * FIG17_MARGIN, FIG17_WIDTH + FIG17_MARGIN / 2],
                                  y_range=[-FIG17_HEIGHT / 2 - FIG17_MARGIN, FIG17_HEIGHT / 2 + FIG17_MARGIN])),
            rrb.TextLogView(origin=f"{root}/outcome", name=f"{cell_id}: outcomes"),
            row_shares=[2, 1],
        ),
        rrb.Vertical(
            _plot(f"{root}/wrench/force", "force [N]: Fx red, Fy green, Fz blue; F_des pale", legend=False),
            _plot(f"{root}/wrench/torque", "torque [Nm]: Mx red, My green, Mz blue; M_des pale", legend=False),
            _plot(f"{root}/deviation/force", "‖F_mes − F_des‖ [N] per attempt: green fit, red no fit", legend=False),
            _plot(f"{root}/deviation/torque", "‖M_mes − M_des‖ [Nm] per attempt: green fit, red no fit",
                  legend=False),
        ),
        column_shares=[3, 2, 3],
        name=cell_id,
    )


def assembly_views(cell_id: str) -> rrb.Container:
    """A cell's assembly tab: parts and arm in 3D, the plan steps, the measured force."""
    root = assembly_root(cell_id)
    return rrb.Horizontal(
        rrb.Spatial3DView(origin=root, name=f"{cell_id}: assembly", contents=["$origin/parts/**", "$origin/arm/**"],
                          eye_controls=CELL_EYE),
        rrb.Vertical(
            rrb.TextLogView(origin=f"{root}/steps", name="plan steps"),
            _plot(f"{root}/force", "force at the TCP Fx, Fy, Fz [N]"),
        ),
        column_shares=[2, 1],
        name=f"{cell_id} assembly",
    )


def tab_names(contents: Contents) -> list[str]:
    """The names of the tabs of ``contents``' blueprint, in order."""
    return [*(["planner"] if contents.planner else []), *contents.cells,
            *(f"{cell} assembly" for cell in contents.assembly_cells)]


def blueprint(contents: Contents, active_tab: int = 0, play_state: PlayState = OPENS,
              timeline: str | None = None) -> rrb.Blueprint:
    """The blueprint of a recording holding ``contents``: the planner's tab, a tab per cell,
    an assembly tab per assembling cell (:func:`tab_names`), tab ``active_tab`` shown; on
    ``timeline`` (default :attr:`Contents.timeline`), paused (the cursor stays where it is:
    where the first data it received starts when the viewer opens) or ``"following"`` the
    newest data."""
    chosen = dict(contents.fig17)
    tabs = [
        *([planner_views()] if contents.planner else []),
        *(cell_views(cell, chosen.get(cell)) for cell in contents.cells),
        *(assembly_views(cell) for cell in contents.assembly_cells),
    ]
    return rrb.Blueprint(
        rrb.Tabs(*tabs, active_tab=active_tab),
        rrb.TimePanel(timeline=timeline or contents.timeline, play_state=play_state),
        rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),  # the views get the room
    )


def opening(live: bool) -> PlayState:
    """How a stream's own blueprint opens: following the newest data when someone watches it
    live (``live``), else :data:`OPENS`."""
    return "following" if live else OPENS


def write_blueprint(folder: Path, contents: Contents) -> Path:
    """``folder/view.rbl``: the blueprint of a recording holding ``contents``, opening
    paused; BridgeError naming the file when it cannot be written."""
    path = check_writable(folder / "view.rbl")  # written by the Rerun SDK itself
    blueprint(contents).save(APPLICATION_ID, str(path))
    return path
