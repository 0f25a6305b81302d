"""``./run.sh bench TOPIC``: benchmarks print their figures (medians, ratios).

Each topic lives in its own module exposing ``main(argv) -> int``; ``bench executor``
is routed by run.sh to the cell's benchmark.
"""

from __future__ import annotations

import importlib
import sys

TOPICS: dict[str, str] = {
    "precedence": "asp.bench.precedence",
    "sizes": "asp.bench.sizes",
    "plan": "asp.bench.plans",
    "session": "asp.bench.session",
    "dominance": "asp.bench.dominance",
    "mesh": "asp.bench.mesh",
    "precedence-physics": "asp.bench.precedence_physics",
    "assemble": "asp.bench.assemble_plans",
}


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: ./run.sh bench {precedence,sizes,plan,executor,session,dominance,mesh,assemble,"
              "precedence-physics} [--help]")
        return 0
    topic = argv[0]
    if topic not in TOPICS:
        print(f"error: unknown benchmark '{topic}'; expected one of: {', '.join([*TOPICS, 'executor'])}",
              file=sys.stderr)
        return 2
    return int(importlib.import_module(TOPICS[topic]).main(argv[1:]) or 0)
