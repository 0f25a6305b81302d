"""The execution layers and ILC (paper 3.1/3.2): each switch changes what the controller
does, ILC converges on a repeated pair, and its state survives a restart of the cell."""

from __future__ import annotations

import json

import numpy as np
import pybullet as pb
import pytest

from bridge.cell_settings import Magnitudes
from executor.cell_description import CellDescription
from executor.control.detector import Thresholds
from executor.control.gains import POSITION_CONTROL_GAINS, ImpedanceGains
from executor.control.ilc import LAYERS, ExecutionTrace, Ilc
from executor.evidence import AttemptSetup
from executor.skills.insertion import rotvec_quat_xyzw
from executor.trial import Cell, CellSetup
from executor.world.arm import TOOL_DOWN_QUAT_XYZW, rotation_error
from executor.world.perturbation import NO_PERTURBATION

# The tight peg tilted 2° in the hand, otherwise exact: it touches the walls all the way down.
TILTED = AttemptSetup(np.zeros(3), np.array([np.radians(2.0), 0.0, 0.0]), np.zeros(2), search_seed=1)
# The systematic part only (a 2.5° habitual tilt): every execution of a pair meets the same errors.
SYSTEMATIC_ONLY = Magnitudes(grasp_offset_random=0.0, grasp_tilt_bias=2.5, grasp_tilt_random=0.0,
                             vision_sigma=0.0, friction_jitter=0.0)


def _ilc() -> Ilc:
    """An ILC with the default cell description's parameters, gains and bounds."""
    d = CellDescription()
    return Ilc(d.ilc, d.gains, d.admittance)


@pytest.fixture(scope="module")
def cell():
    c = Cell(setup=CellSetup(magnitudes=NO_PERTURBATION))
    yield c
    c.close()


@pytest.mark.slow
def test_every_layer_switch_changes_the_execution(cell):
    """The same attempt under each layer: the wrench it meets differs from the layer
    below; with ILC, the second execution differs from the first.  Pure position control
    tracks stiffly (an industrial arm's servo): the tilted tight peg wedges past F_stop
    and does not fit, where every adapting layer fits it; the search and the release
    stay on the compliant impedance."""
    seen = {}
    controller = cell.motion_for("tp").controller
    for name in LAYERS:
        cell.reset_state(layer=name, magnitudes=NO_PERTURBATION)
        seen[name] = cell.run_attempt("tp", "r1", TILTED)
        assert controller.gains == ImpedanceGains()
    assert [name for name, layer in LAYERS.items() if layer.stiff] == ["position"]
    assert POSITION_CONTROL_GAINS.k_trans >= 10 * ImpedanceGains().k_trans
    assert POSITION_CONTROL_GAINS.k_rot >= 10 * ImpedanceGains().k_rot
    assert seen["position"].outcome == "no_fit" and seen["position"].max_force_dev >= Thresholds().f_stop
    assert all(seen[name].outcome == "fit" for name in list(LAYERS)[1:])
    names = list(LAYERS)
    for lower, upper in zip(names, names[1:-1]):
        a, b = seen[lower], seen[upper]
        assert (a.max_force_dev, a.max_torque_dev, a.sim_time_s) != (b.max_force_dev, b.max_torque_dev, b.sim_time_s)
    # The first execution with ILC has nothing learned yet; the second starts from the correction.
    assert seen["full"].max_force_dev == seen["pi_phase_stop"].max_force_dev
    second = cell.run_attempt("tp", "r1", TILTED)
    assert second.max_force_dev != seen["full"].max_force_dev
    assert second.ilc_iteration == 1 and second.ilc_correction_norm > 0


@pytest.mark.slow
def test_stiff_tracking_settles_at_the_cell_time_step(cell):
    """The position layer's gains are stable at 1 ms: a 1 mm step along x and z and a 1°
    step about x (tilt) and z (the tool axis, the lightest inertia) in free space over
    the plate settle to 5 % within 150 ms, with less than 20 % overshoot."""
    motion = cell.motion_for("tp")
    controller = motion.controller
    start = np.array([*cell.geometry.holes["r1"].position[:2], cell.geometry.plate.top_z + 0.02])
    steps = {0: (np.array([1e-3, 0, 0]), np.zeros(3)), 2: (np.array([0, 0, 1e-3]), np.zeros(3)),
             3: (np.zeros(3), np.radians([1.0, 0, 0])), 5: (np.zeros(3), np.radians([0, 0, 1.0]))}
    try:
        for axis, (d_pos, d_rot) in steps.items():
            controller.arm.inverse_kinematics(start, TOOL_DOWN_QUAT_XYZW)
            controller.reset()
            controller.gains = POSITION_CONTROL_GAINS
            motion.hold(start, TOOL_DOWN_QUAT_XYZW, 0.1)
            quat = np.array(pb.multiplyTransforms((0, 0, 0), rotvec_quat_xyzw(d_rot), (0, 0, 0),
                                                  TOOL_DOWN_QUAT_XYZW)[1])
            error = []
            for _ in range(300):
                s = motion.step(start + d_pos, quat)
                error.append(np.concatenate([start + d_pos - s.tip_pos, rotation_error(quat, s.tip_quat_xyzw)])[axis])
            relative = np.array(error) / error[0]
            assert relative.min() > -0.2, (axis, relative.min())
            assert np.all(np.abs(relative[150:]) < 0.05), (axis, np.abs(relative[150:]).max())
    finally:
        controller.gains = ImpedanceGains()


ILC_EXECUTIONS = 6
"""Executions of the repeated pair in the ILC test."""
ILC_BEST_RATIO = 0.8
"""The ILC test's bound on the smallest largest force deviation of the executions after the
first, as a fraction of the first's."""


@pytest.mark.slow
def test_ilc_converges_on_a_repeated_pair(cell, tmp_path):
    """Tight peg in the square hole (0.1 mm clearance on the flats), the same 2.5° habitual
    tilt every time: the learned correction brings the force deviation well below the
    first execution's, and it is saved, reloaded and used by a restarted cell.

    An execution's largest force deviation is the peak of a contact: with ILC it scatters
    by up to 40 % from one execution to the next (9.4 N first; then 5.3-10.5 N, and an arm
    started 1e-8 rad off in its joints draws another sequence), so no single execution is
    asserted. The smallest of the five after the first was 0.56-0.68 of the first over six
    such starts; without ILC every execution repeats the first (9.4 N, 11.2 N at most),
    1.0 or more. The bound ``ILC_BEST_RATIO`` sits between."""
    state = tmp_path / "c1-ilc.json"
    cell.ilc_state = state
    try:
        cell.reset_state(layer="full", magnitudes=SYSTEMATIC_ONLY)
        runs = [cell.run_trial("tp", "s1", seed) for seed in range(ILC_EXECUTIONS)]
    finally:
        cell.ilc_state = None
    assert all(r.outcome == "fit" and r.attempts == 1 for r in runs)
    forces = [r.evidence[0].max_force_dev for r in runs]
    assert min(forces[1:]) < ILC_BEST_RATIO * forces[0], forces
    assert [r.evidence[0].ilc_iteration for r in runs] == list(range(ILC_EXECUTIONS))
    saved = json.loads(state.read_text())["keys"]
    assert saved["tight_peg:s1"]["iterations"] == ILC_EXECUTIONS
    restarted = Cell(setup=CellSetup(magnitudes=SYSTEMATIC_ONLY), ilc_state=state)
    try:
        correction, iteration = restarted.ilc.correction("tight_peg:s1")
        assert iteration == ILC_EXECUTIONS and np.array_equal(correction, cell.ilc.correction("tight_peg:s1")[0])
        assert restarted.run_trial("tp", "s1", ILC_EXECUTIONS).evidence[0].ilc_iteration == ILC_EXECUTIONS
    finally:
        restarted.close()


def test_ilc_update_learns_against_the_error_and_round_trips(tmp_path):
    ilc = _ilc()
    trace = ExecutionTrace()
    for k in range(1000):  # a constant +2 N lateral x deviation and +0.1 Nm about y
        trace.add(k / 1000, np.array([2.0, 0.0, 0.0, 0.0, 0.1]))
    learned = ilc.update("round_peg:r1", trace)
    assert np.all(learned[:, 0] > 0) and np.all(learned[:, 4] > 0)  # moves with the force, as the admittance
    assert np.allclose(learned[:, 1:4], 0.0)
    again = ilc.update("round_peg:r1", trace)
    assert np.all(again[:, 0] > learned[:, 0])  # the error persisted: learns further
    path = tmp_path / "ilc.json"
    ilc.save(path)
    other = _ilc()
    other.load(path)
    assert other.iterations == {"round_peg:r1": 2}
    assert np.array_equal(other.correction("round_peg:r1")[0], again)  # exact: resumed as if never stopped


@pytest.mark.slow
def test_the_served_cell_saves_and_reloads_its_corrections(tmp_path):
    """``executor serve --ilc-state``: the sim backend saves after a successful execution;
    a restarted backend (a resumed session's cell) starts from the saved corrections."""
    from bridge.cell_settings import ServeSettings
    from bridge.messages import InsertRequest
    from executor.serve.sim import SimBackend
    from executor.trial import cell_setup

    state = tmp_path / "c1-ilc.json"
    settings = ServeSettings(ilc_state=str(state))
    backend = SimBackend(settings, cell_setup(settings.cell))
    try:
        result, _evidence = backend.run(InsertRequest(id="r1", part="p1", hole="r1", seed=3))
    finally:
        backend.close()
    assert result == "fit"
    restarted = SimBackend(settings, cell_setup(settings.cell))
    try:
        assert restarted._cell.ilc.iterations == {"round_peg:r1": 1}
    finally:
        restarted.close()


def test_a_corrupt_ilc_state_is_refused_naming_the_file(tmp_path):
    from executor import ExecutorError

    path = tmp_path / "c1-ilc.json"
    path.write_text('{"keys": {"round_peg:r1": {"iterations": 1, "correction": [[0.0]]}}}')
    with pytest.raises(ExecutorError, match='c1-ilc.json: "keys" "round_peg:r1" correction: expected a list of 50'):
        _ilc().load(path)
