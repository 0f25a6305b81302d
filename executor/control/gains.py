"""The impedance controller's gains (:mod:`executor.control.controller`), here without
PyBullet so the cell description can be read without loading the simulator."""

from __future__ import annotations

from typing import Annotated

import msgspec

Gain = Annotated[float, msgspec.Meta(gt=0.0, le=1e6, description="a number in (0, 1e6]")]
"""A stiffness or damping of the controller (units in :class:`ImpedanceGains`)."""


class ImpedanceGains(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """Stiffness and damping: translation [N/m, N·s/m], rotation [Nm/rad, Nm·s/rad],
    null-space posture [Nm/rad, Nm·s/rad]."""

    k_trans: Gain = 2000.0
    d_trans: Gain = 90.0
    k_rot: Gain = 60.0
    d_rot: Gain = 2.5
    k_null: Gain = 2.0
    d_null: Gain = 0.3


POSITION_CONTROL_GAINS = ImpedanceGains(k_trans=20000.0, d_trans=580.0, k_rot=600.0, d_rot=8.0)
"""Stiff tracking: what pure position control is on an industrial arm (a joint servo whose
stiffness seen at the tool is of the order of 10⁴–10⁵ N/m, hundreds of Nm/rad and more).
D_t = 2·√(K_t·m) with the lightest effective tip mass of the arm at the plate, m ≈ 4.2 kg
(4.2–10.3 kg: critically damped to ζ ≈ 0.64); D_r gives ζ ≈ 0.37 about the tilt axes
(effective inertia ≈ 0.19–0.30 kg·m² over the arm's poses at the plate) and stays below 2·I/Δt = 10 Nm·s/rad,
where the explicit 1 ms step becomes unstable about the tool axis (I ≈ 0.005 kg·m²).
docs/cell.md ("Execution layers") says why."""
