"""Fixed-step integration of ``ẏ = f(t, y, args)`` for the compiled hot path."""

from collections.abc import Callable

import numpy as np

from etsc_envs.core.jit import jit


def make_rk4_step(derivative: Callable) -> Callable:
    """Compile a classical Runge–Kutta step for the compiled ``derivative(t, y, args) -> ẏ``.

    The returned function ``rk4_step(t, y, h, args)`` advances ``y`` from ``t`` to ``t + h``;
    ``args`` is passed through to ``derivative`` unchanged (typically a tuple holding the held
    input and the model's parameters). The derivative is bound at compile time rather than
    passed as an argument so that the machine code can be cached on disk.
    """

    @jit
    def rk4_step(t: float, y: np.ndarray, h: float, args) -> np.ndarray:
        k1 = derivative(t, y, args)
        k2 = derivative(t + 0.5 * h, y + 0.5 * h * k1, args)
        k3 = derivative(t + 0.5 * h, y + 0.5 * h * k2, args)
        k4 = derivative(t + h, y + h * k3, args)
        return y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)

    return rk4_step
