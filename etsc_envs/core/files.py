"""Output files that are either written whole or not at all.

Every tool of the suite that writes results (JSON, plots, models, summaries) checks the
destination before the work starts (:func:`require_writable_file`) and writes through a
temporary file in the same folder followed by an atomic rename (:func:`atomic_write_text`,
:func:`atomic_write_bytes`), so an interrupted or failed run never leaves a partly written
file where a finished one is expected. A write that goes through a library which turns an
interrupt into an error of its own (PyTorch's zip writer does) runs inside
:func:`interrupts_deferred`, so Ctrl-C still ends the run as an interrupt, just after the file.
"""

from __future__ import annotations

import argparse
import os
import signal
import tempfile
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path


def require_writable_file(path: str | Path, argument: str) -> Path:
    """``path`` as a :class:`Path` if a file can be written there, else ``ValueError`` naming
    ``argument``: the path is a folder, or a component of its parent is a file."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{argument} must name a file, got the folder {str(path)!r}")
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(
                    f"{argument} cannot be written: {str(parent)!r} is a file, not a folder"
                )
            if not os.access(parent, os.W_OK):
                raise ValueError(f"{argument} cannot be written: {str(parent)!r} is read-only")
            break
    return path


def require_writable_folder(path: str | Path, argument: str) -> Path:
    """``path`` as a :class:`Path` if it is, or can become, a writable folder, else
    ``ValueError`` naming ``argument``."""
    path = Path(path)
    for candidate in (path, *path.parents):
        if candidate.exists():
            if not candidate.is_dir():
                raise ValueError(f"{argument} cannot be a folder: {str(candidate)!r} is a file")
            if not os.access(candidate, os.W_OK):
                raise ValueError(f"{argument} cannot be written: {str(candidate)!r} is read-only")
            break
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


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename (parents created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    descriptor, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, path)
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
