"""``assemble --uncertainty cell``: the cell's options reach the assembling cell's settings
document (no physics), and are refused where they would have no effect: without
``--uncertainty cell``, or with ``--backend truth``; ``--backend franka``'s options and
layer reach its cell, and what only a simulated cell uses is refused with it."""

from __future__ import annotations

from argparse import ArgumentParser
from collections.abc import Callable

import msgspec
import pytest

from asp import PlannerError
from asp.assemble.cli import assembling_cell_of, assembly_settings, build_parser
from asp.assemble.settings import assembling_cell_settings, check_assembling_backend
from asp.bench.assemble_plans import build_parser as bench_parser
from asp.session.cells import CellProcess
from bridge.assembly import load_assembly
from bridge.cell_settings import DEFAULT_CELL, ServeSettings, cell_settings_of
from executor.serve import build_parser as serve_parser
from executor.serve import serve_settings_of


def _checked(parser: ArgumentParser, argv: list[str]):
    args = parser.parse_args(argv)
    return assembling_cell_settings(cell_settings_of(args), args.backend)


def test_the_cell_options_reach_the_assembling_cell() -> None:
    settings = assembly_settings(build_parser().parse_args(["--uncertainty", "cell", "--cell-seed", "3", "--layer",
                                                            "position", "--grasp-tilt-bias", "2.5"]))
    cell = assembling_cell_settings(settings.cell, settings.backend)
    argv = CellProcess.command(ServeSettings(cell_id="a1", cell=cell))
    served = serve_settings_of(serve_parser().parse_args(argv[argv.index("serve") + 1:])).cell
    assert (served.uncertainty, served.cell_seed, served.layer) == ("cell", 3, "position")
    assert served.magnitudes.grasp_tilt_bias == 2.5 and served.magnitudes.vision_sigma == 0.0015


def test_by_default_the_assembling_cell_gets_the_default_cell() -> None:
    assert _checked(build_parser(), []) == DEFAULT_CELL
    assert serve_settings_of(serve_parser().parse_args(["--cell", "a1"])).cell.uncertainty == "random"


@pytest.mark.parametrize("option", [["--layer", "position"], ["--cell-seed", "1"], ["--vision-bias", "0.002"]])
def test_a_cell_option_without_uncertainty_cell_is_refused(option: list[str]) -> None:
    with pytest.raises(PlannerError, match="need --uncertainty cell"):
        _checked(build_parser(), option)


def test_bench_assemble_passes_the_same_cell_settings() -> None:
    cell = _checked(bench_parser(), ["--uncertainty", "cell", "--cell-seed", "2", "--layer", "admittance_p"])
    assert (cell.uncertainty, cell.cell_seed, cell.layer) == ("cell", 2, "admittance_p")


@pytest.mark.parametrize("parser", [build_parser, bench_parser], ids=["assemble", "bench-assemble"])
@pytest.mark.parametrize(("option", "named"), [(["--uncertainty", "cell"], "--uncertainty cell"),
                                               (["--uncertainty", "cell", "--layer", "position"], "--uncertainty cell"),
                                               (["--cell-seed", "1"], "--cell-seed"),
                                               (["--friction-max", "0.6"], "--friction-max")])
def test_a_cell_option_with_the_truth_backend_is_refused_naming_both(parser: Callable[[], ArgumentParser],
                                                                      option: list[str], named: str) -> None:
    with pytest.raises(PlannerError, match=f"^{named} has no effect with --backend truth"):
        _checked(parser(), ["--backend", "truth", *option])


def test_a_franka_cell_gets_the_backend_options_and_its_layer() -> None:
    settings = assembly_settings(build_parser().parse_args(["--backend", "franka", "--backend-option", "host=10.0.0.2",
                                                            "--backend-option", "dynamics=0.1", "--layer", "position"]))
    check_assembling_backend(settings)
    served = assembling_cell_of(settings, load_assembly("spare"), assembling_cell_settings(settings.cell, "franka"))
    argv = CellProcess.command(msgspec.structs.replace(served, cell_id="a1"))
    cell = serve_settings_of(serve_parser().parse_args(argv[argv.index("serve") + 1:]))
    assert (cell.backend, cell.backend_options, cell.cell.layer) == ("franka", {"host": "10.0.0.2", "dynamics": "0.1"},
                                                                      "position")


@pytest.mark.parametrize(("argv", "named"), [
    (["--backend-option", "host=10.0.0.2"], "--backend-option host: only --backend franka"),
    (["--backend", "truth", "--backend-option", "host=10.0.0.2"], "--backend-option host: only --backend franka"),
    (["--backend", "franka", "--block-hole", "r1"], "--block-hole has no effect with --backend franka"),
    (["--backend", "franka", "--save", "x.rrd"], "--save has no effect with --backend franka"),
    (["--backend", "franka", "--uncertainty", "cell"], "--uncertainty cell has no effect with --backend franka"),
    (["--backend", "franka", "--cell-seed", "2"], "--cell-seed has no effect with --backend franka")])
def test_an_option_without_effect_on_the_chosen_backend_is_refused(argv: list[str], named: str) -> None:
    settings = assembly_settings(build_parser().parse_args(argv))
    with pytest.raises(PlannerError, match=f"^{named}"):
        check_assembling_backend(settings)
        assembling_cell_settings(settings.cell, settings.backend)
