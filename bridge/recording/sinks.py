"""Where a recording goes: its file, and live to a Rerun viewer.

Every command that records takes the options :func:`add_viewer_arguments` adds, the
counterparts of the Rerun examples' ``--connect`` and ``--serve`` (named
``--rerun-connect`` / ``--rerun-serve`` because ``--connect`` already names a Zenoh
endpoint in ``session`` and ``executor serve``):

- ``--rerun-connect [URL]``: also stream live to a running viewer (``rerun`` started on
  this machine listens on :data:`DEFAULT_VIEWER_URL`);
- ``--rerun-serve``: also host the recording for a web browser (headless machines): a
  gRPC server and the web viewer on loopback ports the server binds itself (port 0); the
  address is logged.

:func:`open_stream` makes the stream with both sinks at once (file and viewer), so the
file is the same whether or not someone watches; :func:`hosted_viewer` runs the web
viewer (Rerun's own ``rerun --serve-web``) for as long as the command needs it.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import errno
import importlib.util
import logging
import os
import re
import resource
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

import rerun as rr
import rerun.blueprint as rrb

from bridge import BridgeError
from bridge.files import check_writable

DEFAULT_VIEWER_URL = "rerun+http://127.0.0.1:9876/proxy"
"""Where a Rerun viewer started on this machine listens for recordings."""
_LOG = logging.getLogger(__name__)


@dataclass(frozen=True)
class Viewer:
    """Live viewing of a recording: a viewer's URL to stream to, and/or a hosted web viewer;
    ``page``: the address a browser opens to see it (set by :func:`hosted_viewer`)."""

    connect: str | None = None
    serve: bool = False
    page: str | None = None


NO_VIEWER = Viewer()
"""Nobody watches live: the recording goes to its file only."""


def add_viewer_arguments(parser: argparse.ArgumentParser, serve: bool = True) -> None:
    """Add ``--rerun-connect [URL]`` and (``serve``) ``--rerun-serve`` to ``parser``."""
    parser.add_argument("--rerun-connect", nargs="?", const=DEFAULT_VIEWER_URL, metavar="URL",
                        help=f"also stream the recording live to a running Rerun viewer (default {DEFAULT_VIEWER_URL})")
    if serve:
        parser.add_argument("--rerun-serve", action="store_true",
                            help="also serve the recording to a web browser (for headless machines); "
                                 "the address to open is printed, Ctrl-C stops")


def viewer_of(args: argparse.Namespace) -> Viewer:
    """The :class:`Viewer` the options of :func:`add_viewer_arguments` ask for."""
    return Viewer(args.rerun_connect, getattr(args, "rerun_serve", False))


def open_stream(application_id: str, recording_id: str, rrd_path: Path | None,
                viewer: Viewer = NO_VIEWER) -> rr.RecordingStream:
    """A recording stream to ``rrd_path`` (checked writable first) and, if asked, live to
    ``viewer.connect``; in memory when there is neither. BridgeError naming the file if it
    cannot be written. (``viewer.serve`` is :func:`hosted_viewer`'s job.)"""
    recording = rr.RecordingStream(application_id, recording_id=recording_id)
    sinks: list[rr.FileSink | rr.GrpcSink] = []
    if rrd_path is not None:
        check_writable(rrd_path)
        sinks.append(rr.FileSink(str(rrd_path)))
    if viewer.connect:
        sinks.append(rr.GrpcSink(viewer.connect))
    if sinks:
        recording.set_sinks(*sinks)
    else:
        recording.memory_recording()
    return recording


def send_live_blueprint(application_id: str, recording_id: str, viewer: Viewer,
                        layout: rrb.BlueprintLike) -> None:
    """Send ``layout`` to the live viewer ``viewer.connect`` only (no file): a recording
    whose folder gets its blueprint when it ends (``view.rbl``) keeps none in its own file,
    since a viewer opening the folder takes whichever of the two it reads last (measured
    with rerun 0.41: a session's files in name order showed the file's)."""
    if viewer.connect is None:
        return
    stream = rr.RecordingStream(application_id, recording_id=recording_id)
    stream.set_sinks(rr.GrpcSink(viewer.connect))
    stream.send_blueprint(layout)
    stream.flush()
    stream.disconnect()


def finish_stream(recording: rr.RecordingStream, rrd_path: Path | None) -> None:
    """Flush ``recording`` and disconnect it (finishes its file). BridgeError ``<rrd>:
    cannot write (<reason>; ...)`` when Rerun's file writer stopped before, instead of the
    SDK's RuntimeError, which does not say why: the reason is what :func:`write_failure`
    finds now."""
    try:
        recording.flush()
    except RuntimeError as exc:
        with _stderr_silenced():  # the SDK logs the dead sink once more when it is replaced
            recording.memory_recording()
        reason = write_failure(rrd_path) if rrd_path is not None else ""
        raise BridgeError(f"{rrd_path}: cannot write ({reason + '; ' if reason else ''}"
                          f"the recording's file writer stopped: {exc})") from None
    recording.disconnect()


PROBE_BYTES = 4096
"""Size of the block :func:`write_failure` writes to find out whether the disk is full [bytes]."""


def write_failure(path: Path) -> str:
    """Why ``path`` cannot grow now, as the system says it: what writing and syncing
    :data:`PROBE_BYTES` to a temporary file beside it fails with (``No space left on
    device``), else ``File too large`` with the process's file size limit when one is set
    (``ulimit -f``); "" when neither applies."""
    try:
        with tempfile.TemporaryFile(dir=path.parent) as probe:
            probe.write(bytes(PROBE_BYTES))
            probe.flush()
            os.fsync(probe.fileno())
    except OSError as exc:
        return exc.strerror or str(exc)
    limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    if limit != resource.RLIM_INFINITY:
        return f"{os.strerror(errno.EFBIG)}: files are limited to {limit} bytes (ulimit -f)"
    return ""


@contextmanager
def _stderr_silenced() -> Iterator[None]:
    """File descriptor 2 (where the SDK's native code logs) pointed at devnull meanwhile."""
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


@contextmanager
def hosted_viewer(viewer: Viewer, files: Sequence[Path] = ()) -> Iterator[Viewer]:
    """With ``viewer.serve``: host a web viewer (Rerun's own ``rerun --serve-web``, a child
    process on loopback ports it binds itself, showing ``files`` and whatever streams into
    it) while the block runs, log its address, and give a :class:`Viewer` that streams to
    it. Otherwise give ``viewer`` unchanged. BridgeError if the server does not come up."""
    if not viewer.serve:
        yield viewer
        return
    with rerun_server(["--serve-web", "--web-viewer-port", "0", *map(str, files)], web=True) as server:
        server_url = server.url
        page = f"http://127.0.0.1:{server.web_port}/?url={quote(server_url, safe='')}"
        _LOG.info("web viewer: open %s", page)
        yield Viewer(connect=server_url, page=page)


_GRPC_PORT = re.compile(rb"Listening for gRPC connections on 127\.0\.0\.1:(\d+)")
_WEB_PORT = re.compile(rb"Hosting a web-viewer at http://127\.0\.0\.1:(\d+)")


@dataclass(frozen=True)
class RerunServer:
    """A running Rerun server (:func:`rerun_server`): its process (Rerun's binary, leader of
    its own process group), the ports it bound [TCP port numbers]."""

    process: subprocess.Popen
    grpc_port: int
    web_port: int | None

    @property
    def url(self) -> str:
        """Where a recording stream connects to it."""
        return f"rerun+http://127.0.0.1:{self.grpc_port}/proxy"


@contextmanager
def rerun_server(arguments: Sequence[str], web: bool = False) -> Iterator[RerunServer]:
    """Run Rerun's binary ``rerun --bind 127.0.0.1 --port 0 ARGUMENTS`` (in a process group of
    its own) while the block runs and give it with its gRPC port and (``web``) its web
    viewer's port: the ports the server bound itself, read from its log, so no other process
    can take them between a choice and the bind. The server and its children are stopped at
    exit (:func:`_stop`), and it dies with the thread that started it even when that one is
    killed (SIGKILL: no exit code runs; :func:`_die_with_parent`). BridgeError when it exits
    or does not log its ports within :data:`SERVER_START_S`."""
    with tempfile.TemporaryFile() as log:
        env = os.environ | {"RUST_LOG": "info", "RUST_LOG_STYLE": "never", "NO_COLOR": "1"}
        server = subprocess.Popen(
            [_rerun_binary(), "--bind", "127.0.0.1", "--port", "0", *arguments],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=log, env=env, start_new_session=True,
            preexec_fn=_die_with_parent(os.getpid()))
        try:
            ports = _logged_ports(log.fileno(), server, [_GRPC_PORT, _WEB_PORT] if web else [_GRPC_PORT])
            yield RerunServer(server, ports[0], ports[1] if web else None)
        finally:
            _stop(server)


def _rerun_binary() -> str:
    """The viewer binary ``rerun-sdk`` ships in its ``rerun_cli`` package, run directly: its
    wrapper ``python -m rerun_cli`` runs it as a child, which would outlive a killed wrapper."""
    spec = importlib.util.find_spec("rerun_cli")
    if spec is None or spec.origin is None:
        raise BridgeError("the Rerun viewer binary: no package rerun_cli (expected it installed with rerun-sdk)")
    return str(Path(spec.origin).parent / "rerun")


PR_SET_PDEATHSIG = 1
"""``prctl`` option: the signal a process gets when its parent thread ends (Linux)."""


def _die_with_parent(parent: int) -> Callable[[], None] | None:
    """The ``preexec_fn`` that makes a child get SIGKILL when the thread that started it
    ends, however it ends (Linux ``prctl(PR_SET_PDEATHSIG)``; elsewhere None, nothing);
    ``parent`` (its process id) ended already when the child's parent is another one."""
    if not sys.platform.startswith("linux"):
        return None
    prctl = ctypes.CDLL(None, use_errno=True).prctl  # looked up before the fork

    def set_death_signal() -> None:
        prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # it died before the signal was set
            os._exit(1)

    return set_death_signal


def _logged_ports(log: int, server: subprocess.Popen, patterns: Sequence[re.Pattern[bytes]]) -> list[int]:
    """The port each of ``patterns`` finds in the server's log (file descriptor ``log``),
    once all of them are there and the gRPC port accepts connections."""
    deadline = time.monotonic() + SERVER_START_S
    while time.monotonic() < deadline:
        found = [pattern.search(os.pread(log, MAX_LOG_BYTES, 0)) for pattern in patterns]
        if all(found):
            ports = [int(match.group(1)) for match in found if match]
            with socket.socket() as probe:
                if probe.connect_ex(("127.0.0.1", ports[0])) == 0:
                    return ports
        if server.poll() is not None:
            raise BridgeError(f"the Rerun server exited at start (code {server.returncode})")
        time.sleep(0.1)
    raise BridgeError(f"the Rerun server did not start (log its ports) within {SERVER_START_S:g} s")


MAX_LOG_BYTES = 64 * 1024
"""The start of the Rerun server's log searched for its ports [bytes]."""


def _stop(server: subprocess.Popen) -> None:
    """Stop the server and its children: the whole process group (its own session) gets
    SIGTERM, and SIGKILL for whatever is left."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(server.pid, signal.SIGTERM)
    with contextlib.suppress(subprocess.TimeoutExpired):
        server.wait(SERVER_START_S / 3)
    with contextlib.suppress(ProcessLookupError):
        os.killpg(server.pid, signal.SIGKILL)
    server.wait()


SERVER_START_S = 30.0
"""Longest the Rerun server may take to start or stop [s]."""

WAIT_POLL_S = 0.2
"""How often a command that only waits (:func:`keep_serving`) wakes to let Python run a
signal handler that one of the native libraries' threads received [s]."""


def keep_serving(viewer: Viewer) -> None:
    """With ``--rerun-serve``, keep the web viewer up once the work is done, until Ctrl-C
    (which ends the command normally); returns at once otherwise."""
    if not viewer.serve:
        return
    try:  # from the line on: a Ctrl-C right after it is already the normal end
        _LOG.info("done; still serving the recording to the web viewer (Ctrl-C to stop)")
        while True:
            time.sleep(WAIT_POLL_S)
    except KeyboardInterrupt:
        return
