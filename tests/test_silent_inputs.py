"""Inputs that were accepted silently or refused unclearly: each is now refused in one line
naming the file or option and what was expected (exit 2), or warned about, before any
cell starts; and the paths a command prints work from any folder."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from assembly_constraints.asp.session.cells import CellProcess, start_cell
from assembly_constraints.bridge import BridgeError
from assembly_constraints.bridge.cell_settings import ServeSettings
from assembly_constraints.bridge.client import CellDirectory
from assembly_constraints.bridge.keys import alive_key
from assembly_constraints.bridge.session import LOOPBACK_ANY_PORT, bound_endpoints, free_loopback_endpoint, open_session
from assembly_constraints.cli import main
from tests.conftest import error_lines
from tests.executor.test_mesh_parts import _edit, _refusal, product  # noqa: F401 (product: the fixture)

BAD_DESCRIPTION = "[thresholds]\nf_stop = -5.0\n"


def _refused(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    """The one line of ``assembly-constraints ARGV`` run in this process, which must exit 2."""
    capsys.readouterr()
    try:
        code = main(list(argv))
    except SystemExit as exit_:  # argparse's errors
        code = exit_.code
    lines = error_lines(capsys.readouterr().err)
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: "), (code, lines)
    return lines[0]


def test_a_truth_cell_and_export_refuse_a_bad_cell_description(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    """Neither the truth backend nor ``export --assembled`` uses the description, but a bad one
    is an error, not ignored."""
    description = tmp_path / "cell.toml"
    description.write_text(BAD_DESCRIPTION)
    error = _refused(capsys, "executor", "serve", "--backend", "truth", "--cell-description", str(description),
                     "--listen", LOOPBACK_ANY_PORT)
    assert str(description) in error and "[thresholds] f_stop" in error and "(0, 1000]" in error
    error = _refused(capsys, "executor", "export", "--assembled", "--cell-description", str(description),
                     str(tmp_path / "out"))
    assert "[thresholds] f_stop" in error and not (tmp_path / "out").exists()


@pytest.mark.parametrize("argv", [
    ("session", "--backend", "truth", "--out", ""),
    ("precedence", "learn", "--assembly", "cranfield", "--out", ""),
    ("sizes", "learn", "--assembly", "cranfield", "--out", ""),
    ("import", "x.step", "--out", ""),
    ("executor", "trial", "--part", "p1", "--hole", "r1", "--save", ""),
])
def test_an_empty_output_path_is_refused_not_the_current_folder(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        argv: tuple[str, ...]) -> None:
    monkeypatch.chdir(tmp_path)
    assert "expected a path, got the empty string" in _refused(capsys, *argv)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("mesh", "new", "reach"), [
    ("peg.obj", "v 10.005 0.005 0.04", 0.5),  # 10 m away
    ("peg.obj", "v 5.0 -4.0 3.0", 0.5),  # the size of a room
    ("peg.convex.obj", "v nan 0.005 0.036", 0.5),
    ("plate.obj", "v 0.02 inf 0.0", 2.0),  # the base: a static mesh, no pieces, checked as well
    ("plate.obj", "v -0.01 0.03 -2.5", 2.0),
])
def test_a_mesh_far_from_its_part_or_not_finite_is_refused_with_the_range(
        product: Path, mesh: str, new: str, reach: float) -> None:  # noqa: F811 (the fixture)
    path = product / "meshes" / mesh
    text = path.read_text()
    old = next(line for line in text.splitlines() if line.startswith("v "))
    path.write_text(text.replace(old, new, 1))
    if ".convex." not in mesh:  # its entry (and pieces) follow the edited file, as import writes them
        import hashlib

        digests = [hashlib.sha256(t.encode()).hexdigest() for t in (text, path.read_text())]
        _edit(product, *digests)
        pieces = product / "meshes" / "peg.convex.obj"
        pieces.write_text(pieces.read_text().replace(*digests, 1))
    message = _refusal(product)
    assert f"{path}:" in message and f"within [-{reach:g}, {reach:g}] m" in message and new.split()[1] in message, \
        message


def test_a_fifo_given_as_a_recording_says_it_is_not_a_regular_file(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    fifo = tmp_path / "c1.rrd"
    os.mkfifo(fifo)
    assert f"{fifo}: not a regular file (a FIFO)" in _refused(capsys, "view", str(fifo), "--print")
    run = tmp_path / "run"
    run.mkdir()
    os.mkfifo(run / "c1.rrd")
    assert f"{run / 'c1.rrd'}: not a regular file (a FIFO)" in _refused(capsys, "view", str(run), "--print")


def test_an_out_of_range_number_says_the_range(capsys: pytest.CaptureFixture[str]) -> None:
    error = _refused(capsys, "sizes", "learn", "--assembly", "cranfield", "--prior", "cad", "--tolerance", "5")
    assert "--tolerance: '5': expected a finite number in [0, 0.1)" in error
    error = _refused(capsys, "bench", "physics", "--baseline", "x")
    assert "--baseline: 'x': expected a finite number in [1, 1e+09)" in error


def test_a_recording_in_a_missing_folder_names_the_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                                          ) -> None:
    rrd = tmp_path / "runs" / "demo" / "c1.rrd"
    error = _refused(capsys, "executor", "trial", "--part", "p1", "--hole", "r1", "--rrd", str(rrd))
    assert f"{rrd}: cannot write (No such file or directory: no folder {rrd.parent}; create it first)" in error


def test_a_cell_id_claimed_twice_is_named_when_the_session_waits_for_it() -> None:
    with open_session(listen=[LOOPBACK_ANY_PORT]) as tokens:
        endpoint = bound_endpoints(tokens, [LOOPBACK_ANY_PORT])[0]
        held = [tokens.liveliness().declare_token(alive_key("c7", name)) for name in ("first", "second")]
        with open_session(connect=[endpoint]) as planner:
            directory = CellDirectory(planner)
            try:
                deadline = time.monotonic() + 10
                while "c7" not in directory.duplicated and time.monotonic() < deadline:
                    time.sleep(0.05)
                with pytest.raises(BridgeError) as caught:
                    directory.wait_for(1, timeout=0.5)
            finally:
                directory.close()
        for token in held:
            token.undeclare()
    assert "cell id c7 is claimed by 2 processes (liveliness tokens of instances first, second)" in str(caught.value)


@pytest.mark.slow  # a session with a truth cell
def test_a_session_using_any_cell_warns_and_prints_absolute_next_commands(tmp_path: Path, run_cli,
                                                                        cells: list[CellProcess]) -> None:
    endpoint = free_loopback_endpoint()
    cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth", listen=(endpoint,))))
    done = run_cli("session", "--backend", "truth", "--cells", "0", "--connect", endpoint, "--out", "run",
                   cwd=tmp_path, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "--cells 0 without --allow-cells: using every cell that answers on the network (now: c1)" in done.stderr
    run = (tmp_path / "run").resolve()
    assert f"view {run}\n" in done.stdout and f"-m clingo {run / 'learned.lp'} -" in done.stdout, done.stdout

