"""The simulated assembly cell (paper section 3): PyBullet scene, torque-mode Cartesian
impedance arm, hole search, DMP insertion with admittance and phase stopping, failure
detection (eqs. 6, 7 and the goal check) and the wiggle exception strategy.

Entry points: :class:`assembly_constraints.executor.trial.Cell` (``run_trial``) and the ``executor`` subcommand
of the command line (:mod:`assembly_constraints.executor.cli`).
Layers, each importing only those before it: :mod:`assembly_constraints.executor.world` (geometry, PyBullet
scene, arm), :mod:`assembly_constraints.executor.control` (impedance controller, admittance, detector, motion
stepper), :mod:`assembly_constraints.executor.skills` (DMP, hole search, insertion, wiggle, teaching), the
records in :mod:`assembly_constraints.executor.evidence`, the Rerun log :mod:`assembly_constraints.executor.rerun_log`, the trial
:mod:`assembly_constraints.executor.trial`, and on top :mod:`assembly_constraints.executor.campaign`, :mod:`assembly_constraints.executor.serve` (with
the backend interface :mod:`assembly_constraints.executor.backend_plugin` and the replay backend :mod:`assembly_constraints.executor.replay`)
and :mod:`assembly_constraints.executor.cli`; beside them :mod:`assembly_constraints.executor.cad`, a product from its CAD (on
:mod:`assembly_constraints.executor.world` and :mod:`assembly_constraints.executor.assembly`).  One exception: teaching (:mod:`assembly_constraints.executor.skills.teach`) drives a
:class:`assembly_constraints.executor.trial.Cell` to record the skills the trial then uses.
"""


from assembly_constraints.bridge.errors import ToolError


class ExecutorError(ToolError):
    """Base error of the executor: a bad part/hole id, a missing demonstration, bad data.

    The message names the bad value and what was expected; the command line prints
    ``error: <message>`` and exits with code 2.
    """
