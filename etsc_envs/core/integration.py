"""Fixed-step integration of ``ẏ = f(t, y, args)`` for the compiled hot path."""

from collections.abc import Callable

import numpy as np

from etsc_envs.core.jit import jit


@jit
def time_itself(t: float, args) -> float:
    """The default ``time_terms`` of :func:`make_rk4_step`: the time itself."""
    return t


def make_rk4_step(derivative: Callable, time_terms: Callable = time_itself) -> Callable:
    """Compile a classical Runge–Kutta step for the compiled ``derivative(t, y, args) -> ẏ``.

    The returned function ``rk4_step(t, y, h, args)`` advances ``y`` from ``t`` to ``t + h``;
    ``args`` is passed through to ``derivative`` unchanged (typically a tuple holding the held
    input and the model's parameters). The derivative is bound at compile time rather than
    passed as an argument so that the machine code can be cached on disk. The stages are
    written element by element into one buffer (the same arithmetic, in the same order, as
    ``y + 0.5 * h * k1`` and so on, without a temporary array per operation).

    ``time_terms(t, args)``, compiled, gives what the derivative needs of the time (by default
    the time itself), and the derivative takes its value in place of ``t``:
    ``derivative(time_terms(t, args), y, args)``. The step evaluates it once for each of its
    three stage times t, t + h/2 and t + h, so that a derivative whose time-dependent terms
    are costly (rotations, sines) computes them three times a step instead of four.
    """

    @jit
    def rk4_step(t: float, y: np.ndarray, h: float, args) -> np.ndarray:
        half_step = 0.5 * h
        start = y.ravel()
        stage = np.empty_like(y)
        stage_flat = stage.ravel()
        at_half_step = time_terms(t + half_step, args)
        k1 = derivative(time_terms(t, args), y, args).ravel()
        for i in range(start.size):
            stage_flat[i] = start[i] + half_step * k1[i]
        k2 = derivative(at_half_step, stage, args).ravel()
        for i in range(start.size):
            stage_flat[i] = start[i] + half_step * k2[i]
        k3 = derivative(at_half_step, stage, args).ravel()
        for i in range(start.size):
            stage_flat[i] = start[i] + h * k3[i]
        k4 = derivative(time_terms(t + h, args), stage, args).ravel()
        sixth_step = h / 6.0
        out = np.empty_like(y)
        out_flat = out.ravel()
        for i in range(start.size):
            out_flat[i] = start[i] + sixth_step * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        return out

    return rk4_step
