"""Event-triggered ESO, ADRC control law and triggering statistic of paper 002.

Each axis runs its own sub-observer (eq. 16) with high-gain parameter ε_i, fed by ξ, the last
measurement of x_1 = z that reached it (eq. 17).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import fused_matvec3
from etsc_envs.core.rotations import solve3

LoopGains = namedtuple(
    "LoopGains",
    [
        "attitude_gain",  # diag(K) of z = ω_e + K q_ev
        "control_gain",  # diag(K̃) of eq. (24)
        "epsilon",  # ε_i of eq. (16)
        "b",  # g_1(y) = b y + φ(y)
        "c",  # g_2(y) = c y
        "nominal_inertia",  # J0 used by observer and controller
    ],
)
"""Design parameters of the observer and the controller."""


@jit
def phi(theta: np.ndarray) -> np.ndarray:
    """The bounded nonlinearity φ(θ) of eq. (18): ¼ sin θ on [-π/2, π/2], ±¼ outside."""
    return 0.25 * np.sin(np.minimum(np.maximum(theta, -0.5 * np.pi), 0.5 * np.pi))


@jit
def g1(y: np.ndarray, b: float) -> np.ndarray:
    """g_1(y) = b y + φ(y) (section 2, with b = 2 in section 4)."""
    return b * y + phi(y)


@jit
def g2(y: np.ndarray, c: float) -> np.ndarray:
    """g_2(y) = c y (section 2, with c = 1 in section 4)."""
    return c * y


@jit
def control_law(x_hat1: np.ndarray, x_hat2: np.ndarray, gains: LoopGains) -> np.ndarray:
    """u = -J0 K̃ x̂_1 - J0 x̂_2 (eq. 24)."""
    return -fused_matvec3(gains.nominal_inertia, gains.control_gain * x_hat1 + x_hat2)


@jit
def observer_derivative(
    x_hat1: np.ndarray, x_hat2: np.ndarray, xi: np.ndarray, torque: np.ndarray, gains: LoopGains
):
    """Right-hand side of the ET-ESO eq. (16) fed by the held measurement ξ (eq. 17).

    Returns ``(dx̂_1/dt, dx̂_2/dt)``.
    """
    innovation = (xi - x_hat1) / gains.epsilon
    d_hat1 = x_hat2 + g1(innovation, gains.b) + solve3(gains.nominal_inertia, torque)
    d_hat2 = g2(innovation, gains.c) / gains.epsilon
    return d_hat1, d_hat2


@jit
def trigger_statistic(e1: np.ndarray, sigma: np.ndarray, gains: LoopGains) -> float:
    """Σ_i Σ_j |α_ji(e_1i, σ_i)| / ε_min, the left side of eq. (27) over ε_min.

    α_j(e_1, σ) = g_j(e_1 + σ) - g_j(e_1); eq. (27) transmits when this exceeds Ψ.
    """
    alpha1 = g1(e1 + sigma, gains.b) - g1(e1, gains.b)
    alpha2 = g2(e1 + sigma, gains.c) - g2(e1, gains.c)
    return (np.abs(alpha1).sum() + np.abs(alpha2).sum()) / gains.epsilon.min()
