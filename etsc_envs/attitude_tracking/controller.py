"""Event-triggered ESO, ADRC control law and triggering statistic of paper 002.

Each axis runs its own sub-observer (eq. 16) with high-gain parameter ε_i, fed by ξ, the last
measurement of x_1 = z that reached it (eq. 17).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import jit

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
def phi(theta: float) -> float:
    """The bounded nonlinearity φ(θ) of eq. (18): ¼ sin θ on [-π/2, π/2], ±¼ outside."""
    return 0.25 * np.sin(min(max(theta, -0.5 * np.pi), 0.5 * np.pi))


@jit
def g1(y: float, b: float) -> float:
    """g_1(y) = b y + φ(y) (section 2, with b = 2 in section 4), per component."""
    return b * y + phi(y)


@jit
def g2(y: float, c: float) -> float:
    """g_2(y) = c y (section 2, with c = 1 in section 4), per component."""
    return c * y


@jit
def control_law(x_hat1, x_hat2, gains: LoopGains) -> vec3.Vec3:
    """u = -J0 K̃ x̂_1 - J0 x̂_2 (eq. 24)."""
    return vec3.negate(
        vec3.matvec(
            gains.nominal_inertia, vec3.add(vec3.multiply(gains.control_gain, x_hat1), x_hat2)
        )
    )


@jit
def observer_derivative(x_hat1, x_hat2, xi, torque, gains: LoopGains):
    """Right-hand side of the ET-ESO eq. (16) fed by the held measurement ξ (eq. 17).

    Returns ``(dx̂_1/dt, dx̂_2/dt)`` as 3-tuples.
    """
    innovation = vec3.divide(vec3.subtract(xi, x_hat1), gains.epsilon)
    input_rate = vec3.solve(gains.nominal_inertia, torque)
    b, c, epsilon = gains.b, gains.c, gains.epsilon
    d_hat1 = (
        x_hat2[0] + g1(innovation[0], b) + input_rate[0],
        x_hat2[1] + g1(innovation[1], b) + input_rate[1],
        x_hat2[2] + g1(innovation[2], b) + input_rate[2],
    )
    d_hat2 = (
        g2(innovation[0], c) / epsilon[0],
        g2(innovation[1], c) / epsilon[1],
        g2(innovation[2], c) / epsilon[2],
    )
    return d_hat1, d_hat2


@jit
def trigger_statistic(e1, sigma, gains: LoopGains) -> float:
    """Σ_i Σ_j |α_ji(e_1i, σ_i)| / ε_min, the left side of eq. (27) over ε_min.

    α_j(e_1, σ) = g_j(e_1 + σ) - g_j(e_1); eq. (27) transmits when this exceeds Ψ.
    """
    b, c = gains.b, gains.c
    alpha1_sum = 0.0
    alpha2_sum = 0.0
    for i in range(3):
        alpha1_sum += abs(g1(e1[i] + sigma[i], b) - g1(e1[i], b))
        alpha2_sum += abs(g2(e1[i] + sigma[i], c) - g2(e1[i], c))
    return (alpha1_sum + alpha2_sum) / gains.epsilon.min()
