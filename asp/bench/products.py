"""Generated products for load benchmarks: n round pegs and n round holes of random sizes.

:func:`write_product` writes an assembly folder the session and the cells accept as they
accept ``data/cranfield``: ``assembly.toml`` (pegs on a tray, holes on a plate),
``geometry.toml`` (one round shape per peg and per hole, so the cell's ``truth`` backend
answers from cross-sections), ``sizes.lp`` (the same relation as facts, the session's
ground truth), ``precedence.lp`` (none required) and ``demos.txt`` (two random orders).

Sizes: peg diameters are drawn uniformly in [10, 30] mm; hole i is peg i's diameter plus a
clearance drawn in [0.1, 3] mm, so peg i fits hole i (a complete assignment exists) and,
all shapes being round, the relation "diameter < diameter" is a biorder, as the learner
assumes. Ids are shuffled so that index order tells nothing.
"""

from __future__ import annotations

import random
import tomllib
from pathlib import Path

from asp.solve import fact, write_facts
from bridge.assembly import DATA_DIR

_TEMPLATE = DATA_DIR / "cranfield" / "geometry.toml"


def _toml_table(name: str, entries: dict[str, object]) -> str:
    """One TOML table of scalars, strings and lists of them."""
    def value(v: object) -> str:
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return repr(v)

    return f"[{name}]\n" + "".join(f"{key} = {value(v)}\n" for key, v in entries.items()) + "\n"


def write_product(folder: Path, n: int, seed: int) -> dict[str, list[str]]:
    """Write an n-peg, n-hole product into ``folder`` (created); returns its part and hole ids."""
    rng = random.Random(seed)
    folder.mkdir(parents=True, exist_ok=True)
    pegs = [f"p{i:02d}" for i in range(1, n + 1)]
    holes = [f"h{i:02d}" for i in range(1, n + 1)]
    diameters = sorted(rng.uniform(0.010, 0.030) for _ in range(n))
    clearances = [rng.uniform(0.0001, 0.003) for _ in range(n)]
    rng.shuffle(pegs)
    rng.shuffle(holes)
    peg_size = dict(zip(pegs, diameters))
    hole_size = {hole: d + c for hole, d, c in zip(holes, diameters, clearances)}
    columns = max(1, round(n**0.5))
    layout = [f'name = "generated product, {n} pegs and {n} holes (seed {seed})"\n\n']
    for k, peg in enumerate(sorted(pegs)):
        layout.append(_toml_table(f"parts.{peg}", {"name": f"peg {peg}", "role": "peg",
                                                   "start": [0.2 + 0.04 * (k % columns), 0.4 + 0.04 * (k // columns)]}))
    for k, hole in enumerate(sorted(holes)):
        layout.append(_toml_table(f"holes.{hole}", {"name": f"hole {hole}", "shape": "round",
                                                    "position": [0.5 + 0.04 * (k % columns),
                                                                 -0.1 + 0.04 * (k // columns)]}))
    (folder / "assembly.toml").write_text("".join(layout), encoding="utf-8")
    template = tomllib.loads(_TEMPLATE.read_text(encoding="utf-8"))
    geometry = [_toml_table("plate", template["plate"])]
    for hole in sorted(holes):
        geometry.append(_toml_table(f"hole_shapes.{hole}", {"holes": [hole], "kind": "round",
                                                            "size": round(hole_size[hole], 6)}))
    for peg in sorted(pegs):
        demo_hole = min((h for h in holes if peg_size[peg] < hole_size[h]), key=hole_size.__getitem__)
        geometry.append(_toml_table(f"part_shapes.{peg}", {"parts": [peg], "kind": "round",
                                                           "size": round(peg_size[peg], 6), "length": 0.05,
                                                           "mass": 0.05, "demo_hole": demo_hole}))
    (folder / "geometry.toml").write_text("".join(geometry), encoding="utf-8")
    parts = [fact("part", peg) for peg in sorted(pegs)]
    fits = [fact("fits", p, h) for p in sorted(pegs) for h in sorted(holes)
            if round(peg_size[p], 6) < round(hole_size[h], 6)]
    write_facts(folder / "sizes.lp", [*parts, *(fact("hole", hole) for hole in sorted(holes)), *fits])
    write_facts(folder / "precedence.lp", parts, header="No precedence constraints: any order.")
    orders = [rng.sample(pegs, n) for _ in range(2)]
    (folder / "demos.txt").write_text("".join(" ".join(order) + "\n" for order in orders), encoding="utf-8")
    return {"parts": sorted(pegs), "holes": sorted(holes)}
