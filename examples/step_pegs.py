"""A small product as a designer would send it: a STEP assembly made with build123d.

    .venv/bin/python examples/step_pegs.py OUT.step

A 100 x 60 x 20 mm plate with three holes (round 13.3 mm, a 12.3 x 8.3 mm slot turned by
30°, an empty 9 mm square; 15 mm deep, 0.8 mm entry chamfers) and two pegs in the
assembled pose (round 12 mm, rect 12 x 8 mm), placed where the simulated arm reaches
(the CAD frame is the cell frame). ``./run.sh import OUT.step --out DIR`` makes an
assembly folder of it (docs/import.md).
"""

from __future__ import annotations

import sys

from build123d import Axis, Box, Compound, Cylinder, Pos, Rot, chamfer, export_step


def main(out: str) -> None:
    plate = Box(100, 60, 20) - Pos(-20, 0, 2.5) * Cylinder(6.65, 15)
    plate = plate - Pos(20, 0, 2.5) * Rot(0, 0, 30) * Box(12.3, 8.3, 15)
    plate = plate - Pos(0, 20, 2.5) * Box(9, 9, 15)
    top = plate.faces().sort_by(Axis.Z)[-1]
    plate = chamfer([edge for wire in top.inner_wires() for edge in wire.edges()], length=0.8)
    at = Pos(550, 0, 10)  # [mm]: the plate's centre 0.55 m in front of the arm, on the table
    plate = at * plate
    peg = at * Pos(-20, 0, 10) * Cylinder(6.0, 30)
    rect = at * Pos(20, 0, 10) * Rot(0, 0, 30) * Box(12, 8, 30)
    plate.label, peg.label, rect.label = "plate", "round peg", "rect peg"
    export_step(Compound(label="pegs", children=[plate, peg, rect]), out)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
