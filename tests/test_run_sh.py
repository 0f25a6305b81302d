"""``./run.sh`` runs commands in the caller's working directory: relative paths resolve
there, not in the repository (``test`` and ``lint`` still run in the repository); ``test``
runs the franka_arm tests after the suite only when its arguments select no tests."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest

from tests.conftest import ROOT, child_env

RUN_SH = ROOT / "run.sh"


def _run_sh(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(RUN_SH), *args], cwd=cwd, env=child_env(), capture_output=True, text=True,
                          timeout=120)


@pytest.mark.slow
def test_relative_paths_resolve_in_the_callers_folder(tmp_path: Path) -> None:
    """``--assembly cranfield`` is still found under data/; the default run folder
    runs/<UTC time> is relative to the caller's folder and lands there, not in the
    repository, and the cells (which run in the repository) still write their recordings
    into it; a folder named like a package in the caller's folder does not shadow the
    project."""
    (tmp_path / "asp").mkdir()
    (tmp_path / "asp" / "__init__.py").write_text('raise SystemExit("the caller\'s asp/ was imported")\n')
    done = _run_sh("session", "--backend", "truth", "--assembly", "cranfield", "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    run = Path(json.loads(done.stdout)["run"])
    assert not run.is_absolute() and run.parts[0] == "runs" and not (ROOT / run).exists()
    assert (tmp_path / run / "session.json").is_file()
    assert (tmp_path / run / "c1.rrd").is_file() and (tmp_path / run / "planner.rrd").is_file()


@pytest.mark.parametrize(("args", "selects"), [
    ((), False), (("-p", "no:cacheprovider"), False), (("-n", "0", "-x"), False),
    (("-m", "not slow"), True), (("-mslow",), True), (("-k", "session"), True), (("--lf",), True),
    (("--deselect", "tests/test_api.py"), True), (("tests/test_run_sh.py",), True),
    (("tests/test_run_sh.py::test_relative_out_is_written_in_the_callers_folder",), True),
])
def test_the_franka_arm_tests_follow_the_suite_only_without_a_selection(args: tuple[str, ...], selects: bool) -> None:
    """``./run.sh test ARGS`` runs the franka_arm tests after the suite when ARGS select no
    tests themselves (run.sh's ``selects_tests``, run here in bash): CI's plain run does,
    the quick loop ``-m "not slow"``, a keyword, a path, a deselection do not."""
    function = re.search(r"^selects_tests\(\) \{\n.*?^\}\n", RUN_SH.read_text(encoding="utf-8"), re.M | re.S)
    assert function is not None
    done = subprocess.run(["bash", "-c", function[0] + 'selects_tests "$@"', "bash", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=30)
    assert done.returncode == (0 if selects else 1), (args, done.stderr)


def test_every_franka_arm_test_is_in_the_folder_its_serial_run_collects() -> None:
    """run.sh collects only ``ARM_TESTS`` for the franka_arm tests' serial run: a test module
    elsewhere marked ``franka_arm`` would run in neither of its pytest runs (the suite's
    addopts leave the marker out)."""
    found = re.search(r'^ARM_TESTS="([^"]+)"$', RUN_SH.read_text(encoding="utf-8"), re.M)
    assert found is not None
    folder = ROOT / found[1]
    marked = {path for path in (ROOT / "tests").rglob("*.py")
              if re.search(r"mark\.franka_arm\b", path.read_text(encoding="utf-8"))}
    assert marked and all(folder in path.parents for path in marked), sorted(map(str, marked))
