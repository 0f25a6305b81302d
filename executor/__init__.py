"""The simulated assembly cell (paper section 3): PyBullet scene, torque-mode Cartesian
impedance arm, hole search, DMP insertion with admittance and phase stopping, failure
detection (eqs. 6, 7 and the goal check) and the wiggle exception strategy.

Entry points: :class:`executor.trial.Cell` (``run_trial``) and ``python -m executor.cli``.
"""


class ExecutorError(Exception):
    """Base error of the executor: a bad part/hole id, a missing demonstration, bad data.

    The message names the bad value and what was expected; the command line prints
    ``error: <message>`` and exits with code 2.
    """
