"""The compiler used for every hot-path function of the suite.

Dynamics, observers and control laws are pure functions of flat float arrays compiled with
Numba, so that one environment step is a single compiled call. ``NUMBA_DISABLE_JIT=1`` in the
environment runs the same functions as plain Python (for debugging and coverage).

The machine code is cached on disk. Numba invalidates a cached function only when its own
source file changes, yet a compiled function carries the code of the compiled functions it
calls: after an edit of, say, ``core/rotations.py`` every caller in another file would load
its old machine code and silently compute with the old rotations. The caches here therefore
key every entry also by :func:`package_source_stamp`, which any edit of the package changes,
and by ``NUMBA_BOUNDSCHECK`` (code compiled with bounds checks is cached apart).
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import inspect
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from numba import config as numba_config
from numba import njit
from numba.core.caching import FunctionCache


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


@functools.cache
def package_source_stamp(package: str) -> str:
    """A digest of the path, modification time and size of every ``.py`` file of the
    top-level ``package`` (for a plain module, of its one file), computed once per process."""
    module = importlib.import_module(package)
    if hasattr(module, "__path__"):
        files = sorted(path for root in module.__path__ for path in Path(root).rglob("*.py"))
    else:
        file = getattr(module, "__file__", None)
        files = [Path(file)] if file else []
    entries = []
    for path in files:
        stat = path.stat()
        entries.append((str(path), stat.st_mtime_ns, stat.st_size))
    return _sha256(repr(entries).encode())


class PackageFunctionCache(FunctionCache):
    """Numba's on-disk cache with each entry keyed also by the source stamp of the function's
    top-level package, so that editing any module of it invalidates every cached function."""

    def _index_key(self, sig: Any, codegen: Any) -> tuple[Any, ...]:
        signature, magic, hashes = super()._index_key(sig, codegen)
        return signature, magic, (*hashes, self._package_stamp())

    def _package_stamp(self) -> str:
        stamp = package_source_stamp(self._py_func.__module__.partition(".")[0])
        # Machine code compiled with NUMBA_BOUNDSCHECK=1 checks every index; Numba's own key
        # leaves the flag out, so without it one run would load the other's code.
        return f"{stamp}+boundscheck" if getattr(numba_config, "BOUNDSCHECK", None) else stamp


def _with_cache(dispatcher: Any, cache: type[FunctionCache]) -> Any:
    if hasattr(dispatcher, "py_func"):  # compiled (not NUMBA_DISABLE_JIT)
        dispatcher._cache = cache(dispatcher.py_func)
    return dispatcher


_compile = njit(cache=True, nogil=True)
_compile_inline = njit(cache=True, nogil=True, inline="always")
_compile_parallel = njit(cache=True, nogil=True, parallel=True)


def jit(function: Callable[..., Any]) -> Callable[..., Any]:
    """Decorator: compile a function in nopython mode, caching the machine code on disk
    (:class:`PackageFunctionCache`)."""
    return _with_cache(_compile(function), PackageFunctionCache)


def inline_jit(function: Callable[..., Any]) -> Callable[..., Any]:
    """Like :func:`jit`, and Numba inlines the function's body into every compiled caller
    (``inline="always"``). For the step's small callees that take the model's namedtuples of
    arrays: a call across a compiled-function boundary pays reference counting on each array it
    passes (about 130 ns a call on this project's machine), an inlined body does not. Each
    caller compiles its own copy, so it is kept to the few functions a step calls most."""
    return _with_cache(_compile_inline(function), PackageFunctionCache)


def parallel_jit(function: Callable[..., Any]) -> Callable[..., Any]:
    """Decorator for batch precomputations: like :func:`jit`, and ``numba.prange`` loops run on
    all cores (``NUMBA_NUM_THREADS`` limits them)."""
    return _with_cache(_compile_parallel(function), PackageFunctionCache)


def compiled_function_identity(function: Any) -> tuple[Any, ...]:
    """What a compiled function (or a closure over compiled functions) is, the same in every
    process: module, qualified name, bytecode, the stamp (modification time and size) of its
    source file, and recursively the identity of every function it closes over; a value that
    is not a function (a flag a factory closes over) is its ``repr``."""
    if not callable(function):
        return (repr(function),)
    python_function = getattr(function, "py_func", function)
    try:
        source = inspect.getsourcefile(python_function)
        stat = os.stat(source) if source else None
        stamp = (stat.st_mtime_ns, stat.st_size) if stat else None
    except (OSError, TypeError):
        stamp = None
    cells = tuple(
        compiled_function_identity(cell.cell_contents) for cell in python_function.__closure__ or ()
    )
    return (
        python_function.__module__,
        python_function.__qualname__,
        _sha256(python_function.__code__.co_code),
        stamp,
        cells,
    )


class ClosureFunctionCache(PackageFunctionCache):
    """Numba's on-disk cache for a function that closes over other compiled functions.

    Numba keys a closure's cache entry by a pickle of the closed-over values, and a pickled
    dispatcher carries an id drawn afresh in every process: the entry written by one process
    never matches in the next, so every process compiled the closure again (8–11 s per problem)
    and the index grew by one entry per process. This cache keys the entry by
    :func:`compiled_function_identity` of the closed-over functions instead, which a new
    process computes alike and an edit of their source files changes.
    """

    def _index_key(self, sig: Any, codegen: Any) -> tuple[Any, ...]:
        identity = repr(
            tuple(
                compiled_function_identity(cell.cell_contents)
                for cell in self._py_func.__closure__ or ()
            )
        ).encode()
        return (
            sig,
            codegen.magic_tuple(),
            (_sha256(self._py_func.__code__.co_code), _sha256(identity), self._package_stamp()),
        )


def closure_jit(function: Callable[..., Any]) -> Callable[..., Any]:
    """Like :data:`jit`, for a function defined inside a factory that closes over compiled
    functions (the problem kernels of the loop step): cached on disk with
    :class:`ClosureFunctionCache`, so that later processes load it instead of compiling."""
    return _with_cache(_compile(function), ClosureFunctionCache)
