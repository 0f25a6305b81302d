"""The simulated assembly cell (paper section 3): PyBullet scene, torque-mode Cartesian
impedance arm, hole search, DMP insertion with admittance and phase stopping, failure
detection (eqs. 6, 7 and the goal check) and the wiggle exception strategy.

Entry points: :class:`executor.trial.Cell` (``run_trial``) and the ``executor`` subcommand
of the command line (:mod:`executor.cli`).
Layers, each importing only those before it: :mod:`executor.world` (geometry, PyBullet
scene, arm), :mod:`executor.control` (impedance controller, admittance, detector, motion
stepper), :mod:`executor.skills` (DMP, hole search, insertion, wiggle, teaching), the
records in :mod:`executor.evidence`, the Rerun log :mod:`executor.rerun_log`, the trial
:mod:`executor.trial`, and on top :mod:`executor.campaign`, :mod:`executor.serve` (with
the backend interface :mod:`executor.backends` and the replay backend :mod:`executor.replay`)
and :mod:`executor.cli`; beside them :mod:`executor.cad`, a product from its CAD (on
:mod:`executor.world` and :mod:`executor.assembly`).  One exception: teaching (:mod:`executor.skills.teach`) drives a
:class:`executor.trial.Cell` to record the skills the trial then uses.
"""


from bridge.errors import ToolError


class ExecutorError(ToolError):
    """Base error of the executor: a bad part/hole id, a missing demonstration, bad data.

    The message names the bad value and what was expected; the command line prints
    ``error: <message>`` and exits with code 2.
    """
