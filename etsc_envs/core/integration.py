"""Fixed-step integration of ``ẏ = f(t, y, args)`` for the compiled hot path."""

from collections.abc import Callable

import numpy as np

from etsc_envs.core.jit import jit


def make_rk4_step(derivative: Callable) -> Callable:
    """Compile a classical Runge–Kutta step for the compiled ``derivative(t, y, args) -> ẏ``.

    The returned function ``rk4_step(t, y, h, args)`` advances ``y`` from ``t`` to ``t + h``;
    ``args`` is passed through to ``derivative`` unchanged (typically a tuple holding the held
    input and the model's parameters). The derivative is bound at compile time rather than
    passed as an argument so that the machine code can be cached on disk. The stages are
    written element by element into one buffer (the same arithmetic, in the same order, as
    ``y + 0.5 * h * k1`` and so on, without a temporary array per operation).
    """

    @jit
    def rk4_step(t: float, y: np.ndarray, h: float, args) -> np.ndarray:
        half_step = 0.5 * h
        start = y.ravel()
        stage = np.empty_like(y)
        stage_flat = stage.ravel()
        k1 = derivative(t, y, args).ravel()
        for i in range(start.size):
            stage_flat[i] = start[i] + half_step * k1[i]
        k2 = derivative(t + half_step, stage, args).ravel()
        for i in range(start.size):
            stage_flat[i] = start[i] + half_step * k2[i]
        k3 = derivative(t + half_step, stage, args).ravel()
        for i in range(start.size):
            stage_flat[i] = start[i] + h * k3[i]
        k4 = derivative(t + h, stage, args).ravel()
        sixth_step = h / 6.0
        out = np.empty_like(y)
        out_flat = out.ravel()
        for i in range(start.size):
            out_flat[i] = start[i] + sixth_step * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        return out

    return rk4_step
