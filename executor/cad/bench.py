"""``./run.sh bench import``: import plus geometric precedence of a generated product.

The product (``--parts N``, 6 to 200, default 20): a plate with ``N - 3`` holes on a grid, round
(d 8 mm, 24-gon) and rectangular (12 x 8 mm, turned by 30°) in turn, a peg in each with
0.3 mm clearance; the pegs of the first row stand 15 mm out, the others 25 mm; two 4 mm
covers, one lying on the first row, the other on it, each with openings for the others
(which pass through both). Written as STL files in mm, then imported
(:func:`assembly_constraints.executor.cad.cli.run_import`) ``--repeat`` times. Prints the median wall and CPU
time of the import, the collision queries and the edges found; exit code 1 when the
median CPU time (the process's, all its threads: what one core would need) exceeds
``--target``. The wall time is printed too: on a shared machine it also counts the
waits for a core.
"""

from __future__ import annotations

import math
import statistics
import tempfile
import time
from pathlib import Path

import trimesh

from assembly_constraints.bridge.cli_types import ArgumentParser, int_in, number_in
from assembly_constraints.executor.cad.cli import run_import

PITCH = 30.0  # grid pitch of the holes [mm]
DEPTH = 15.0  # hole depth [mm]; the plate is 20 mm thick


def _box(extents: tuple[float, float, float], centre: tuple[float, float, float], yaw: float = 0.0
         ) -> trimesh.Trimesh:
    box = trimesh.creation.box(extents)
    box.apply_transform(trimesh.transformations.rotation_matrix(math.radians(yaw), (0, 0, 1)))
    box.apply_translation(centre)
    return box


def _cylinder(radius: float, height: float, centre: tuple[float, float, float]) -> trimesh.Trimesh:
    cylinder = trimesh.creation.cylinder(radius=radius, height=height, sections=24)
    cylinder.apply_translation(centre)
    return cylinder


def write_product(folder: Path, parts: int) -> None:
    """The product of the module docstring as ``folder/<part>.stl`` [mm]."""
    pegs = parts - 3
    columns = math.ceil(math.sqrt(pegs))
    rows = math.ceil(pegs / columns)
    width, height = columns * PITCH, rows * PITCH
    cavities, pieces = [], {}
    for k in range(pegs):
        x, y = (k % columns + 0.5) * PITCH - width / 2, (k // columns + 0.5) * PITCH - height / 2
        length = 30.0 if k < columns else 40.0
        centre = (x, y, 10 - DEPTH + length / 2)
        if k % 2 == 0:
            cavities.append(_cylinder(4.15 / math.cos(math.pi / 24), DEPTH + 1, (x, y, 10 - DEPTH / 2 + 0.5)))
            pieces[f"peg{k}"] = _cylinder(4.0, length, centre)
        else:
            cavities.append(_box((12.3, 8.3, DEPTH + 1), (x, y, 10 - DEPTH / 2 + 0.5), 30.0))
            pieces[f"peg{k}"] = _box((12.0, 8.0, length), centre, 30.0)
    plate = trimesh.boolean.difference([_box((width, height, 20.0), (0, 0, 0)), *cavities], engine="manifold")
    openings = [_box((16.0, 16.0, 10.0), (float(p.centroid[0]), float(p.centroid[1]), 0))
                for k, p in enumerate(pieces.values()) if k >= columns]
    for name, z in (("cover_low", 27.0), ("cover_high", 31.0)):
        sheet = _box((width, height, 4.0), (0, 0, z))
        holes = [o.copy() for o in openings]
        for hole in holes:
            hole.apply_translation((0, 0, z))
        pieces[name] = trimesh.boolean.difference([sheet, *holes], engine="manifold")
    pieces["plate"] = plate
    for name, mesh in pieces.items():
        mesh.export(folder / f"{name}.stl")


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench import", description="Import plus geometric precedence of a generated "
                            "product (docs/import.md): wall and CPU time, collision queries.")
    # 6: three pegs at least, so that a second row exists for the covers' openings
    parser.add_argument("--parts", type=int_in(6, 200), default=20, help="parts of the product (6 to 200, default 20)")
    parser.add_argument("--repeat", type=int_in(1, 100), default=3, help="imports to take the median of (default 3)")
    parser.add_argument("--target", type=number_in(float, 0.0, 3600.0), default=10.0,
                        help="the median CPU time's bound [s] (default 10)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench-import-") as tmp:
        source = Path(tmp) / "cad"
        source.mkdir()
        write_product(source, args.parts)
        walls, cpus = [], []
        for k in range(args.repeat):
            wall, cpu = time.perf_counter(), time.process_time()
            done = run_import(source, Path(tmp) / f"out{k}", "mm", None)
            derived, why = done.derived, done.why
            walls.append(time.perf_counter() - wall)
            cpus.append(time.process_time() - cpu)
    wall, cpu = statistics.median(walls), statistics.median(cpus)
    print(f"{len(derived.parts)} parts, {len(derived.holes)} holes, {derived.queries} collision queries, "
          f"{len(derived.edges)} geometric edges, stages {len(derived.stages)}")
    print(f"import + geometric precedence: median {wall:.2f} s wall, {cpu:.2f} s CPU over {args.repeat} run(s) "
          f"(target {args.target:g} s CPU)" + ("" if why is None else f"; no geometry.toml: {why}"))
    return 0 if cpu <= args.target else 1
