"""Output files that are either written whole or not at all, checked before the work.

Every tool of the suite that writes results (JSON, plots, models, summaries) checks the
destination before the work starts (:func:`require_writable_file`,
:func:`require_writable_folder`): a probe file is created and removed in the folder that will
hold the output, so a place the process cannot write (a read-only or virtual file system,
which ``os.access`` reports as writable to root) is refused with one line, as are a folder
where a file is wanted and a file where a folder is wanted. Files are written through a
temporary file in the same folder followed by an atomic rename (:func:`atomic_write_text`,
:func:`atomic_write_bytes`), so an interrupted or failed run never leaves a partly written
file where a finished one is expected; a symbolic link is written through (its target is
replaced, the link kept), a device or a FIFO (``/dev/null``, a named pipe) is written in
place, and a new file gets the permissions the umask allows (an existing one keeps its own).
A write that goes through a library which turns an interrupt into an error of its own
(PyTorch's zip writer does) runs inside :func:`interrupts_deferred`, so Ctrl-C still ends the
run as an interrupt, just after the file.
"""

from __future__ import annotations

import argparse
import os
import signal
import stat
import tempfile
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path


def _nearest_existing(path: Path, argument: str) -> Path:
    """The nearest existing folder among ``path``'s parents (``path`` itself excluded), or
    ``ValueError`` naming ``argument`` when that nearest existing one is a file."""
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(
                    f"{argument} cannot be written: {str(parent)!r} is a file, not a folder"
                )
            return parent
    return Path.cwd()


def _probe(folder: Path, argument: str) -> None:
    """Create and remove a file in ``folder``, or ``ValueError`` naming ``argument`` with the
    system's reason."""
    try:
        descriptor, probe = tempfile.mkstemp(prefix=".write-probe-", dir=folder)
    except OSError as error:
        raise ValueError(
            f"{argument} cannot be written: no file can be created in {str(folder)!r} "
            f"({error.strerror or type(error).__name__})"
        ) from None
    os.close(descriptor)
    os.unlink(probe)


def _resolved(path: Path, argument: str) -> Path:
    """``path`` with its links followed, or ``ValueError`` naming ``argument`` for a loop of
    symbolic links."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):
        raise ValueError(
            f"{argument} cannot be written: {str(path)!r} is a loop of symbolic links"
        ) from None


def require_writable_file(path: str | Path, argument: str) -> Path:
    """``path`` as a :class:`Path` if a file can be written there, else ``ValueError`` naming
    ``argument``: the path (or the target of a link) is a folder, a component of its parent is
    a file, or no file can be created in the folder that would hold it. An existing device or
    FIFO passes (it is written in place)."""
    path = Path(path)
    target = _resolved(path, argument)
    if target.is_dir():
        raise ValueError(f"{argument} must name a file, got the folder {str(path)!r}")
    if target.exists() and not target.is_file():
        if not os.access(target, os.W_OK):
            raise ValueError(f"{argument} cannot be written: {str(path)!r} is not writable")
        return path
    _probe(_nearest_existing(target, argument), argument)
    return path


def require_writable_folder(path: str | Path, argument: str) -> Path:
    """``path`` as a :class:`Path` if it is, or can become, a folder in which files can be
    created, else ``ValueError`` naming ``argument``."""
    path = Path(path)
    target = _resolved(path, argument)
    if target.exists() and not target.is_dir():
        raise ValueError(f"{argument} must name a folder, got the file {str(path)!r}")
    _probe(target if target.is_dir() else _nearest_existing(target, argument), argument)
    return path


def output_file_argument(argument: str, *, stdout: bool = True) -> Callable[[str], str]:
    """An argparse ``type=`` for an output file option: the command line is refused at parse
    time, with one line naming ``argument``, when the file cannot be written (``-`` passes
    through as standard output if ``stdout``)."""

    def checked(value: str) -> str:
        if stdout and value == "-":
            return value
        try:
            require_writable_file(value, argument)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None
        return value

    return checked


def output_folder_argument(argument: str) -> Callable[[str], Path]:
    """An argparse ``type=`` for an output folder option (see :func:`output_file_argument`)."""

    def checked(value: str) -> Path:
        try:
            return require_writable_folder(value, argument)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None

    return checked


def _new_file_mode() -> int:
    """The permissions a new file gets under the process's umask (``0o666 & ~umask``)."""
    umask = os.umask(0o022)
    os.umask(umask)
    return 0o666 & ~umask


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename (parents created).

    A symbolic link is followed (its target is replaced, the link kept); a device or a FIFO is
    written in place; a new file gets the umask's permissions, a replaced one keeps its own."""
    path = Path(path)
    target = path.resolve()
    if target.exists() and not target.is_file() and not target.is_dir():
        with open(target, "wb") as stream:
            stream.write(data)
        return path
    target.parent.mkdir(parents=True, exist_ok=True)
    mode = stat.S_IMODE(target.stat().st_mode) if target.is_file() else _new_file_mode()
    descriptor, temporary = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
    try:
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(temporary, mode)
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` through a temporary file and a rename."""
    return atomic_write_bytes(path, text.encode("utf-8"))


@contextmanager
def interrupts_deferred() -> Iterator[None]:
    """Hold SIGINT until the block ends, then deliver it to the handler that was in place
    (``KeyboardInterrupt`` under Python's default). Outside the main thread, where Python
    cannot install signal handlers, the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: received.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if received:
        signal.raise_signal(signal.SIGINT)
