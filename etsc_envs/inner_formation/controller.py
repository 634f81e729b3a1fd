"""Per-axis event-triggered ESO (eq. 3) and the output feedback of eqs. (15)-(16), paper 004."""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import fused_multiply_add

ObserverFeedback = namedtuple(
    "ObserverFeedback",
    [
        "gain",  # ℓ_i, per axis
        "beta",  # [β_1, β_2, β_3], shared by the axes
        "feedback",  # 3×3: row i = (1/50) g_i of section 4
    ],
)
"""Design parameters of the observer and of the output feedback."""


@jit
def observer_derivative(
    estimate: np.ndarray, held_position, control, design: ObserverFeedback
) -> tuple[vec3.Vec3, vec3.Vec3, vec3.Vec3]:
    """Eq. (3) for the three axes; ``estimate = [ζ (3), ψ (3), φ (3)]``.

    ζ̇ = ψ + ℓβ_1 (r(t_k) - ζ),  ψ̇ = φ + ℓ²β_2 (r(t_k) - ζ) + u,  φ̇ = ℓ³β_3 (r(t_k) - ζ).
    Fed with r(t) instead of r(t_k) this is the continuous ESO of eq. (14).
    Returns ``(ζ̇, ψ̇, φ̇)``.
    """
    innovation = vec3.subtract(held_position, estimate[0:3])
    gain, beta = design.gain, design.beta
    position_gain = vec3.scale(beta[0], gain)
    velocity_gain = vec3.scale(beta[1], vec3.multiply(gain, gain))
    disturbance_gain = vec3.scale(beta[2], vec3.multiply(vec3.multiply(gain, gain), gain))
    position_rate = vec3.add(estimate[3:6], vec3.multiply(position_gain, innovation))
    velocity_rate = vec3.add(
        vec3.add(estimate[6:9], vec3.multiply(velocity_gain, innovation)), control
    )
    return position_rate, velocity_rate, vec3.multiply(disturbance_gain, innovation)


@jit
def control_law(estimate: np.ndarray, design: ObserverFeedback) -> vec3.Vec3:
    """u_i = û_i - φ_i (eq. 16) with û_i = -(1/50) g_i · [ζ_i, ψ_i, φ_i] (eq. 15, section 4).

    Row i of ``design.feedback`` acts on axis i's own estimates.
    """
    return (
        _axis_control(estimate, design.feedback, 0),
        _axis_control(estimate, design.feedback, 1),
        _axis_control(estimate, design.feedback, 2),
    )


@jit
def _axis_control(estimate: np.ndarray, feedback: np.ndarray, axis: int) -> float:
    row = feedback[axis]
    weighted = fused_multiply_add(
        row[2],
        estimate[6 + axis],
        fused_multiply_add(row[1], estimate[3 + axis], row[0] * estimate[axis]),
    )
    return -weighted - estimate[6 + axis]
