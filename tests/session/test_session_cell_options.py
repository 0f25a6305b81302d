"""The session passes the sim cell's execution layer and uncertainty to the cells it
starts, and gives each cell its own cell seed derived from the session seed."""

from __future__ import annotations

from assembly_constraints.asp.session.cells import cell_seed, serve_argv
from assembly_constraints.asp.session.run import build_parser
from assembly_constraints.bridge.cell_options import cell_argv


def _value(argv: list[str], option: str) -> str:
    return argv[argv.index(option) + 1]


def test_the_cells_argv_carries_the_layer_the_magnitudes_and_a_cell_seed_per_cell() -> None:
    args = build_parser().parse_args(["--seed", "7", "--layer", "position", "--grasp-tilt-bias", "2.5"])
    options = cell_argv(args)
    first, second = (serve_argv(f"c{k}", backend="sim", cell_options=options, cell_seed=cell_seed(args.seed, k))
                     for k in (1, 2))
    assert _value(first, "--layer") == "position" and float(_value(first, "--grasp-tilt-bias")) == 2.5
    assert float(_value(first, "--vision-sigma")) == 0.0015  # the defaults are passed too
    assert (_value(first, "--cell-seed"), _value(second, "--cell-seed")) == ("7", "8")
    assert cell_seed(2**32 - 1, 2) == 0
    truth = serve_argv("c1", backend="truth", cell_options=options, cell_seed=7)
    assert "--layer" not in truth and "--cell-seed" not in truth  # a truth cell simulates nothing

