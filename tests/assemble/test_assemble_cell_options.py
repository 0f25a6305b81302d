"""``assemble --uncertainty cell``: the cell's options reach ``executor serve`` (no physics),
and are refused where they would have no effect: without ``--uncertainty cell``, or with
``--backend truth``."""

from __future__ import annotations

from argparse import ArgumentParser
from collections.abc import Callable

import pytest

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.assemble.cli import build_parser, cell_options
from assembly_constraints.asp.bench.assemble_plans import build_parser as bench_parser
from assembly_constraints.asp.session.cells import serve_argv
from assembly_constraints.executor.serve import build_parser as serve_parser


def test_the_cell_options_reach_the_assembling_cell() -> None:
    args = build_parser().parse_args(["--uncertainty", "cell", "--cell-seed", "3", "--layer", "position",
                                      "--grasp-tilt-bias", "2.5"])
    argv = serve_argv("a1", backend="sim", cell_options=cell_options(args))
    served = serve_parser().parse_args(argv[argv.index("serve") + 1:])
    assert (served.uncertainty, served.cell_seed, served.layer) == ("cell", 3, "position")
    assert served.grasp_tilt_bias == 2.5 and served.vision_sigma == 0.0015  # the defaults are passed too


def test_by_default_the_assembling_cell_gets_no_cell_options() -> None:
    args = build_parser().parse_args([])
    assert cell_options(args) == []
    assert serve_parser().parse_args(["--cell", "a1"]).uncertainty == "random"


@pytest.mark.parametrize("option", [["--layer", "position"], ["--cell-seed", "1"], ["--vision-bias", "0.002"]])
def test_a_cell_option_without_uncertainty_cell_is_refused(option: list[str]) -> None:
    with pytest.raises(PlannerError, match="need --uncertainty cell"):
        cell_options(build_parser().parse_args(option))


def test_bench_assemble_passes_the_same_cell_options() -> None:
    args = bench_parser().parse_args(["--uncertainty", "cell", "--cell-seed", "2", "--layer", "admittance_p"])
    served = serve_parser().parse_args(cell_options(args))
    assert (served.uncertainty, served.cell_seed, served.layer) == ("cell", 2, "admittance_p")


@pytest.mark.parametrize("parser", [build_parser, bench_parser], ids=["assemble", "bench-assemble"])
@pytest.mark.parametrize(("option", "named"), [(["--uncertainty", "cell"], "--uncertainty cell"),
                                               (["--uncertainty", "cell", "--layer", "position"], "--uncertainty cell"),
                                               (["--cell-seed", "1"], "--cell-seed"),
                                               (["--friction-max", "0.6"], "--friction-max")])
def test_a_cell_option_with_the_truth_backend_is_refused_naming_both(parser: Callable[[], ArgumentParser],
                                                                      option: list[str], named: str) -> None:
    with pytest.raises(PlannerError, match=f"^{named} has no effect with --backend truth"):
        cell_options(parser().parse_args(["--backend", "truth", *option]))
