"""Writing output files whole or not at all: the one implementation for the whole project.

- :func:`write_atomic` writes a file through a temporary file in the same folder
  (write, flush, fsync, ``os.replace``, fsync of the folder): a reader sees the old
  content or the new, never a part; after a failure (full disk, no permission, missing
  folder) the old file is unchanged and no temporary file is left behind. A path that
  names a character device or a FIFO (``/dev/null``, ``/dev/stdout``, a named pipe) is
  written through, never replaced; a FIFO without a reader, a socket or a block device
  is refused.
- :func:`write_figure` renders a matplotlib figure into memory and writes it with
  :func:`write_atomic`.
- :func:`check_writable` checks, before a long run, that a file which a library writes
  itself (a Rerun ``.rrd``) can be created there.
- :func:`make_folder` creates an output folder (with its parents).

Every failure is a :class:`~bridge.BridgeError` of one line naming the path and the
operating system's reason, e.g. ``runs/x/learned.lp: cannot write (No space left on device)``.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import stat
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from bridge import BridgeError

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _current_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_FILE_MODE = 0o666 & ~_current_umask()  # what open() would give a new file


def os_reason(exc: OSError) -> str:
    """The operating system's reason of ``exc`` in words, e.g. ``No such file or directory``."""
    return exc.strerror or str(exc)


def _write_reason(exc: OSError, folder: Path) -> str:
    """:func:`os_reason`, naming ``folder`` when it is what is missing (the folder of an
    output file must exist: only output folders are created)."""
    if exc.errno == errno.ENOENT and not folder.is_dir():
        return f"{os_reason(exc)}: no folder {folder}; create it first"
    return os_reason(exc)


def _fsync_folder(folder: Path) -> None:
    fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _write_through(path: Path, mode: int, payload: bytes) -> Path:
    """Write ``payload`` into the special file ``path`` (of ``st_mode`` ``mode``) in place:
    a character device or a FIFO with a reader; BridgeError for anything else."""
    if not (stat.S_ISCHR(mode) or stat.S_ISFIFO(mode)):
        kind = "a block device" if stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode) else "a special file"
        raise BridgeError(f"{path}: cannot write ({kind}; expected a regular file, a character device or a FIFO)")
    try:
        fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)  # a FIFO without a reader fails at once (ENXIO)
    except OSError as exc:
        reason = "a FIFO with no reader" if exc.errno == errno.ENXIO and stat.S_ISFIFO(mode) else os_reason(exc)
        raise BridgeError(f"{path}: cannot write ({reason})") from None
    try:
        os.set_blocking(fd, True)
        view = memoryview(payload)
        while view:
            view = view[os.write(fd, view):]
    except OSError as exc:
        raise BridgeError(f"{path}: cannot write ({os_reason(exc)})") from None
    finally:
        os.close(fd)
    return path


def write_atomic(path: Path | str, data: bytes | str) -> Path:
    """Replace ``path`` by ``data`` (``str``: UTF-8) atomically and durably; returns the path.

    The data goes to a temporary file ``.<name>.<random>.tmp`` in the same folder, which
    is flushed, fsynced and renamed over ``path`` (``os.replace``); then the folder is
    fsynced so the rename survives a power cut. A new file gets the mode ``open()``
    would give it, an existing one keeps its mode. Raises BridgeError ``<path>: cannot
    write (<reason>)`` on any OSError (missing folder, ``path`` a directory, no
    permission, full disk); the old file then stays whole and the temporary is removed.
    A character device or a FIFO is written through in place (no atomicity to have), a
    FIFO without a reader, a socket or a block device refused: a special file is never
    replaced.
    """
    path = Path(path)
    payload = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    with contextlib.suppress(OSError):  # missing, or unreadable: the rename below reports it
        mode = path.stat().st_mode
        if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
            return _write_through(path, mode, payload)
    folder = path.parent
    temporary: str | None = None
    try:
        fd, temporary = tempfile.mkstemp(dir=folder, prefix=f".{path.name}.", suffix=".tmp")
        with os.fdopen(fd, "wb") as file:
            file.write(payload)
            file.flush()
            os.fsync(file.fileno())
        try:
            mode = path.stat().st_mode & 0o7777
        except FileNotFoundError:
            mode = _FILE_MODE
        os.chmod(temporary, mode)
        os.replace(temporary, path)
        temporary = None
        _fsync_folder(folder)
    except OSError as exc:
        raise BridgeError(f"{path}: cannot write ({_write_reason(exc, folder)})") from None
    finally:
        if temporary is not None:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
    return path


def write_figure(path: Path | str, figure: Figure, dpi: float = 120) -> Path:
    """Lay out ``figure`` (``tight_layout``), render it in memory in the format of the file
    name's suffix (default PNG) at ``dpi`` [dots per inch], :func:`write_atomic` it and
    close the figure, also when writing fails; returns the path."""
    import matplotlib.pyplot as plt

    path = Path(path)
    try:
        figure.tight_layout()
        buffer = io.BytesIO()
        figure.savefig(buffer, format=path.suffix.lstrip(".").lower() or "png", dpi=dpi)
        return write_atomic(path, buffer.getvalue())
    finally:
        plt.close(figure)


def check_writable(path: Path | str) -> Path:
    """Check that a file can be created at ``path`` (for files written by a library, such
    as a Rerun ``.rrd``): it is not a directory and its folder exists and accepts a new
    file (a temporary file is created there and removed). Returns the path; BridgeError
    ``<path>: cannot write (<reason>)`` if not."""
    path = Path(path)
    if path.is_dir():
        raise BridgeError(f"{path}: cannot write (Is a directory)")
    try:
        fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        os.close(fd)
        os.unlink(temporary)
    except OSError as exc:
        raise BridgeError(f"{path}: cannot write ({_write_reason(exc, path.parent)})") from None
    return path


def make_folder(path: Path | str) -> Path:
    """Create the output folder ``path`` and its parents if missing; returns it.
    BridgeError ``<path>: cannot create the folder (<reason>)`` if that fails (a parent
    is a regular file, no permission...)."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise BridgeError(f"{path}: cannot create the folder (a file of that name exists)") from None
    except OSError as exc:
        raise BridgeError(f"{path}: cannot create the folder ({os_reason(exc)})") from None
    return path
