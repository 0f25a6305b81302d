"""``./run.sh bench reach``: where the simulated cell's arm puts a part onto a pin along a
horizontal axis, and a peg into a hole entered sideways.

Each point of the grid is one product built, imported, taught and assembled (seed 0): for
each axis of the part's motion (``--axes``), each x of the pin's free end (the hole's entry
centre) in the cell (``--xs``, mm: the arm's base at the origin), each y (``--ys``, mm) and
each height (``--heights``, mm above the floor). The products: ``--kind pin``, the block
with a d 10 pin and the ring with a d 10.2 bore (0.1 mm of room all round) of
``tests/cad/test_horizontal_pins.py`` (:func:`pin_cad`); ``--kind hole``, the corpus's
``agh_hex_horizontal`` (``tests/cad/corpus``, absent from an installed package) box and
hexagonal peg (for +x and +y, where the import would enter its hole through the box from
the other side, its box's far face closed by a 5 mm plate and its peg cut 1 mm short of it);
each turned about z so that the part moves along the axis, raised on a
riser of the base's own footprint to the height, and placed (``import --place``, with
``--turn 0``: the import chooses no pose of its own) so that the free end (entry) is at
the point. The import's reach rule
(:data:`executor.cad.operations.arm.SIDEWAYS_PIN_REACH`, :data:`executor.cad.operations.arm.SIDEWAYS_HOLE_REACH`)
is set aside for it: the point is the cell's step wherever the import takes it as one.

Prints one line a point: ``reached`` (the part assembled within 2 mm of its goal), or
where it stopped (the import's reason, the error of teaching or of the step, the step's
outcome), and the process's CPU time for it. Exit code 1 when a point was not reached.
"""

from __future__ import annotations

import argparse
import resource
import tempfile
from collections.abc import Sequence
from pathlib import Path
from unittest import mock

import numpy as np
import shapely
import trimesh

from bridge.cli_types import ArgumentParser
from bridge.product import load_product_description
from executor import ExecutorError
from executor.cad.cli import ImportOptions, run_import
from executor.cad.operations import arm

CORPUS_HOLE = Path(__file__).resolve().parents[2] / "tests" / "cad" / "corpus" / "agh_hex_horizontal"
"""The hole's product: real CAD, a peg going along -y into a box's hole 30 mm up."""
TURNS = {"-y": 0, "+x": 1, "+y": 2, "-x": 3}
"""The quarter turns about z that make a product drawn with its part moving along -y move along each axis."""
EVERYWHERE = {axis: (((-10.0, 10.0), (-10.0, 10.0), (-10.0, 10.0)),) for axis in TURNS}
"""A reach rule that takes every point within 10 m along every axis as reached."""
PIN_HEIGHT = 30.0
"""[mm] the pin's height above the floor in :func:`pin_cad` without a riser (the hole's too)."""


def pin_cad(folder: Path, bore: float, wall: float | None = None, turn: int = 0) -> Path:
    """The block (60 x 50 x 60 mm on the floor) with a d 10 pin (a 64-gon) from its +y face
    (y 25) to y 60, 30 mm up, and the ring (d 24, 8 mm long) with a round ``bore`` [mm] (a
    128-gon) against that face, as STL files [mm] in ``folder``, and the import settings
    (``base = "block"``) beside it; with a ``wall`` [mm], a 10 mm wall beside the pin (x 20 to
    30 mm, as high as the block) reaches that far out of the block's +y face; all turned
    ``turn`` quarter turns about z."""
    folder.mkdir(parents=True)
    block = trimesh.creation.box((60.0, 50.0, 60.0))
    block.apply_translation((0.0, 0.0, 30.0))
    pin = trimesh.creation.cylinder(radius=5.0, height=40.0, sections=64)
    pin.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (1.0, 0.0, 0.0)))
    pin.apply_translation((0.0, 40.0, PIN_HEIGHT))
    solids = [block, pin]
    if wall is not None:
        side = trimesh.creation.box((10.0, wall, 60.0))
        side.apply_translation((25.0, 25.0 + wall / 2, 30.0))
        solids.append(side)
    quarter = trimesh.transformations.rotation_matrix(turn * np.pi / 2, (0.0, 0.0, 1.0))
    trimesh.boolean.union(solids, engine="manifold").apply_transform(quarter).export(folder / "block.stl")
    pin_ring(bore, 12.0, 25.0, turn).export(folder / "ring.stl")
    (folder.parent / "import.toml").write_text('base = "block"\n')
    return folder


def pin_ring(bore: float, outer: float, y: float, turn: int = 0) -> trimesh.Trimesh:
    """A ring [mm] about :func:`pin_cad`'s pin, ``outer`` in radius, 8 mm long, with a round
    ``bore`` (a 128-gon), from ``y`` to ``y`` + 8 mm along it, turned as the block is."""
    section = shapely.Point(0, 0).buffer(outer, quad_segs=32).difference(shapely.Point(0, 0).buffer(bore / 2,
                                                                                                     quad_segs=32))
    ring = trimesh.creation.extrude_polygon(section, 8.0)
    ring.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, (1.0, 0.0, 0.0)))  # its axis along y
    ring.apply_translation((0.0, y, PIN_HEIGHT))
    return ring.apply_transform(trimesh.transformations.rotation_matrix(turn * np.pi / 2, (0.0, 0.0, 1.0)))


def _raised(folder: Path, base: str, lift: float) -> None:
    """The product's STL files [mm] in ``folder`` moved up by ``lift`` [mm], ``base`` standing
    on a riser of its own footprint's box (united with it, 0.5 mm into its bottom)."""
    if lift <= 0.0:
        return
    for path in folder.glob("*.stl"):
        mesh = trimesh.load(path, force="mesh")
        mesh.apply_translation((0.0, 0.0, lift))
        if path.stem == base:
            (x0, y0, _), (x1, y1, _) = mesh.bounds
            riser = trimesh.creation.box((x1 - x0, y1 - y0, lift + 0.5))
            riser.apply_translation(((x0 + x1) / 2, (y0 + y1) / 2, (lift + 0.5) / 2))
            mesh = trimesh.boolean.union([mesh, riser], engine="manifold")
        mesh.export(path)


def _product(folder: Path, kind: str, axis: str, height: float) -> tuple[Path, Path, str]:
    """The product's CAD folder, import settings and feature id for ``kind`` moving along ``axis``."""
    turn = TURNS[axis]
    if kind == "pin":
        cad = pin_cad(folder / "cad", 10.2, turn=turn)
        _raised(cad, "block", height - PIN_HEIGHT)
        return cad, folder / "import.toml", "block_pin1"
    cad = folder / "cad"
    cad.mkdir(parents=True)
    quarter = trimesh.transformations.rotation_matrix(turn * np.pi / 2, (0.0, 0.0, 1.0))
    box = trimesh.load(CORPUS_HOLE / "meshes" / "box.stl", force="mesh")
    peg = trimesh.load(CORPUS_HOLE / "meshes" / "hex_peg.stl", force="mesh")
    assert isinstance(box, trimesh.Trimesh) and isinstance(peg, trimesh.Trimesh)
    if axis in ("+x", "+y"):  # the hole through the box is entered along -y or -x whichever way it is turned
        box, peg = _closed(box, peg)
    box.apply_transform(quarter).export(cad / "box.stl")
    peg.apply_transform(quarter).export(cad / "hex_peg.stl")
    _raised(cad, "box", height - PIN_HEIGHT)
    return cad, CORPUS_HOLE / "import.toml", "h1"


def _closed(box: trimesh.Trimesh, peg: trimesh.Trimesh) -> tuple[trimesh.Trimesh, trimesh.Trimesh]:
    """The hole's box [mm] with its far (-y) face closed by a 5 mm plate, and its peg cut
    1 mm short of that face: a hole the import enters from its +y face only."""
    (x0, y0, z0), (x1, _, z1) = box.bounds
    plate = trimesh.creation.box((x1 - x0, 5.5, z1 - z0))
    plate.apply_translation(((x0 + x1) / 2, y0 - 2.25, (z0 + z1) / 2))
    (px0, _, pz0), (px1, py1, pz1) = peg.bounds
    keep = trimesh.creation.box((px1 - px0 + 2, py1 - y0, pz1 - pz0 + 2))  # y from y0 + 1 to beyond the peg's end
    keep.apply_translation(((px0 + px1) / 2, (y0 + py1) / 2 + 1, (pz0 + pz1) / 2))
    return (trimesh.boolean.union([box, plate], engine="manifold"),
            trimesh.boolean.intersection([peg, keep], engine="manifold"))


def measure(kind: str, axis: str, x: float, y: float, height: float, tmp: Path) -> str:
    """One point [mm]: "reached", or where it stopped (module docstring)."""
    # Imported here: --help loads no PyBullet.
    from executor.assembly.product import load_product
    from executor.assembly.step import Assembler
    from executor.cell_description import CellDescription
    from executor.skills.teach import teach_all
    from executor.trial import Cell

    cad, config, feature = _product(tmp / "first", kind, axis, height)
    with mock.patch.object(arm, "SIDEWAYS_PIN_REACH", EVERYWHERE), \
            mock.patch.object(arm, "SIDEWAYS_HOLE_REACH", EVERYWHERE):
        # built z up: a block raised on its riser stands on its edge, its feature sideways (import --up)
        run_import(cad, tmp / "first" / "out", "mm", config, ImportOptions(place=(0.56, 0.0), up="+z", turn=0))
        at = load_product_description(tmp / "first" / "out").assembly.holes[feature].position
        assert at is not None and at[0] is not None and at[1] is not None
        place = (0.56 + x / 1e3 - at[0], y / 1e3 - at[1])
        out = tmp / "out"
        run_import(cad, out, "mm", config, ImportOptions(place=place, up="+z", turn=0))
    geometry = load_product_description(out).geometry
    assert geometry is not None
    if (written := geometry.hole_shapes[feature].axis) != axis:
        return f"import: the part moves along {written}, not {axis}"
    if geometry.manual:
        return "import: " + "; ".join(f"{pid} {m.reason}" for pid, m in geometry.manual.items())
    cell = Cell(str(out))
    try:
        teach_all(cell)
    except ExecutorError as error:
        return f"teach: {error}"
    finally:
        cell.close()
    product = load_product(str(out))
    base, part = product.base.id, next(p for p in product.pegs)
    assembler = Assembler(product, description=CellDescription())
    try:
        if (step := assembler.run_step(base, None, 0)).outcome != "fit":
            return f"base: {step.outcome}"
        step = assembler.run_step(part, feature, 0)
    except ExecutorError as error:
        return f"step: {error}"
    finally:
        assembler.close()
    if step.outcome != "fit" or step.pose_error > 0.002:
        return f"step: {step.outcome}, {1e3 * step.pose_error:.2f} mm from its goal"
    return f"reached ({1e3 * step.pose_error:.2f} mm from its goal)"


def _numbers(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas, got {text!r}") from None


def main(argv: Sequence[str]) -> int:
    parser = ArgumentParser(prog="bench reach", description="Where the cell's arm reaches a pin along a horizontal "
                            "axis or a hole entered sideways: one product built, imported, taught and assembled "
                            "a point (docs/cell.md).")
    parser.add_argument("--kind", choices=["pin", "hole"], default="pin",
                        help="pin: the ring onto the block's pin; hole: agh_hex_horizontal's peg (default pin)")
    parser.add_argument("--axes", default="+x,-x,+y,-y", help="the part's motions (default +x,-x,+y,-y)")
    parser.add_argument("--xs", type=_numbers, default=[400.0, 500.0, 600.0, 700.0],
                        help="x of the free end (entry) [mm], commas (default 400,500,600,700)")
    parser.add_argument("--ys", type=_numbers, default=[0.0, 100.0], help="its y [mm], commas (default 0,100)")
    parser.add_argument("--heights", type=_numbers, default=[30.0, 120.0],
                        help=f"its height [mm], commas, at least {PIN_HEIGHT:g} (default 30,120)")
    args = parser.parse_args(list(argv))
    axes = args.axes.split(",")
    if bad := [a for a in axes if a not in TURNS]:
        parser.error(f"--axes: expected some of {', '.join(TURNS)}, got {', '.join(bad)}")
    if min(args.heights) < PIN_HEIGHT:
        parser.error(f"--heights: expected {PIN_HEIGHT:g} mm or more")
    if args.kind == "hole" and not CORPUS_HOLE.is_dir():
        parser.error(f"{CORPUS_HOLE}: no such folder (the repository's corpus)")
    missed = 0
    for axis in axes:
        for height in args.heights:
            for y in args.ys:
                for x in args.xs:
                    cpu = resource.getrusage(resource.RUSAGE_SELF).ru_utime
                    with tempfile.TemporaryDirectory(prefix="bench-reach-") as tmp:
                        found = measure(args.kind, axis, x, y, height, Path(tmp))
                    missed += not found.startswith("reached")
                    cpu = resource.getrusage(resource.RUSAGE_SELF).ru_utime - cpu
                    print(f"{args.kind} {axis} x {x:g} y {y:g} z {height:g} mm: {found} [{cpu:.1f} s CPU]",
                          flush=True)
    return 1 if missed else 0
