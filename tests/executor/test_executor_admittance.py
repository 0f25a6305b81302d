"""The admittance's PI law: a persisting deviation keeps moving the offset (integral),
up to the bound; the integral holds the offset that cancelled a deviation, and an
opposite deviation unwinds it back to the reference."""

from __future__ import annotations

import numpy as np

from executor.control.admittance import Admittance, AdmittanceParams

DT = 0.001  # [s], the control period


def run(adm: Admittance, force_x: float, seconds: float) -> float:
    """Offset along x [m] after ``seconds`` of a constant lateral force deviation [N]."""
    for _ in range(round(seconds / DT)):
        offset, _rot = adm.update(np.array([force_x, 0.0, 0.0]), np.zeros(3), DT)
    return float(offset[0])


def test_a_persisting_deviation_is_integrated_beyond_the_proportional_answer() -> None:
    params = AdmittanceParams()
    adm = Admittance(params)
    proportional = 1.0 / params.stiffness  # steady offset of the spring alone for 1 N [m]
    early = run(adm, 1.0, 0.2)
    later = run(adm, 1.0, 0.8)
    assert early > 0.5 * proportional
    assert later > early * 1.5  # the integral keeps adapting while the deviation persists
    assert run(adm, 200.0, 1.0) == params.bound  # bounded


def test_the_integral_holds_the_offset_and_an_opposite_deviation_unwinds_it() -> None:
    adm = Admittance(AdmittanceParams())
    pushed = run(adm, 1.0, 0.5)
    assert pushed > 0
    held = run(adm, 0.0, 1.0)
    assert 0.5 * pushed < held <= pushed  # integral action: no deviation, offset kept
    assert run(adm, -1.0, 0.5) < 0.2 * pushed  # the opposite deviation brings it back


def test_p_only_admittance_holds_no_integral() -> None:
    """Integral gain 0 (the ``admittance_p`` layer): the offset settles at ΔF / K and
    nothing is kept once the deviation is gone."""
    params = AdmittanceParams(integral_gain=0.0)
    adm = Admittance(params)
    assert abs(run(adm, 1.0, 1.0) - 1.0 / params.stiffness) < 0.05 / params.stiffness
    assert abs(run(adm, 0.0, 1.0)) < 0.05 / params.stiffness
