"""``./run.sh bench import``: import plus geometric precedence of a generated product.

The product (``--parts N``, 6 to 200, default 20): a plate with ``N - 3`` holes on a grid, round
(d 8 mm, 24-gon) and rectangular (12 x 8 mm, turned by 30°) in turn, a peg in each with
0.3 mm clearance; the pegs of the first row stand 15 mm out, the others 25 mm; two 4 mm
covers, one lying on the first row, the other on it, each with openings for the others
(which pass through both). Written as STL files in mm, then imported
(:func:`executor.cad.cli.run_import`) ``--repeat`` times. Prints the collision queries,
the edges found, and the median wall and CPU time of the import, each as a fraction of
``--target``; exit code 1 when the median wall time (what a user waits) exceeds it. The
CPU time is the process's and the workers it forks (the sweeps', the overlap check's, the
work after the sweeps': :data:`executor.cad.sweep.WORKERS`, ``--workers``), all their
threads: what one core would need; on a shared machine the wall time also counts the waits
for a core.
"""

from __future__ import annotations

import gc
import math
import resource
import statistics
import tempfile
import time
from pathlib import Path

import trimesh

from bridge.cli_types import ArgumentParser, int_in, number_in
from executor.cad import sweep
from executor.cad.cli import Imported, run_import

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


BORE = 16.0  # bearing outer and housing bore radius [mm]
SHAFT = 8.0  # shaft radius, the bearings', spacers', pulleys' and nuts' bore [mm]
HEIGHT = 30.0  # shaft axis above the base's floor [mm]
UNIT_PITCH = 100.0  # between the shafts along y [mm]
RINGS = [("bearing", 18.0, 30.0, BORE), ("spacer", 30.0, 40.0, 12.0), ("pulley", 40.0, 55.0, 25.0),
         ("nut", 55.0, 61.0, 11.0)]
"""Rings on each side of a shaft: name, inner and outer end along the axis [mm], outer radius [mm]."""


def _along_x(mesh: trimesh.Trimesh, start: float, end: float, y: float) -> trimesh.Trimesh:
    """``mesh`` made along z (height end - start, centred), turned onto x from ``start``
    to ``end`` [mm], at ``y`` and the shaft height."""
    mesh.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, (0, 1, 0)))
    mesh.apply_translation(((start + end) / 2, y, HEIGHT))
    return mesh


def write_shafts(folder: Path, parts: int, sections: int) -> None:
    """A unit of horizontal shafts as ``folder/<part>.stl`` [mm]: the base (a floor plate
    with a housing block per shaft, bored through along x at :data:`BORE`), per shaft a
    lid on its housing, the shaft and on each side a bearing in the bore, a spacer and a
    pulley (all at zero clearance: the same nominal radii, tessellated with ``sections``
    plus a few per part, so no two polygons agree); then nuts on the shafts' ends up to
    ``parts`` parts (at most four per shaft more than that)."""
    shafts = max(1, (parts - 1) // 8)
    solid = [_box((60.0, UNIT_PITCH * shafts, 5.0), (0.0, UNIT_PITCH * (shafts - 1) / 2, -2.5))]
    bores, pieces = [], {}
    for k in range(shafts):
        y = UNIT_PITCH * k
        solid.append(_box((60.0, 50.0, 2 * HEIGHT), (0.0, y, HEIGHT)))
        bores.append(_along_x(trimesh.creation.cylinder(radius=BORE, height=62.0, sections=sections), -31, 31, y))
        pieces[f"lid{k}"] = _box((60.0, 50.0, 5.0), (0.0, y, 2 * HEIGHT + 2.5))
        pieces[f"shaft{k}"] = _along_x(trimesh.creation.cylinder(radius=SHAFT, height=130.0, sections=sections + 3),
                                        -65, 65, y)
        for n, (name, inner, outer, radius) in enumerate(RINGS[:3]):
            for side, sign in (("a", -1), ("b", 1)):
                ring = trimesh.creation.annulus(r_min=SHAFT, r_max=radius, height=outer - inner,
                                                sections=sections + 5 + 2 * n + (sign > 0))
                ends = sorted((sign * inner, sign * outer))
                pieces[f"{name}{k}{side}"] = _along_x(ring, ends[0], ends[1], y)
    name, inner, outer, radius = RINGS[3]
    for n in range(min(parts - 1 - len(pieces), 4 * shafts)):
        k, sign = n // 2 % shafts, -1 if n % 2 else 1
        ring = trimesh.creation.annulus(r_min=SHAFT, r_max=radius, height=outer - inner, sections=sections + 11)
        ends = sorted((sign * inner, sign * outer))
        pieces[f"nut{n}"] = _along_x(ring, ends[0], ends[1], UNIT_PITCH * k)
    pieces["base"] = trimesh.boolean.difference([trimesh.boolean.union(solid, engine="manifold"), *bores],
                                                engine="manifold")
    for pid, mesh in pieces.items():
        mesh.export(folder / f"{pid}.stl")


def _children_cpu() -> float:
    """The CPU time [s] of this process's ended and reaped child processes (the import's workers)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _timed(source: Path, out: Path, config: Path | None, repeat: int) -> tuple[float, float, Imported]:
    """Median wall and CPU time [s] of ``repeat`` imports of ``source``, and the last
    import; the CPU time this process's and its workers' (the sweeps' ended with the
    import's sweeper: collected before the clocks are read)."""
    walls, cpus = [], []
    for k in range(repeat):
        wall, cpu = time.perf_counter(), time.process_time() + _children_cpu()
        done = run_import(source, out / str(k), "mm", config)
        gc.collect()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() + _children_cpu() - cpu)
    return statistics.median(walls), statistics.median(cpus), done


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench import", description="Import plus geometric precedence of generated "
                            "products (docs/import.md): wall and CPU time, collision queries.")
    parser.add_argument("--product", choices=["shafts", "plate"], default="shafts",
                        help="shafts: horizontal shafts in zero-clearance bearings, 9 and 20 parts (default); "
                        "plate: pegs in a plate under two covers, --parts N")
    # 6: three pegs at least, so that a second row exists for the covers' openings
    parser.add_argument("--parts", type=int_in(6, 200), default=20,
                        help="parts of the plate product (6 to 200, default 20)")
    parser.add_argument("--triangles", type=int_in(10_000, 2_000_000), default=250_000,
                        help="triangles of the 9-part shafts product; the 20-part one is as fine (default 250000)")
    parser.add_argument("--repeat", type=int_in(1, 100), default=3, help="imports to take the median of (default 3)")
    parser.add_argument("--target", type=number_in(float, 0.0, 3600.0), default=None,
                        help="the median wall time's bound [s] (default: 10 for 9 parts, 30 for 20, 10 for the plate)")
    parser.add_argument("--workers", type=int_in(1, 64), default=None,
                        help="processes the sweeps and the work after them run in (default: two where the cores "
                             "allow and the parts have "
                             f"{sweep.PARALLEL_TRIANGLES} triangles or more, else one)")
    args = parser.parse_args(argv)
    sweep.WORKERS = args.workers
    sizes = [(args.parts, 10.0)] if args.product == "plate" else [(9, 10.0), (20, 30.0)]
    met = True
    with tempfile.TemporaryDirectory(prefix="bench-import-") as tmp:
        for parts, target in sizes:
            source = Path(tmp) / f"cad{parts}"
            source.mkdir()
            if args.product == "plate":
                write_product(source, parts)
            else:
                write_shafts(source, parts, args.triangles // 56)
            config = source / "import.toml"
            config.write_text('base = "base"\n' if args.product == "shafts" else 'base = "plate"\n')
            wall, cpu, done = _timed(source, Path(tmp) / f"out{parts}", config, args.repeat)
            derived, bound = done.derived, target if args.target is None else args.target
            triangles = sum(len(part.mesh.faces) for part in derived.parts.values())
            workers = args.workers or sweep.default_workers(part.mesh for part in derived.parts.values())
            print(f"{args.product}: {len(derived.parts)} parts, {triangles} triangles, {len(derived.slides)} "
                  f"zero-clearance fits, {len(derived.edges)} geometric edges, stages {len(derived.stages)}, "
                  f"sweeps in {workers} process(es)")
            verdict = "met" if wall <= bound else "not met"
            print(f"  import + geometric precedence: median over {args.repeat} run(s) {wall:.2f} s wall "
                  f"({wall / bound:.2f} of the {bound:g} s target: {verdict}), {cpu:.2f} s CPU ({cpu / bound:.2f} "
                  f"of it), {derived.queries} collision queries"
                  + ("" if done.why is None else f"; no geometry.toml: {done.why}"))
            met = met and wall <= bound
    return 0 if met else 1
