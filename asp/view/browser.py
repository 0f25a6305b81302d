"""A headless Chromium driven through the DevTools protocol, to take pictures of a web page.

Chromium is started with ``--remote-debugging-pipe``: it reads protocol commands (JSON,
each ended by a NUL byte) on its file descriptor 3 and writes answers and events on
descriptor 4, so no websocket client is needed. WebGL2 comes from SwiftShader (ANGLE),
which is what the Rerun web viewer falls back to when WebGPU finds no adapter.
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import select
import shutil
import signal
import tempfile
import time
from typing import Any

from asp import PlannerError

NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
"""Executables looked for on PATH, in this order."""
FLAGS = ("--headless=new", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--no-first-run", "--no-default-browser-check", "--mute-audio",
         "--remote-debugging-pipe")
COMMAND_TIMEOUT_S = 60.0
"""Longest one protocol command may take [s]."""


def find_chromium() -> str | None:
    """The first of :data:`NAMES` on PATH, or None."""
    return next((found for name in NAMES if (found := shutil.which(name))), None)


class Browser:
    """One headless Chromium with one page of ``width`` × ``height`` pixels, started niced
    (``nice`` added to its priority); use as a context manager (the browser is killed at exit)."""

    def __init__(self, executable: str, width: int = 1600, height: int = 1000, nice: int = 10) -> None:
        self._profile = tempfile.TemporaryDirectory(prefix="chromium-")
        to_browser, self._commands = os.pipe()
        self._answers, from_browser = os.pipe()
        argv = ["nice", "-n", str(nice), executable, *FLAGS, f"--user-data-dir={self._profile.name}",
                f"--window-size={width},{height}", "about:blank"]
        nice_path = shutil.which("nice")
        if nice_path is None:
            raise PlannerError("no 'nice' on PATH; expected coreutils")
        devnull = os.open(os.devnull, os.O_RDWR)
        try:
            self.pid = os.posix_spawn(nice_path, argv, os.environ, setsid=True, file_actions=[
                (os.POSIX_SPAWN_DUP2, devnull, 0), (os.POSIX_SPAWN_DUP2, devnull, 1),
                (os.POSIX_SPAWN_DUP2, devnull, 2), (os.POSIX_SPAWN_DUP2, to_browser, 3),
                (os.POSIX_SPAWN_DUP2, from_browser, 4)])
        finally:
            for fd in (to_browser, from_browser, devnull):
                os.close(fd)
        self._next_id = 0
        self._buffer = b""
        self._session = ""
        self.size = (width, height)

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def open(self, url: str) -> None:
        """Open ``url`` in a new page of :attr:`size` and attach to it."""
        target = self.command("Target.createTarget", url="about:blank")["targetId"]
        self._session = self.command("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        width, height = self.size
        self.command("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1,
                     mobile=False)
        self.command("Page.navigate", url=url)

    def screenshot(self) -> bytes:
        """The page as PNG bytes."""
        return base64.b64decode(self.command("Page.captureScreenshot", format="png")["data"])

    def evaluate(self, expression: str, await_promise: bool = False) -> Any:
        """The value of a JavaScript ``expression`` in the page (``await_promise``: the value
        the promise it gives resolves to); PlannerError naming the exception it throws."""
        answer = self.command("Runtime.evaluate", expression=expression, returnByValue=True,
                              awaitPromise=await_promise)
        if "exceptionDetails" in answer:
            details = answer["exceptionDetails"]
            raise PlannerError(f"chromium: {expression[:60]}: "
                               f"{details.get('exception', {}).get('description', details.get('text'))}")
        return answer["result"].get("value")

    def command(self, method: str, **params: Any) -> dict[str, Any]:
        """Send one protocol command (to the page once :meth:`open` attached) and wait for
        its answer; PlannerError on an error answer or after :data:`COMMAND_TIMEOUT_S`."""
        self._next_id += 1
        message: dict[str, Any] = {"id": self._next_id, "method": method, "params": params}
        if self._session and not method.startswith("Target."):
            message["sessionId"] = self._session
        os.write(self._commands, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + COMMAND_TIMEOUT_S
        while True:
            answer = self._receive(deadline)
            if answer.get("id") != self._next_id:
                continue  # an event, or the answer to an earlier command
            if "error" in answer:
                raise PlannerError(f"chromium: {method}: {answer['error'].get('message', answer['error'])}")
            result: dict[str, Any] = answer.get("result", {})
            return result

    def _receive(self, deadline: float) -> dict[str, Any]:
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._answers], [], [], left)[0]:
                raise PlannerError(f"chromium did not answer within {COMMAND_TIMEOUT_S:g} s")
            chunk = os.read(self._answers, 1 << 20)
            if not chunk:
                raise PlannerError("chromium exited (its DevTools pipe closed)")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        decoded: dict[str, Any] = json.loads(message)
        return decoded

    def close(self) -> None:
        """Kill the browser (its whole process group) and remove its profile."""
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.pid, signal.SIGKILL)
        with contextlib.suppress(ChildProcessError):
            os.waitpid(self.pid, 0)
        for fd in (self._commands, self._answers):
            with contextlib.suppress(OSError):
                os.close(fd)
        self._profile.cleanup()
