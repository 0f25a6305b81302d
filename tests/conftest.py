"""Shared test infrastructure: the repository root, the one environment policy for
child processes, and the runners of the command lines (as separate processes, like
``./run.sh`` runs them).

Fixtures (session-scoped but ``cli_env``, so hypothesis tests may use them too):

- ``root`` → ``Path``: the repository root (also the constant ``ROOT``, for module-level paths);
- ``run_cli(*args, cwd=None, input=None, timeout=120)``: ``python -m assembly_constraints ARGS``;
- ``run_executor(*args, cwd=None, input=None, timeout=120)``: the same with ``executor ARGS``;
- ``run_main(*args, cwd=None, input=None, timeout=120)``: ``assembly_constraints.cli.main(ARGS)``
  in this process (function-scoped), for what a command does that is not about its process
  (its exit code, output and files): the same result without a child's start-up (Python and
  the imports of clingo, PyBullet, Rerun: about 1 s of CPU each), ``timeout`` unused; the
  working directory, stdin, the root logger's handlers and level, the environment and the
  handlers of :data:`HANDLED_SIGNALS` are this process's again after it;
- ``main_in_process(*args, cwd=None, input=None)`` (a function, not a fixture): the same as
  ``run_main`` for a module's or session's fixture, its output captured without ``capsys``;
- ``run_python(module, *args, cwd=None, input=None, timeout=120)``: ``python -m MODULE ARGS``
  (e.g. ``clingo``);
- ``run_session(*args, timeout=60)`` → ``dict``: ``session --backend truth --json ARGS`` (the
  ``TRUTH_SESSION`` arguments), which must exit 0; its JSON result;
- ``cli_argv(*args)`` → ``list[str]``: the argv of ``python -m assembly_constraints ARGS``, for ``Popen``;
- ``cli_env`` → ``dict``: a fresh copy of the environment of every child process (``child_env()``).

``assembled(folder, base, part, hole)`` runs the assembling cell in this process (a helper,
not a fixture): the base, then the part into its hole or onto its pin, each asserted to fit
(the part within 2 mm of its goal).

Each runner returns the ``subprocess.CompletedProcess`` (``capture_output=True, text=True``),
run in ``cwd`` (default: the repository root) with ``child_env()``; a run longer than
``timeout`` seconds raises ``subprocess.TimeoutExpired``. Tests that need a long-running
process (``Popen``: cells, SIGKILL) start it themselves, with ``cwd=root, env=cli_env``.

The environment policy lives here only: ``child_env()`` for children, and the autouse
``_no_display`` for this process (so the viewer or a GUI never opens, also not from cells a
test starts in-process).
"""

from __future__ import annotations

import contextlib
import fcntl
import functools
import io
import json
import logging
import os
import signal
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import pytest

from asp.session.cells import CellProcess

if TYPE_CHECKING:
    import numpy as np

    from executor.assembly.step import StepRecord
from tests._schedule import (  # noqa: F401 (hooks: the order on xdist's workers)
    pytest_collection_modifyitems,
    pytest_configure,
    pytest_xdist_make_scheduler,
)

ROOT = Path(__file__).resolve().parent.parent
CLI_MODULE = "assembly_constraints"  # ./run.sh SUBCOMMAND: the one command line
DEFAULT_TIMEOUT = 120.0  # [s] per command line run
TRUTH_SESSION = ("session", "--backend", "truth", "--json")  # a learning session with truthful cells
# Unset for the whole test run and its children: no viewer or GUI ever opens.
DISPLAY_VARIABLES = ("DISPLAY", "WAYLAND_DISPLAY")
HANDLED_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGPIPE, signal.SIGHUP)
"""Signals whose handlers ``run_main`` puts back after the command (a cell or a session
installs its own for SIGINT and SIGTERM)."""


def child_env() -> dict[str, str]:
    """The environment policy of every child process: this process's environment without
    a display, and ``PYTHONPATH`` = the repository root (only)."""
    env = {name: value for name, value in os.environ.items() if name not in DISPLAY_VARIABLES}
    env["PYTHONPATH"] = str(ROOT)
    return env


def python_argv(module: str, *args: str) -> list[str]:
    """The argv of ``python -m MODULE ARGS`` with this interpreter."""
    return [sys.executable, "-m", module, *args]


def python_module(module: str, *args: str, cwd: Path | str | None = None, input: str | None = None,
                  timeout: float = DEFAULT_TIMEOUT) -> subprocess.CompletedProcess[str]:
    """``python -m MODULE ARGS`` as a separate process under the environment policy."""
    return subprocess.run(python_argv(module, *args), cwd=ROOT if cwd is None else cwd, env=child_env(),
                          input=input, capture_output=True, text=True, timeout=timeout)


def error_lines(stderr: str) -> list[str]:
    """The non-empty lines of a command's stderr without PyBullet's banner (printed when the
    cell's modules are imported, before any input is read)."""
    return [line for line in stderr.splitlines() if line.strip() and not line.startswith("pybullet build time")]


class Runner(Protocol):
    def __call__(self, *args: str, cwd: Path | str | None = None, input: str | None = None,
                 timeout: float = DEFAULT_TIMEOUT) -> subprocess.CompletedProcess[str]: ...


@contextlib.contextmanager
def simulated_arm_lock() -> Iterator[None]:
    """Waits for, then holds, the machine's lock of franky-sim arms: each runs a
    free-running 1 kHz loop with its client, and two at once (one per test worker) starved
    each other into libfranka timeouts. For a module's fixture that shares one arm among
    its tests (which then do not take ``one_simulated_arm``: the lock is not re-entrant)."""
    with open(Path(tempfile.gettempdir()) / "assembly-constraints-franky-sim.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


@pytest.fixture
def one_simulated_arm() -> Iterator[None]:
    """The machine's lock of franky-sim arms (:func:`simulated_arm_lock`), held for the test."""
    with simulated_arm_lock():
        yield


@pytest.fixture(scope="session", autouse=True)
def _no_display() -> Iterator[None]:
    """No display for the tests themselves either (in-process code, cells they start)."""
    with pytest.MonkeyPatch.context() as patch:
        for name in DISPLAY_VARIABLES:
            patch.delenv(name, raising=False)
        yield


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture
def cli_env() -> dict[str, str]:
    return child_env()


@pytest.fixture(scope="session")
def run_cli() -> Runner:
    return functools.partial(python_module, CLI_MODULE)


@pytest.fixture(scope="session")
def run_executor() -> Runner:
    return functools.partial(python_module, CLI_MODULE, "executor")


@contextlib.contextmanager
def _as_a_process(cwd: Path | str | None, input: str | None) -> Iterator[None]:
    """The block runs a command as its own process would: in ``cwd`` (default: the
    repository root), ``input`` on stdin, no root log handler (the command's is made on the
    block's stderr, as a child's on its own); the working directory, stdin, the root
    logger's handlers and level, the environment and the handlers of
    :data:`HANDLED_SIGNALS` are this process's again after it."""
    root_logger = logging.getLogger()
    level = root_logger.level
    environ = dict(os.environ)
    handlers = {number: signal.getsignal(number) for number in HANDLED_SIGNALS}
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(ROOT if cwd is None else cwd)
        patch.setattr(sys, "stdin", io.StringIO(input or ""))
        patch.setattr(root_logger, "handlers", [])
        try:
            yield
        finally:
            # what a command sets for its process (RUST_LOG, its signal handlers) ends with it
            root_logger.setLevel(level)
            os.environ.clear()
            os.environ.update(environ)
            for number, handler in handlers.items():
                if handler is not None:
                    signal.signal(number, handler)


def _exit_code(args: tuple[str, ...]) -> int:
    """``assembly_constraints.cli.main(ARGS)``'s exit code (argparse's errors: its SystemExit's)."""
    from assembly_constraints.cli import main

    try:
        return main(list(args))
    except SystemExit as exit_:
        return exit_.code if isinstance(exit_.code, int) else 1


def main_in_process(*args: str, cwd: Path | str | None = None, input: str | None = None,
                    timeout: float = DEFAULT_TIMEOUT) -> subprocess.CompletedProcess[str]:
    """``run_main`` for a module's or session's fixture, which cannot take a test's
    ``capsys``: the command's stdout and stderr are captured by redirecting
    ``sys.stdout`` and ``sys.stderr`` for its run; ``timeout`` unused."""
    out, err = io.StringIO(), io.StringIO()
    with _as_a_process(cwd, input), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = _exit_code(args)
    return subprocess.CompletedProcess([CLI_MODULE, *args], code, out.getvalue(), err.getvalue())


@pytest.fixture
def run_main(capsys: pytest.CaptureFixture[str]) -> Runner:
    def run(*args: str, cwd: Path | str | None = None, input: str | None = None,
            timeout: float = DEFAULT_TIMEOUT) -> subprocess.CompletedProcess[str]:
        capsys.readouterr()
        with _as_a_process(cwd, input):
            code = _exit_code(args)
        out, err = capsys.readouterr()
        return subprocess.CompletedProcess([CLI_MODULE, *args], code, out, err)
    return run


@pytest.fixture(scope="session")
def run_python() -> Callable[..., subprocess.CompletedProcess[str]]:
    return python_module


@pytest.fixture(scope="session")
def run_session(run_cli: Runner) -> Callable[..., dict]:
    def run(*args: str, timeout: float = 60) -> dict:
        done = run_cli(*TRUTH_SESSION, *args, timeout=timeout)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)
    return run


@pytest.fixture(scope="session")
def cli_argv() -> Callable[..., list[str]]:
    return functools.partial(python_argv, CLI_MODULE)


@pytest.fixture
def cells() -> Iterator[list[CellProcess]]:
    """Cell processes a test starts (append them); each is killed when the test ends."""
    started: list[CellProcess] = []
    try:
        yield started
    finally:
        for cell in started:
            cell.kill()


def assembled(folder: Path | str, base: str, part: str, hole: str) -> tuple[StepRecord, np.ndarray]:
    """The assembling cell's step of ``part`` into (or onto) ``hole`` of the taught product in
    ``folder`` after ``base`` stood in its place, and the part's orientation then (xyzw
    quaternion); asserts that both fit, the part within 2 mm of its goal pose."""
    # Imported here: the tests that assemble nothing do not load PyBullet.
    from executor.assembly.product import load_product
    from executor.assembly.step import Assembler
    from executor.cell_description import CellDescription

    assembler = Assembler(load_product(str(folder)), description=CellDescription())
    try:
        assert assembler.run_step(base, None, 0).outcome == "fit"
        step = assembler.run_step(part, hole, 0)
        _, quat = assembler.world.pose(part)
    finally:
        assembler.close()
    assert step.outcome == "fit" and step.pose_error < 0.002, step
    return step, quat
