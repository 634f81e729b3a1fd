"""The compiler used for every hot-path function of the suite.

Dynamics, observers and control laws are pure functions of flat float arrays compiled with
Numba, so that one environment step is a single compiled call. ``NUMBA_DISABLE_JIT=1`` in the
environment runs the same functions as plain Python (for debugging and coverage).
"""

from __future__ import annotations

import hashlib
import inspect
import os
from collections.abc import Callable
from typing import Any

from numba import njit
from numba.core.caching import FunctionCache

jit = njit(cache=True, nogil=True)
"""Decorator: compile a function in nopython mode, caching the machine code on disk."""

parallel_jit = njit(cache=True, nogil=True, parallel=True)
"""Decorator for batch precomputations: like :data:`jit`, and ``numba.prange`` loops run on all
cores (``NUMBA_NUM_THREADS`` limits them)."""


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def compiled_function_identity(function: Any) -> tuple[Any, ...]:
    """What a compiled function (or a closure over compiled functions) is, the same in every
    process: module, qualified name, bytecode, the stamp (modification time and size) of its
    source file, and recursively the identity of every function it closes over."""
    python_function = getattr(function, "py_func", function)
    try:
        source = inspect.getsourcefile(python_function)
        stat = os.stat(source) if source else None
        stamp = (stat.st_mtime_ns, stat.st_size) if stat else None
    except (OSError, TypeError):
        stamp = None
    cells = tuple(
        compiled_function_identity(cell.cell_contents)
        if callable(cell.cell_contents)
        else repr(cell.cell_contents)
        for cell in python_function.__closure__ or ()
    )
    return (
        python_function.__module__,
        python_function.__qualname__,
        _sha256(python_function.__code__.co_code),
        stamp,
        cells,
    )


class ClosureFunctionCache(FunctionCache):
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
            (_sha256(self._py_func.__code__.co_code), _sha256(identity)),
        )


def closure_jit(function: Callable[..., Any]) -> Callable[..., Any]:
    """Like :data:`jit`, for a function defined inside a factory that closes over compiled
    functions (the problem kernels of the loop step): cached on disk with
    :class:`ClosureFunctionCache`, so that later processes load it instead of compiling."""
    dispatcher = jit(function)
    if hasattr(dispatcher, "py_func"):  # compiled (not NUMBA_DISABLE_JIT)
        dispatcher._cache = ClosureFunctionCache(dispatcher.py_func)
    return dispatcher
