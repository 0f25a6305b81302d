"""Argument types both command lines share (argparse ``type=`` callables), and their parser.

A malformed value raises :class:`argparse.ArgumentTypeError`, which :class:`ArgumentParser`
turns into one line ``error: PROG: argument --x: ...`` and exit code 2. Numbers are
checked for finiteness and range (:func:`int_in`, :func:`non_negative_int`,
:func:`finite_float`), so no NaN, infinity or absurd count reaches the code.
"""

from __future__ import annotations

import argparse
import gc
import logging
import math
import os
import re
import signal
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any, NoReturn, TypeVar

from bridge import BridgeError
from bridge.errors import EXIT_BAD_INPUT, EXIT_BROKEN_PIPE, EXIT_INTERRUPTED, EXIT_TERMINATED
from bridge.inputs import shorten

T = TypeVar("T")

PROGRAM = "assembly-constraints"
"""The one console command (``pip install .`` puts it on PATH; ``./run.sh`` wraps it): every
help page and error names it (:class:`ArgumentParser` puts it before a subcommand's name)."""

MAX_SEED = 2**32 - 1
"""Seeds are integers in [0, MAX_SEED] (numpy's generators take no negative seed)."""

MAX_MESSAGE_CHARS = 300
"""argparse's messages (which echo the value) are cut to this many characters."""


class ArgumentParser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line on stderr, ``error: PROG: MESSAGE``,
    with exit code 2 (argparse's default adds the usage lines; ``--help`` shows them).
    ``prog`` is the subcommand (``"session"``, ``"executor serve"``): help pages and errors
    show it after :data:`PROGRAM`. Subparsers made by :meth:`add_subparsers` are of this class too."""

    def __init__(self, prog: str | None = None, **kwargs: Any) -> None:
        if prog is not None and not prog.startswith(PROGRAM):
            prog = f"{PROGRAM} {prog}"
        for key in ("description", "epilog"):  # often a module's docstring
            if kwargs.get(key):
                kwargs[key] = plain_text(kwargs[key])
        super().__init__(prog=prog, **kwargs)

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"error: {self.prog}: {shorten(' '.join(message.split()), MAX_MESSAGE_CHARS)}\n")


_ROLE = re.compile(r":(?:mod|class|func|meth|data|attr|exc):`~?([^`]+)`")
_STRONG = re.compile(r"\*\*([^*]+)\*\*")


def plain_text(text: str) -> str:
    """A docstring as a help page shows it: reStructuredText literals (double backquotes),
    roles (``:mod:`x` ``) and strong emphasis (``**x**``) as plain text, the repository's
    ``./run.sh`` as the program."""
    return _STRONG.sub(r"\1", _ROLE.sub(r"\1", text)).replace("``", "").replace("./run.sh", PROGRAM)


ASSEMBLY_HELP = ("a shipped assembly's name (cranfield, battery, spare, graded, taskboard) or a folder holding "
                 "assembly.toml")
"""The one meaning of ``--assembly`` on every help page."""


def add_assembly_argument(parser: argparse._ActionsContainer, default: str | None = "cranfield", *,
                          required: bool = False, purpose: str = "") -> None:
    """Add ``--assembly`` with its one meaning (:data:`ASSEMBLY_HELP`); ``purpose`` says
    what the command takes from it, ``default`` None: no default."""
    tail = f" (default {default})" if default is not None else ""
    parser.add_argument("--assembly", default=default, required=required, metavar="ASSEMBLY",
                        help=f"{ASSEMBLY_HELP}{tail}" + (f"; {purpose}" if purpose else ""))


class _OneLineFormatter(logging.Formatter):
    """``warning: message``: the level in lower case, like the ``error:`` lines; progress
    (INFO) and details (DEBUG) as the plain message."""

    def format(self, record: logging.LogRecord) -> str:
        if record.levelno < logging.WARNING:
            return one_line(record.getMessage())
        return f"{record.levelname.lower()}: {one_line(record.getMessage())}"


def path_setting(path: Path | None) -> str | None:
    """A parsed path option as a settings struct holds it (a string; None stays None)."""
    return None if path is None else str(path)


NATIVE_LOG_FILTER = "warn,re_log_encoding::rrd::file_sink=off,re_log_encoding::rrd::encoder=off"
"""``RUST_LOG`` of the Rerun SDK's native code unless the user sets it: its default level
(warnings and errors), without the file writer's own report of a failed write ("Failed to
write log stream to ...: ... (os error 28)", "encoder couldn't be finished"), since the
command reports that as its one error line (:func:`bridge.recording.sinks.finish_stream`)."""


def configure_logging(level: int | None = None) -> None:
    """Log to stderr, one line a record (``warning: ...``), from ``level`` up: the console
    command's default INFO (progress), ``-v`` DEBUG and ``-q`` ERROR. The handler is
    installed once per process (at WARNING when no level is given); a later call only
    sets a given level. Sets ``RUST_LOG`` to :data:`NATIVE_LOG_FILTER` when unset, which
    the Rerun SDK reads when it is imported (later: the subcommands import it lazily), and
    which the cells this process starts inherit."""
    os.environ.setdefault("RUST_LOG", NATIVE_LOG_FILTER)
    root = logging.getLogger()
    if not any(isinstance(handler.formatter, _OneLineFormatter) for handler in root.handlers):
        handler = logging.StreamHandler()
        handler.setFormatter(_OneLineFormatter())
        root.addHandler(handler)
        root.setLevel(logging.WARNING)
    if level is not None:
        root.setLevel(level)




def one_line(message: object, limit: int = 2000) -> str:
    """An error message as one line (whitespace runs, newlines included, become one space),
    cut to ``limit`` characters."""
    return shorten(" ".join(str(message).split()), limit)


def _stdout_to_devnull() -> None:
    """Point stdout's file descriptor at devnull, so the interpreter's final flush of
    what is still buffered cannot fail again."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)


def quiet_broken_pipe() -> int:
    """After a BrokenPipeError on stdout: point stdout at devnull and return
    :data:`EXIT_BROKEN_PIPE` (the Python documentation's recipe, "Note on SIGPIPE", with
    the shell's exit code)."""
    _stdout_to_devnull()
    return EXIT_BROKEN_PIPE


class StdoutError(Exception):
    """Writing stdout failed for another reason than a closed pipe (``> /dev/full``, a full
    disk, ``ulimit -f``)."""


class _GuardedStdout:
    """sys.stdout as is, except that a failed write or flush raises :class:`StdoutError`
    (a BrokenPipeError stays one: a closed pipe is quiet, see :func:`run_command`)."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        return self._guarded(self._stream.write, text)

    def flush(self) -> None:
        self._guarded(self._stream.flush)

    @staticmethod
    def _guarded(function: Callable[..., Any], *args: Any) -> Any:
        try:
            return function(*args)
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise StdoutError(f"stdout: cannot write ({exc.strerror or exc})") from None

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def run_command(command: Callable[[], int], errors: tuple[type[Exception], ...]) -> int:
    """Run a command line's work and return its exit code: ``errors`` (bad input) become one
    line ``error: ...`` on stderr and exit 2; a closed stdout (``... | head -1``) stops
    quietly with :data:`EXIT_BROKEN_PIPE`; stdout that cannot be written (``> /dev/full``)
    is ``error: stdout: cannot write (<reason>)``, exit 2; Ctrl-C exits 130, SIGTERM 143,
    both after the command's ``finally`` blocks and context managers ran (they stop the
    processes it started: cells, web viewer, browser). Log records go to stderr as one line
    each (:func:`configure_logging`)."""
    configure_logging()
    stdout = sys.stdout
    if not isinstance(stdout, _GuardedStdout):
        sys.stdout = _GuardedStdout(stdout)
    previous = _terminate_by_exception()
    try:
        code = command()
        sys.stdout.flush()  # a closed pipe or a full disk shows here, not in the interpreter's last flush
        return code
    except BrokenPipeError:
        return quiet_broken_pipe()
    except StdoutError as exc:
        _stdout_to_devnull()
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except errors as exc:
        print(f"error: {one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Terminated:
        print("terminated", file=sys.stderr)
        return EXIT_TERMINATED
    finally:
        sys.stdout = stdout
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


class Terminated(BaseException):
    """SIGTERM arrived (raised in the main thread by :func:`run_command`'s handler): like
    KeyboardInterrupt, it unwinds the command so its clean-up runs."""


def _on_sigterm(_signum: int, _frame: object) -> None:
    signal.signal(signal.SIGTERM, signal.SIG_IGN)  # a repeated SIGTERM does not cut the clean-up short
    raise Terminated


def worker_signals() -> None:
    """The initializer of a worker process a command forks (a pool's): SIGTERM, which the
    pool's ``terminate`` sends, ends it at once as by default, not through the command's
    handler it was forked with (which would raise :class:`Terminated` in it and print its
    traceback), and Ctrl-C is left to the command, which stops the pool."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def forked_worker() -> None:
    """The initializer of a worker process a command forks (a pool's): :func:`worker_signals`,
    and every object it inherits frozen (:func:`gc.freeze`): the worker's garbage
    collections then never walk them (a full collection writes to each object's header,
    so the kernel copies every page holding one: tens of MB a worker), and what is freed
    or collected is only what the worker made; cycles among the inherited objects are
    left to the parent, which keeps its own copy."""
    gc.freeze()
    worker_signals()


def _terminate_by_exception() -> signal.Handlers | Callable[..., Any] | int | None:
    """Make SIGTERM raise :class:`Terminated` while a command runs (Python's default ends the
    process at once, leaving its children running); returns the handler to restore, None
    when nothing was changed (not the main thread, or a handler of the caller's own)."""
    if threading.current_thread() is not threading.main_thread():
        return None
    current = signal.getsignal(signal.SIGTERM)
    if current not in (signal.SIG_DFL, None):
        return None
    signal.signal(signal.SIGTERM, _on_sigterm)
    return current


MAX_JOBS = 64
"""``--jobs``: at most this many processes or cells at once."""


def default_jobs() -> int:
    """The machine's cores (those this process may use), at most :data:`MAX_JOBS`."""
    return max(1, min(MAX_JOBS, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                      else os.cpu_count() or 1))


def add_jobs_argument(parser: argparse._ActionsContainer, what: str) -> None:
    """``--jobs N``: how many ``what`` run at once (default: the machine's cores). Results
    do not depend on N (each unit of work has its own seed and its own process or cell)."""
    parser.add_argument("--jobs", type=int_in(1, MAX_JOBS), default=default_jobs(), metavar="N",
                        help=f"{what} at once (default: the machine's cores, here {default_jobs()}); "
                             "the results do not depend on it")


_INTEGER = re.compile(r"[+-]?[0-9]+")
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|[+-]?(?:inf|infinity|nan)",
                      re.IGNORECASE)


def strict_int(text: str) -> int:
    """An item type: an integer written with ASCII digits and an optional sign, nothing
    else (``int`` alone also takes ``1_0``, ``５`` and surrounding blanks); ValueError otherwise."""
    if not _INTEGER.fullmatch(text):
        raise ValueError(text)
    return int(text)


def strict_float(text: str) -> float:
    """An item type: a decimal number with ASCII digits (``1``, ``-0.5``, ``2e-3``; also
    ``inf`` and ``nan``, for the caller's range check to name); ValueError for ``1_0``,
    ``５`` and the like, which ``float`` alone takes."""
    if not _DECIMAL.fullmatch(text):
        raise ValueError(text)
    return float(text)


def integer(text: str) -> int:
    """An argparse type: any integer, written as :func:`strict_int` takes it."""
    try:
        return strict_int(text)
    except ValueError:
        expected = "expected an integer (ASCII digits, optional sign)"
        raise argparse.ArgumentTypeError(f"{shorten(text)!r}: {expected}") from None


def int_in(low: int, high: int = sys.maxsize) -> Callable[[str], int]:
    """An argparse type: an integer in [low, high] (``high`` default: no practical bound),
    written as :func:`strict_int` takes it."""
    expected = f"an integer >= {low}" if high == sys.maxsize else f"an integer from {low} to {high}"

    def parse(text: str) -> int:
        try:
            value = strict_int(text)
        except ValueError:
            value = None
        if value is None or not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected {expected}")
        return value

    return parse


def non_negative_int(text: str) -> int:
    """An argparse type: an integer >= 0 (at most ``sys.maxsize``)."""
    return int_in(0)(text)


def finite_float(low: float, high: float, *, low_open: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite number in [low, high], or (low, high] when ``low_open``,
    written as :func:`strict_float` takes it."""
    expected = f"a finite number in {'(' if low_open else '['}{low:g}, {high:g}]"

    def parse(text: str) -> float:
        try:
            value = strict_float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and (low < value if low_open else low <= value) and value <= high):
            raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected {expected}")
        return value

    return parse


def comma_list(
    item: Callable[[str], T], what: str = "values", allow_empty: bool = False
) -> Callable[[str], list[T]]:
    """An argparse type: ``"a,b,c"`` → ``[item("a"), item("b"), item("c")]``.

    Empty items, items ``item`` rejects (ValueError, ArgumentTypeError, BridgeError) and an
    item given twice (``bp-p1,bp-p1`` would run it twice) are an error naming the whole text
    and ``what`` was expected; ``""`` is the empty list when ``allow_empty``.
    """

    def parse(text: str) -> list[T]:
        if allow_empty and not text.strip():
            return []
        parts = [part.strip() for part in text.split(",")]
        try:
            if not all(parts):
                raise ValueError(text)
            values = [item(part) for part in parts]
        except (ValueError, argparse.ArgumentTypeError, BridgeError):
            raise argparse.ArgumentTypeError(f"{shorten(text, 200)!r}: expected comma-separated {what}") from None
        twice = next((part for k, part in enumerate(parts) if values[k] in values[:k]), None)
        if twice is not None:
            raise argparse.ArgumentTypeError(f"{shorten(text, 200)!r}: {shorten(twice)!r} is given twice; expected "
                                             f"comma-separated {what}, each once")
        return values

    return parse


def number_in(kind: Callable[[str], float], low: float, high: float) -> Callable[[str], float]:
    """An argparse (or :func:`comma_list` item) type: a finite number of ``kind`` (``int``,
    ``float``, :func:`strict_int`...) in [low, high); ArgumentTypeError naming the range
    otherwise."""
    integer = kind in (int, strict_int)
    expected = f"{'an integer' if integer else 'a finite number'} in [{low:g}, {high:g})"

    def parse(text: str) -> float:
        try:
            value = kind(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and low <= value < high):
            raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected {expected}")
        return value

    return parse


def png_path(text: str) -> str:
    """An argparse type: a file path ending in ``.png`` (not a folder: matplotlib would
    write ``FOLDER.png`` beside it)."""
    if not text.lower().endswith(".png") or text.endswith(("/", "\\")):
        raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected a file path ending in .png")
    return text


def nonempty_path(text: str) -> Path:
    """An argparse type: a path, not the empty string (``Path("")`` is the current folder,
    so an empty ``$VAR`` would silently write there)."""
    if not text:
        raise argparse.ArgumentTypeError("expected a path, got the empty string")
    return Path(text)


def size_pair(text: str) -> tuple[int, int]:
    """An item type: ``"4x5"`` → ``(4, 5)``, both positive (ValueError otherwise)."""
    m, sep, n = text.partition("x")
    size = (strict_int(m), strict_int(n)) if sep else (0, 0)
    if min(size) < 1:
        raise ValueError(text)
    return size


def part_hole_pair(text: str) -> tuple[str, str]:
    """An item type: ``"p1:r1"`` → ``("p1", "r1")`` (ValueError otherwise)."""
    part, sep, hole = text.partition(":")
    if not (sep and part and hole) or ":" in hole:
        raise ValueError(text)
    return part, hole


def backend_option(text: str) -> tuple[str, str]:
    """An argparse type: ``"key=value"`` → ``("key", "value")``."""
    key, sep, value = text.partition("=")
    if not (sep and re.fullmatch(r"[A-Za-z_][\w-]*", key)):
        raise argparse.ArgumentTypeError(f"{shorten(text)!r}: expected KEY=VALUE")
    return key, value
