"""The project's one error root and its exit codes.

Every error the tool reports on purpose (bad input, an unsolvable request, a lost cell)
is a :class:`ToolError`; each layer has its subclass (:class:`asp.PlannerError`,
:class:`bridge.BridgeError`, :class:`executor.ExecutorError`), so a
caller may catch one layer's errors or all of them, and nothing needs converting between them. The command
line prints a ``ToolError`` as one line ``error: <message>`` and exits with
:data:`EXIT_BAD_INPUT`.
"""

from __future__ import annotations

EXIT_OK = 0
"""Done."""
EXIT_CHECK_FAILED = 1
"""A check the command ran failed (a benchmark's target, a schema that drifted)."""
EXIT_BAD_INPUT = 2
"""Bad input or usage: the message names the file:line or field and what was expected."""
EXIT_UNSOLVABLE = 3
"""The assembly cannot be finished: no complete hole assignment, or a plan stopped."""
EXIT_INTERRUPTED = 130
"""Ctrl-C."""
EXIT_TERMINATED = 143
"""Stopped by SIGTERM (128 + SIGTERM), after stopping the processes the command started."""
EXIT_BROKEN_PIPE = 141
"""Standard output closed by its reader (``... | head -1``): stopped quietly, as 128 + SIGPIPE."""


class ToolError(Exception):
    """Base of every error the tool reports: the message names the bad value (file:line
    or field) and what was expected."""
