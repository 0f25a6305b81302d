"""The up-axis check on every product read with each of the six ups (docs/import.md, "The up axis").

Each product is imported once as it is drawn, z up (``import`` with its settings and no
``up``): every corpus product (``tests/cad/corpus/*``), every shipped product with CAD
(``data/*``, exported with ``executor export --assembled``) and the products of ``./run.sh
bench import`` (the plate of 6 and 20 parts, the shaft units of 9 and 20 parts, these
tessellated with 64-gons, not the bench's 250000 triangles: the check reads boxes, faces and
axes, not the fineness). Its derived facts are then turned as the product would be read
drawn with each other up (the meshes turned by the inverse of that up's turn,
:func:`executor.cad.parts.turn_points`, and every removal direction with them: the parts'
axes, their blockers, the holes' and pins' axes: a part free both ways along an axis keeps
the way the import as drawn chose, where an import of the turned CAD picks the cell's
preferred way), and the check run on each reading (:func:`executor.cad.upright.drawn_up`).
A product refused in its own orientation is a false refusal; one read turned and refused
is named right when the up its line names first is the one it was drawn with.

``python -m tests.cad.up_readings [--product NAME ...] [--cache DIR]`` prints one line per
product and reading, then the counts; ``--cache`` keeps each product's facts (pickled) so
that a second run does not import again. Exits 1 on a false refusal.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import io
import pickle
import re
import sys
import tempfile
from pathlib import Path

from assembly_constraints.cli import main as cli_main
from executor.cad.cli import run_import
from executor.cad.derive import Derived
from executor.cad.parts import UP_AXES
from executor.cad.upright import drawn_up
from executor.cad.upright.gravity import turned_facts
from executor.campaign.import_bench import write_product, write_shafts

ROOT = Path(__file__).resolve().parents[2]
CORPUS = Path(__file__).parent / "corpus"
SHIPPED = ("cranfield", "graded", "spare", "taskboard")
"""The shipped products with CAD (``data/<name>``, exported assembled)."""
INVERSE = {"+z": "+z", "-z": "-z", "+y": "-y", "-y": "+y", "+x": "-x", "-x": "+x"}
"""Each up -> the up whose turn undoes its turn (:func:`executor.cad.parts.turn_points`)."""
SECTIONS = 64
"""The sides of the bench's shaft units' round parts here."""


def _source(name: str, work: Path) -> tuple[Path, str, Path]:
    """The CAD of product ``name`` (a corpus or shipped product, or ``bench:plate6``,
    ``bench:plate20``, ``bench:shafts9``, ``bench:shafts20``), its units and settings file,
    written under ``work`` where it is no folder of the project's."""
    if (CORPUS / name).is_dir():
        return CORPUS / name / "meshes", "mm", CORPUS / name / "import.toml"
    if name in SHIPPED:
        with contextlib.redirect_stdout(io.StringIO()):
            assert cli_main(["-q", "executor", "export", "--assembled", "--assembly", name, str(work / "cad")]) == 0
        return work / "cad", "m", work / "cad" / "import.toml"
    kind, parts = re.fullmatch(r"bench:(plate|shafts)(\d+)", name).groups()  # type: ignore[union-attr]
    (work / "cad").mkdir()
    if kind == "plate":
        write_product(work / "cad", int(parts))
    else:
        write_shafts(work / "cad", int(parts), SECTIONS)
    config = work / "import.toml"
    config.write_text('base = "base"\n' if kind == "shafts" else 'base = "plate"\n')
    return work / "cad", "mm", config


def products() -> list[str]:
    """Every product the tool reads: the corpus's, the shipped ones with CAD, the bench's."""
    corpus = sorted(p.name for p in CORPUS.iterdir() if (p / "import.toml").is_file())
    return corpus + list(SHIPPED) + ["bench:plate6", "bench:plate20", "bench:shafts9", "bench:shafts20"]


def facts(name: str, cache: Path | None) -> Derived:
    """Product ``name`` imported as drawn (no ``up``): what the import derived, its parts'
    B-rep re-tessellation dropped (kept pickled in ``cache``, when given)."""
    kept = None if cache is None else cache / f"{name.replace(':', '_')}.pickle"
    if kept is not None and kept.is_file():
        return pickle.loads(kept.read_bytes())
    with tempfile.TemporaryDirectory(prefix="up_readings_") as tmp:
        source, units, config = _source(name, Path(tmp))
        with contextlib.redirect_stdout(io.StringIO()):
            derived = run_import(source, Path(tmp) / "out", units, config).derived
    derived.parts = {pid: dataclasses.replace(part, remesh=None) for pid, part in derived.parts.items()}
    if kept is not None:
        kept.parent.mkdir(parents=True, exist_ok=True)
        kept.write_bytes(pickle.dumps(derived))
    return derived


def reading(derived: Derived, drawn: str) -> Derived:
    """The facts of ``derived`` (a product z up) as the import reads them from its CAD drawn
    with ``drawn`` up: turned by the inverse of ``drawn``'s turn."""
    return turned_facts(derived, INVERSE[drawn])


def named(line: str) -> list[str]:
    """The ups a refusal's line suggests, first first (``set up = "+y" or "-y"``)."""
    suggestion = line.split("; set up = ", 1)[1].split(" or --up", 1)[0].split(" (", 1)[0]
    return re.findall(r'"([+-][xyz])"', suggestion)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.cad.up_readings", description=__doc__.split("\n\n")[0])
    parser.add_argument("--product", action="append", help="a product (default: all): a corpus or shipped "
                        "product's name, bench:plate6, bench:plate20, bench:shafts9, bench:shafts20")
    parser.add_argument("--cache", type=Path, help="keep each product's imported facts here")
    args = parser.parse_args(argv)
    counts = {"false": 0, "turned": 0, "refused": 0, "right": 0, "among": 0}
    for name in args.product or products():
        derived = facts(name, args.cache)
        for drawn in UP_AXES:
            why = drawn_up(reading(derived, drawn))
            suggested = [] if why is None else named(why)
            if drawn == "+z":
                counts["false"] += why is not None
            else:
                counts["turned"] += 1
                counts["refused"] += why is not None
                counts["right"] += bool(suggested) and suggested[0] == drawn
                counts["among"] += drawn in suggested
            verdict = "read" if why is None else f"refused naming {' or '.join(suggested)}"
            print(f"{name} drawn {drawn}: {verdict}" + ("" if why is None else f": {why}"), flush=True)
    print(f"own orientation refused: {counts['false']}; turned readings: {counts['turned']}, refused "
          f"{counts['refused']}, the up named first right in {counts['right']}, among the ups named in "
          f"{counts['among']}")
    return 1 if counts["false"] else 0


if __name__ == "__main__":
    sys.exit(main())
