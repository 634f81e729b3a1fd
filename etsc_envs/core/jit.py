"""The compiler used for every hot-path function of the suite.

Dynamics, observers and control laws are pure functions of flat float arrays compiled with
Numba, so that one environment step is a single compiled call. ``NUMBA_DISABLE_JIT=1`` in the
environment runs the same functions as plain Python (for debugging and coverage).
"""

from numba import njit

jit = njit(cache=True, nogil=True)
"""Decorator: compile a function in nopython mode, caching the machine code on disk."""

parallel_jit = njit(cache=True, nogil=True, parallel=True)
"""Decorator for batch precomputations: like :data:`jit`, and ``numba.prange`` loops run on all
cores (``NUMBA_NUM_THREADS`` limits them)."""
