"""Rerun logging of the cell's insertion attempts (paper 3.2, Fig. 17).

The :class:`~executor.trial.Cell` calls an :class:`AttemptLogger` while it executes:
``log_scene`` once, then per attempt ``begin_attempt``, ``log_search_path``,
``log_step`` at every control step and ``end_attempt``.

Entities (all under ``executor/<cell-id>/``):

=============================== ===================================================
``scene/<name>``                static geometry (boxes, cylinders), ``static=True``
``scene/hole_rims``             the holes' rims at the plate's top [m], ``static=True``
``tool/tip``                    tool-tip position over ``sim_time`` [m] (a point of :data:`TIP_RADIUS_UI`)
``tool/force``                  F_mes as an arrow at the tool tip (:data:`FORCE_ARROW_M_PER_N`)
``tool/path``                   the attempt's tool path up to then as a line strip [m]: none at its
                                first step, grey at a few times while the attempt runs, the whole
                                path green (fit) or red (no fit) when it ends
``search/path``                 the stochastic hole-search path [m], from the step its search
                                ended at (none before it in the attempt)
``wrench/force/{measured,desired}``   F_mes, F_des (x, y, z) over ``sim_time`` [N]
``wrench/torque/{measured,desired}``  M_mes, M_des (x, y, z) over ``sim_time`` [Nm]
``deviation/{force,torque}/<key>``    ‖F_mes − F_des‖ [N], ‖M_mes − M_des‖ [Nm] (eqs. 6, 7),
                                one series per attempt (:attr:`AttemptTrace.key`),
                                green when it fitted, red when not
``phase``                       DMP phase over ``sim_time`` (0 → 1 during the
                                insertion; 0 while searching or retreating)
``by_phase/<outcome>/<key>``    Fig. 17: F_des and F_mes of the insertion against the DMP
                                phase 0..1, a 2D plot growing with the insertion: the part up
                                to then at a few times during it, whole at its last step
                                (:func:`executor.rerun_plots.send_fig17`)
``outcome``                     text log, one line per attempt
``result/{fit,max_force_dev,max_torque_dev,end_error,...}``  per-attempt scalars
``ilc/<shape>/<hole>/correction_norm``  size of the ILC correction after each update
                                (mm and degrees, :func:`executor.control.ilc.correction_norm`)
                                over timeline ``execution``
=============================== ===================================================

Timelines: ``experiment`` (sequence: one per trial, or set by the caller),
``sim_time`` (duration [s]; kept increasing across attempts even when the cell
restarts its clock), ``log_time`` (the wall clock when each step ran, the timeline a
session's planner logs on too) and ``execution`` (sequence: the ILC iteration of a part
shape and hole).

Steps are buffered and sent column-wise (``send_columns``) at ``end_attempt``, which
keeps the per-step cost to a list append; samples closer than ``period_s`` in sim
time are skipped so a long campaign stays small. The search path, the growing tool path
and Fig. 17 are sent then too, each row at the times of the step it ends with
(:func:`executor.rerun_plots.growth_ends`: at most
:data:`executor.rerun_plots.GROWTH_ROWS` rows an attempt).
"""

from __future__ import annotations

import time
import uuid
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
import rerun as rr

from bridge.recording.compaction import compact_recording
from bridge.recording.layout import (
    APPLICATION_ID,
    HOLE_RIMS,
    SESSION_TIMELINE,
    Contents,
    blueprint,
    cell_root,
    fig17_path,
    opening,
)
from bridge.recording.sinks import NO_VIEWER, Viewer, finish_stream, open_stream
from executor import ExecutorError
from executor.rerun_plots import (
    AXIS_NAMES,
    DESIRED_COLORS,
    MEASURED_COLORS,
    growth_ends,
    outcome_color,
    send_fig17,
)

if TYPE_CHECKING:
    from executor.evidence import AttemptEvidence
    from executor.rerun_arm import ArmRecorder

FORCE_ARROW_M_PER_N = 0.004
"""Length of the force arrow at the tool [m] per newton of F_mes."""
TIP_RADIUS_UI = 2.0
"""Radius of the tool tip's point [UI points: pixels at 100 % UI scaling, whatever the zoom];
the 3D views draw the tip over the last second as its trail
(:data:`bridge.recording.layout.TRAIL_S`): a line of dots a few pixels
wide, in the cell's overview and in the close-ups alike."""
TIP_COLOR = [30, 110, 230]
FORCE_COLOR = [200, 30, 160]
PATH_COLOR = [110, 110, 120]
"""The tool path's colour while its attempt runs (its outcome is not known yet)."""
RIM_COLOR = [60, 60, 60]
SEARCH_COLOR = [240, 180, 0]
PATH_RADIUS_UI = 1.0
"""Radius of the tool path's and the search path's lines [UI points]."""
FORCE_RADIUS_UI = 1.5
"""Radius of the force arrow's shaft [UI points]."""

_TIME_TOLERANCE = 1e-9  # [s] float slack when comparing sim times
_ATTEMPT_GAP_S = 0.001  # [s] between attempts when the cell restarts its clock


class SceneShape(NamedTuple):
    """One static body of the scene; a plain tuple in this order works as well.

    ``shape`` is ``"box"`` or ``"cylinder"``; ``half_extents`` [m] are the box's half
    sizes, or ``(radius, radius, half_length)`` of a cylinder along its local z axis.
    """

    name: str
    shape: str
    half_extents: Sequence[float]
    position: Sequence[float]
    quat_xyzw: Sequence[float] = (0.0, 0.0, 0.0, 1.0)
    color: Sequence[int] | None = None


@dataclass(frozen=True)
class TraceStep:
    """One control step as logged: ``sim_time`` [s] as the cell reported it, ``phase`` (DMP
    phase), ``tool_pos`` (3,) [m], ``force_mes``/``force_des`` (3,) [N] measured and
    desired, ``torque_mes``/``torque_des`` (3,) [Nm]; ``arm_pose``: the arm's link poses
    (:meth:`executor.rerun_arm.ArmRecorder.sample`) or None;
    ``wall_time`` [s since the epoch]: when it was logged."""

    sim_time: float
    phase: float
    tool_pos: np.ndarray
    force_mes: np.ndarray
    force_des: np.ndarray
    torque_mes: np.ndarray
    torque_des: np.ndarray
    arm_pose: np.ndarray | None
    wall_time: float


@dataclass
class AttemptTrace:
    """The buffered samples of one attempt (also kept for plots, e.g. Fig. 17).

    Arrays have one row per logged step: ``sim_time`` [s] as the cell reported it,
    ``wall_time`` [s since the epoch], ``phase`` (DMP phase), ``tool_pos`` [m], forces [N],
    torques [Nm].
    """

    part: str
    hole: str
    trial_seed: int
    attempt: int
    experiment: int
    outcome: str = ""
    sim_time: list[float] = field(default_factory=list)
    wall_time: list[float] = field(default_factory=list)
    phase: list[float] = field(default_factory=list)
    tool_pos: list[np.ndarray] = field(default_factory=list)
    force_mes: list[np.ndarray] = field(default_factory=list)
    force_des: list[np.ndarray] = field(default_factory=list)
    torque_mes: list[np.ndarray] = field(default_factory=list)
    torque_des: list[np.ndarray] = field(default_factory=list)
    arm_poses: list[np.ndarray] = field(default_factory=list)
    search_path: np.ndarray | None = None
    search_step: int = 0
    """The hole-search path ``(N, 3)`` [m] and the step it was logged at (when the search ended)."""

    def add(self, step: TraceStep) -> None:
        """Append one step (:class:`TraceStep`)."""
        if step.arm_pose is not None:
            self.arm_poses.append(step.arm_pose)
        self.sim_time.append(float(step.sim_time))
        self.wall_time.append(step.wall_time)
        self.phase.append(float(step.phase))
        for name in ("tool_pos", "force_mes", "force_des", "torque_mes", "torque_des"):
            getattr(self, name).append(np.array(getattr(step, name), dtype=np.float64))

    def insertion(self) -> np.ndarray:
        """Indices of the DMP insertion's steps (wiggles included): those logged with
        phase > 0; search, settling and retreat are logged at phase 0."""
        return np.flatnonzero(self.array("phase") > 0.0)

    @property
    def key(self) -> str:
        """Entity-path-safe name of the attempt, e.g. ``e0003_p1_r1_s7_a2``."""
        return f"e{self.experiment:04d}_{self.part}_{self.hole}_s{self.trial_seed}_a{self.attempt}"

    def array(self, name: str) -> np.ndarray:
        """One buffered signal as an array (``(N,)`` or ``(N, 3)``)."""
        return np.asarray(getattr(self, name), dtype=np.float64)


def open_recording(recording_id: str, rrd_path: Path | None, viewer: Viewer = NO_VIEWER,
                   application_id: str = APPLICATION_ID) -> rr.RecordingStream:
    """A stream of ``recording_id`` to the file ``rrd_path`` (written by the Rerun SDK) and to
    ``viewer``; ExecutorError ``<path>: cannot write (<reason>)`` when the file cannot be created."""
    try:
        return open_stream(application_id, recording_id, rrd_path, viewer)
    except RuntimeError as exc:  # the SDK's own check, e.g. a race with the one above
        raise ExecutorError(f"{rrd_path}: cannot write ({exc})") from None


@dataclass(frozen=True)
class LogTarget:
    """Where an :class:`AttemptLogger`'s recording goes: a new stream of ``application_id``
    with ``recording_id`` (random if None) saved to ``rrd_path``, or the existing
    ``recording`` stream (not both; neither: data stays in memory); ``viewer``: also
    streamed live to a Rerun viewer or served to a browser (:mod:`bridge.recording.sinks`);
    ``send_blueprint``: send the cell's view layout (off where the planner sends it)."""

    rrd_path: str | Path | None = None
    recording_id: str | None = None
    application_id: str = APPLICATION_ID
    recording: rr.RecordingStream | None = None
    viewer: Viewer = NO_VIEWER
    send_blueprint: bool = True


class AttemptLogger:
    """Logs a cell's attempts into one Rerun recording (explicit stream, not global).

    ``AttemptLogger("c1", LogTarget(rrd_path="runs/x/c1.rrd"))`` opens a new stream saving
    to the file; ``AttemptLogger("c1", LogTarget(recording=stream))`` logs into an existing
    ``rr.RecordingStream`` instead (:class:`LogTarget`). Without either, data stays in
    memory (``keep_traces`` then still gives the traces for plots).

    ``period_s`` [s]: steps closer than this in sim time to the last kept one are
    skipped. ``keep_traces``: keep every finished :class:`AttemptTrace` in ``traces``.
    """

    def __init__(self, cell_id: str = "c1", target: LogTarget = LogTarget(), *, period_s: float = 0.005,
                 keep_traces: bool = False) -> None:
        recording, rrd_path, viewer = target.recording, target.rrd_path, target.viewer
        if recording is not None and rrd_path is not None:
            raise ExecutorError("AttemptLogger: give rrd_path or recording, not both")
        if period_s < 0:
            raise ExecutorError(f"AttemptLogger: period_s must be >= 0 [s], got {period_s}")
        self.cell_id = cell_id
        self.root = cell_root(cell_id)
        self.period_s = period_s
        self.keep_traces = keep_traces
        self.traces: list[AttemptTrace] = []
        self._owns_stream = recording is None
        self._rrd_path = Path(rrd_path) if rrd_path is not None else None
        if recording is None:
            recording = open_recording(target.recording_id or str(uuid.uuid4()), self._rrd_path, viewer,
                                       target.application_id)
        self.rec = recording
        self._experiment = 0
        self._last_attempt: tuple[str, str, int, int] | None = None
        self._styled: set[str] = set()  # entities whose static style was sent
        self._current: AttemptTrace | None = None
        self._time_offset = 0.0  # [s] added to the cell's sim_time
        self._last_time = 0.0  # [s] last logged (offset) sim time
        self._sent_steps = False
        self._skipped: TraceStep | None = None  # last step not kept (yet)
        self._arm: ArmRecorder | None = None
        self._arm_static_sent = False
        self._held: str | None = None
        if target.send_blueprint:
            live = viewer.connect is not None
            self.rec.send_blueprint(blueprint(Contents(cells=(cell_id,)), play_state=opening(live)))

    @classmethod
    def to_file(
        cls, rrd_path: str | Path | None, cell_id: str = "c1", recording_id: str | None = None,
        viewer: Viewer = NO_VIEWER,
    ) -> AttemptLogger:
        """A logger saving to ``rrd_path`` (its folder must exist; ExecutorError naming the
        path if the file cannot be created) and streaming to ``viewer``."""
        return cls(cell_id, LogTarget(rrd_path=rrd_path, recording_id=recording_id, viewer=viewer))

    # -- static geometry -------------------------------------------------------------

    def log_scene(self, shapes: Sequence[SceneShape | tuple[Any, ...]]) -> None:
        """Log static bodies once (``static=True``) under ``scene/<name>``."""
        for raw in shapes:
            shape = SceneShape(*raw)
            half = np.asarray(shape.half_extents, dtype=np.float64)
            quat = rr.Quaternion(xyzw=list(shape.quat_xyzw))
            colors = [list(shape.color)] if shape.color is not None else None
            if shape.shape == "box":
                archetype: Any = rr.Boxes3D(
                    half_sizes=[half], centers=[shape.position], quaternions=[quat],
                    colors=colors, fill_mode="solid",
                )
            elif shape.shape == "cylinder":
                archetype = rr.Cylinders3D(
                    radii=[float(half[0])], lengths=[2.0 * float(half[2])],
                    centers=[shape.position], quaternions=[quat], colors=colors,
                    fill_mode="solid",
                )
            else:
                raise ExecutorError(
                    f"scene shape '{shape.name}': shape must be 'box' or 'cylinder', "
                    f"got {shape.shape!r}"
                )
            self.rec.log(f"{self.root}/scene/{shape.name}", archetype, static=True)

    def attach_arm(self, arm: ArmRecorder, held_part: str) -> None:
        """From now on log ``arm``'s links at every kept step; log its geometry (the meshes
        once per recording, the held part whenever it changes)."""
        if arm is self._arm and held_part == self._held:
            return
        self._set_time(self._last_time)
        arm.log_geometry(self.rec, self.root, held_part, with_static=not self._arm_static_sent)
        self._arm, self._held, self._arm_static_sent = arm, held_part, True

    def log_arm_at_rest(self, arm: ArmRecorder) -> None:
        """The arm as it stands before its first move, its hand empty, at the current time
        (``sim_time`` 0 and ``experiment`` 0 before any attempt, ``log_time`` now): its
        meshes and link poses, all at that one instant rather than the meshes static, so a
        viewer shows the whole arm in place from then on and nothing of it before (on
        ``log_time``, before the cell started), never its links piled at the origin."""
        at = [rr.TimeColumn("experiment", sequence=[self._experiment]),
              rr.TimeColumn("sim_time", duration=[self._last_time]),
              rr.TimeColumn(SESSION_TIMELINE, timestamp=[time.time()])]
        arm.log_geometry(self.rec, self.root, None, with_static=not self._arm_static_sent, at=at)
        arm.send(self.rec, self.root, at, arm.sample()[np.newaxis])
        self._arm_static_sent = True

    def log_scene_mesh(self, name: str, mesh: Path, color: Sequence[int]) -> None:
        """Log a static mesh file (``.obj``/``.stl``/``.glb``, world coordinates [m]) under
        ``scene/<name>``, e.g. the plate's bosses with their holes."""
        self.rec.log(f"{self.root}/scene/{name}", rr.Asset3D(path=mesh, albedo_factor=list(color)), static=True)

    def log_hole_rims(self, rims: Sequence[np.ndarray]) -> None:
        """Log the holes' rims (closed lines ``(K, 3)`` [m]) static under ``scene/hole_rims``,
        where the tool view shows them without the plate (:data:`HOLE_RIMS`)."""
        self.rec.log(f"{self.root}/{HOLE_RIMS}", rr.LineStrips3D(list(rims), colors=[RIM_COLOR], radii=-PATH_RADIUS_UI),
                     static=True)

    # -- one attempt ---------------------------------------------------------------------

    def begin_attempt(
        self, part: str, hole: str, trial_seed: int, attempt: int, experiment: int | None = None
    ) -> None:
        """Start buffering an attempt; a new trial advances the ``experiment`` timeline.

        A trial is new when (part, hole, seed) changes or ``attempt`` does not grow;
        ``experiment`` (e.g. the planner's experiment number) overrides the counter.
        """
        previous = self._last_attempt
        same_trial = (
            previous is not None
            and previous[:3] == (part, hole, trial_seed)
            and attempt > previous[3]
        )
        if experiment is not None:
            self._experiment = experiment
        elif not same_trial:
            self._experiment += 1
        self._last_attempt = (part, hole, trial_seed, attempt)
        self._current = AttemptTrace(part, hole, trial_seed, attempt, self._experiment)
        self._skipped = None
        self._set_time(self._last_time)

    def log_step(
        self,
        sim_time: float,
        phase: float,
        tool_pos: np.ndarray,
        force_mes: np.ndarray,
        force_des: np.ndarray,
        torque_mes: np.ndarray,
        torque_des: np.ndarray,
    ) -> None:
        """Buffer one control step: sim time [s], DMP phase, tool tip [m], F [N], M [Nm].

        Steps within ``period_s`` of the last kept one are skipped, except the
        attempt's final step, which ``end_attempt`` keeps.
        """
        trace = self._require_attempt("log_step")
        arm_pose = None if self._arm is None else self._arm.sample()
        step = TraceStep(sim_time, phase, tool_pos, force_mes, force_des, torque_mes, torque_des, arm_pose, time.time())
        if trace.sim_time:
            if sim_time - trace.sim_time[-1] < self.period_s - _TIME_TOLERANCE:
                self._skipped = step
                return
        elif self._sent_steps and sim_time + self._time_offset <= self._last_time:
            self._time_offset = self._last_time + _ATTEMPT_GAP_S - sim_time
        trace.add(step)
        self._skipped = None

    def log_search_path(self, points: np.ndarray) -> None:
        """Buffer the hole-search path ``points`` ``(N, 3)`` [m] the search just ran: it is
        sent with the steps, at the time of the last one logged so far."""
        trace = self._require_attempt("log_search_path")
        trace.search_path = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        trace.search_step = max(len(trace.sim_time) - 1, 0)

    def end_attempt(self, evidence: AttemptEvidence) -> AttemptTrace:
        """Send the buffered steps, the search and tool paths, Fig. 17 and the outcome;
        returns the trace."""
        trace = self._require_attempt("end_attempt")
        trace.outcome = evidence.outcome
        if self._skipped is not None:
            trace.add(self._skipped)
            self._skipped = None
        if trace.sim_time:
            self._send_steps(trace)
            self._send_paths(trace)
            self._last_time = trace.sim_time[-1] + self._time_offset
            self._sent_steps = True
        self._set_time(self._last_time)
        insertion = trace.insertion()
        if len(insertion):
            ends = growth_ends(len(insertion))
            send_fig17(self.rec, fig17_path(self.cell_id, f"{trace.outcome}/{trace.key}"),
                       self._indexes(trace, insertion[ends - 1]), ends, trace.array("phase")[insertion],
                       trace.array("force_mes")[insertion], trace.array("force_des")[insertion])
        self._log_outcome(trace, evidence)
        if self.keep_traces:
            self.traces.append(trace)
        self._current = None
        return trace

    def log_ilc(self, key: str, iteration: int, norm: float) -> None:
        """After an ILC update: the size of the correction of ``key`` (part shape:hole)
        over the ``execution`` timeline (the key's ILC iteration)."""
        index = [rr.TimeColumn("execution", sequence=[iteration])]
        self.rec.send_columns(f"{self.root}/ilc/{key.replace(':', '/')}/correction_norm", indexes=index,
                              columns=rr.Scalars.columns(scalars=[norm]))

    def close(self) -> None:
        """Flush; if this logger created the stream, finish it (BridgeError naming the file
        if it could not be written) and compact the file it wrote."""
        if not self._owns_stream:
            self.rec.flush()
            return
        finish_stream(self.rec, self._rrd_path)
        if self._rrd_path is not None:
            compact_recording(self._rrd_path)

    # -- internals -----------------------------------------------------------------

    def _require_attempt(self, method: str) -> AttemptTrace:
        if self._current is None:
            raise ExecutorError(f"AttemptLogger.{method}: call begin_attempt first")
        return self._current

    def _set_time(self, sim_time: float) -> None:
        self.rec.set_time("experiment", sequence=self._experiment)
        self.rec.set_time("sim_time", duration=sim_time)

    def _indexes(self, trace: AttemptTrace, rows: np.ndarray | None = None) -> list[rr.TimeColumn]:
        """The times of ``trace``'s steps ``rows`` (every step when None) on ``experiment``,
        ``sim_time`` (the logged, increasing one) and ``log_time``."""
        times, wall = trace.array("sim_time") + self._time_offset, trace.array("wall_time")
        if rows is not None:
            times, wall = times[rows], wall[rows]
        return [rr.TimeColumn("experiment", sequence=np.full(len(times), trace.experiment)),
                rr.TimeColumn("sim_time", duration=times), rr.TimeColumn(SESSION_TIMELINE, timestamp=wall)]

    def _send_paths(self, trace: AttemptTrace) -> None:
        """The attempt's tool path and search path, each starting empty at its first step (the
        previous attempt's are not drawn in this one): the tool path growing
        (:func:`growth_ends`), each row the path up to its time, grey while the attempt runs
        and whole in the outcome's colour at its last step; the search path from the step
        the search ended at."""
        tip = trace.array("tool_pos")
        ends = growth_ends(len(tip)) if len(tip) >= 2 else np.zeros(0, dtype=np.int64)
        colors = [PATH_COLOR] * (len(ends) - 1) + [outcome_color(trace.outcome)] * min(len(ends), 1)
        self._send_strips("tool/path", trace, [0, *(ends - 1)], [tip[:end] for end in ends], colors)
        search = [] if trace.search_path is None else [trace.search_path]
        self._send_strips("search/path", trace, sorted({0, trace.search_step}), search, [SEARCH_COLOR] * len(search))

    def _send_strips(self, path: str, trace: AttemptTrace, rows: Sequence[int], strips: Sequence[np.ndarray],
                     colors: Sequence[Sequence[int]]) -> None:
        """Lines under ``path`` at the times of ``trace``'s steps ``rows``: none at the first
        row when there are more rows than ``strips``, then one strip a row."""
        empty = len(rows) - len(strips)
        self.rec.send_columns(f"{self.root}/{path}", indexes=self._indexes(trace, np.array(rows, dtype=np.int64)),
                              columns=rr.LineStrips3D.columns(strips=strips, colors=colors,
                                                              radii=np.full(len(strips), -PATH_RADIUS_UI))
                              .partition([0] * empty + [1] * len(strips)))

    def _send_steps(self, trace: AttemptTrace) -> None:
        timed = self._indexes(trace)
        count = len(trace.sim_time)
        label = f"{trace.part}→{trace.hole} s{trace.trial_seed} a{trace.attempt} {trace.outcome}"
        for quantity, measured, desired in (
            ("force", "force_mes", "force_des"), ("torque", "torque_mes", "torque_des"),
        ):
            mes, des = trace.array(measured), trace.array(desired)
            self._series(f"wrench/{quantity}/measured", timed, mes, quantity, "", MEASURED_COLORS)
            self._series(f"wrench/{quantity}/desired", timed, des, quantity, " des", DESIRED_COLORS)
            entity = f"{self.root}/deviation/{quantity}/{trace.key}"
            self.rec.log(entity, rr.SeriesLines(names=[label], colors=[outcome_color(trace.outcome)]), static=True)
            self.rec.send_columns(entity, indexes=timed,
                                  columns=rr.Scalars.columns(scalars=np.linalg.norm(mes - des, axis=1)))
        self.rec.send_columns(
            f"{self.root}/phase", indexes=timed,
            columns=rr.Scalars.columns(scalars=trace.array("phase")),
        )
        if self._arm is not None and len(trace.arm_poses) == count:
            self._arm.send(self.rec, self.root, timed, np.stack(trace.arm_poses))
        tip = trace.array("tool_pos")
        self._style("tool/tip", rr.Points3D.from_fields(radii=-TIP_RADIUS_UI, colors=TIP_COLOR))
        self.rec.send_columns(f"{self.root}/tool/tip", indexes=timed,
                              columns=rr.Points3D.columns(positions=tip).partition([1] * count))
        self._style("tool/force", rr.Arrows3D.from_fields(radii=-FORCE_RADIUS_UI, colors=FORCE_COLOR))
        self.rec.send_columns(
            f"{self.root}/tool/force", indexes=timed,
            columns=rr.Arrows3D.columns(origins=tip, vectors=trace.array("force_mes") * FORCE_ARROW_M_PER_N)
            .partition([1] * count),
        )

    def _style(self, path: str, style: rr.AsComponents) -> None:
        """Log ``style`` (colours, radii) on ``path`` static, once per recording."""
        entity = f"{self.root}/{path}"
        if entity not in self._styled:
            self.rec.log(entity, style, static=True)
            self._styled.add(entity)

    def _series(
        self, path: str, indexes: list[rr.TimeColumn], values: np.ndarray, quantity: str,
        suffix: str, colors: list[list[int]],
    ) -> None:
        """Send an ``(N, 3)`` signal as three named plot series under ``path``."""
        entity = f"{self.root}/{path}"
        unit = "N" if quantity == "force" else "Nm"
        names = [f"{name}{suffix} [{unit}]" for name in AXIS_NAMES[quantity]]
        self._style(path, rr.SeriesLines(names=names, colors=colors))
        self.rec.send_columns(entity, indexes=indexes, columns=rr.Scalars.columns(scalars=values))

    def _log_outcome(self, trace: AttemptTrace, evidence: AttemptEvidence) -> None:
        text = (
            f"{trace.part}→{trace.hole} seed {trace.trial_seed} attempt {trace.attempt}: "
            f"{evidence.outcome} (max ΔF {evidence.max_force_dev:.1f} N, "
            f"max ΔM {evidence.max_torque_dev:.2f} Nm, end error "
            f"{1000 * evidence.end_error:.1f} mm, phase {evidence.phase_reached:.2f}, "
            f"jammed {evidence.jammed}, wiggles {evidence.wiggles}, "
            f"{evidence.sim_time_s:.2f} s sim, {evidence.duration_s:.2f} s wall)"
        )
        level = "INFO" if evidence.outcome == "fit" else "WARN"
        self.rec.log(f"{self.root}/outcome", rr.TextLog(text, level=level))
        for name, value in (
            ("fit", 1.0 if evidence.outcome == "fit" else 0.0),
            ("max_force_dev", evidence.max_force_dev),
            ("max_torque_dev", evidence.max_torque_dev),
            ("end_error", evidence.end_error),
            ("phase_reached", evidence.phase_reached),
        ):
            self.rec.log(f"{self.root}/result/{name}", rr.Scalars(float(value)))
