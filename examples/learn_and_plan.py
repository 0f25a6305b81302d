"""Learn Cranfield's constraints and plan with the Python API (docs/api.md).

    python examples/learn_and_plan.py [FOLDER]

Learns precedence from the demonstrations, learns which part fits which hole by asking
an oracle (here the assembly's known sizes; a real cell would run the insertion), writes
the learned facts to FOLDER/learned.lp (default: the working folder) and prints a plan.
"""

from __future__ import annotations

import sys
from pathlib import Path

from assembly_constraints import api


def main(folder: Path) -> None:
    relation = api.learn_precedence("cranfield")
    print(f"learned {len(relation.pairs())} must-precede pairs from the demonstrations")

    truth = api.truth_oracle("cranfield")
    asked: list[str] = []

    def insert(part: str, hole: str) -> api.Result:
        """Stands in for a robot: one insertion attempt of ``part`` into ``hole``."""
        asked.append(f"{part}->{hole}")
        return truth.ask(part, hole)

    sizes = api.learn_sizes(insert, truth.parts, truth.holes, policy="best")
    print(f"{len(asked)} experiments: {' '.join(asked)}")
    print("fits:", " ".join(f"{p}->{h}" for p, h in sorted(sizes.knowledge.fits)))

    facts = api.write_facts(folder / "learned.lp", relation, sizes)
    plan = api.plan([facts])[0]
    print("plan:", " ".join(step.part + (f"->{step.hole}" if step.hole else "") for step in plan.steps))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path.cwd())
