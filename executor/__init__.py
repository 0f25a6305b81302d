"""The simulated assembly cell (paper section 3): PyBullet scene, torque-mode Cartesian
impedance arm, hole search, DMP insertion with admittance and phase stopping, failure
detection (eqs. 6, 7 and the goal check) and the wiggle exception strategy.

Entry points: :class:`executor.trial.Cell` (``run_trial``) and the
``executor`` subcommand of the command line (:mod:`executor.cli`).
Layers (modules of this package), each importing only those before it: ``world`` (geometry,
PyBullet scene, arm), ``control`` (impedance controller, admittance, detector, motion
stepper), ``skills`` (DMP, hole search, insertion, wiggle, teaching), the records in
``evidence``, the Rerun log ``rerun_log``, the trial ``trial``, and on top ``campaign``,
``serve`` (with the backend interface ``backend_plugin`` and the replay backend ``replay``)
and ``cli``; beside them ``cad``, a product from its CAD (on ``world`` and ``assembly``), and
``franka``, the same skills on a Franka arm through franky (the arm behind
``control.motion.ArmController``; a ``serve`` backend) and franky-sim with the product.
Teaching (``skills.teach``) drives any cell with a hand (its ``TeachingCell`` protocol,
which ``trial.Cell`` and ``franka.teach.FrankaTeacher`` meet) to record the skills the
trial then uses.
"""


from bridge.errors import ToolError


class ExecutorError(ToolError):
    """Base error of the executor: a bad part/hole id, a missing demonstration, bad data.

    The message names the bad value and what was expected; the command line prints
    ``error: <message>`` and exits with code 2.
    """


class UnknownPair(ExecutorError):
    """The request names a part or hole the cell does not have."""
