"""Tolerances for comparing floating point results of another process (maybe another CPU,
another libm) with this one's, each from the physics it must not change. Within one
process results may be compared exactly; across processes never bit for bit.

The tightest clearance of the shipped products is 0.1 mm (the tight peg); the detector's
thresholds are F_stop 30 N, M_stop 4.5 Nm and the 3 mm goal tolerance, chosen with
margins over the largest fitting deviations (25.8 N, 3 Nm; docs/cell.md "Thresholds").
"""

from __future__ import annotations

# A scripted, contact-free path moves by rounding only: a tenth of the 0.1 mm clearance
# cannot change whether a part passes.
PATH_BOUND = 1e-5  # [m]
# Positions that come out of a 0.1 mm-clearance contact, where chatter amplifies last-bit
# differences (36 µm measured on another x86-64 CPU): bounded by that clearance, a
# thirtieth of the goal tolerance.
END_BOUND = 1e-4  # [m]
# A force or torque moved by less than the margin between its threshold and the largest
# fitting deviation (30 − 25.8 N, 4.5 − 3 Nm) keeps every fit a fit; measured across CPUs:
# 0.76 N and 0.13 Nm (the tight peg's reference wrench), 2e-4 N (the square peg's).
FORCE_BOUND = 4.0  # [N]
TORQUE_BOUND = 1.5  # [Nm]
# Generated meshes print vertices to 1 µm; a transcendental (cos, sin) that differs in its
# last bit can flip the last printed digit: one digit, a hundredth of the clearance.
MESH_BOUND = 1.5e-6  # [m]


def assert_same_asset(actual: str, expected: str) -> None:
    """Generated asset texts agree: every line equal, except that the coordinates of OBJ
    vertex lines (``v x y z``, from cos and sin) may differ by ``MESH_BOUND``. URDFs are
    pure arithmetic of decimal inputs printed with fixed digits, so they match exactly."""
    got, want = actual.splitlines(), expected.splitlines()
    assert len(got) == len(want), f"{len(got)} lines, expected {len(want)}"
    for number, (a, b) in enumerate(zip(got, want), start=1):
        if a.startswith("v ") and b.startswith("v "):
            moved = max(abs(float(x) - float(y)) for x, y in zip(a.split()[1:], b.split()[1:], strict=True))
            assert moved <= MESH_BOUND, f"line {number}: {a!r}, expected {b!r}"
        else:
            assert a == b, f"line {number}: {a!r}, expected {b!r}"
