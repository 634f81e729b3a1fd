"""Per-axis event-triggered ESO (eq. 3) and the output feedback of eqs. (15)-(16), paper 004."""

from __future__ import annotations

from collections import namedtuple

import numpy as np

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
    estimate: np.ndarray, held_position: np.ndarray, control: np.ndarray, design: ObserverFeedback
) -> np.ndarray:
    """Eq. (3) for the three axes; ``estimate = [ζ (3), ψ (3), φ (3)]``.

    ζ̇ = ψ + ℓβ_1 (r(t_k) - ζ),  ψ̇ = φ + ℓ²β_2 (r(t_k) - ζ) + u,  φ̇ = ℓ³β_3 (r(t_k) - ζ).
    Fed with r(t) instead of r(t_k) this is the continuous ESO of eq. (14).
    """
    innovation = held_position - estimate[0:3]
    gain = design.gain
    rate = np.empty(9)
    rate[0:3] = estimate[3:6] + gain * design.beta[0] * innovation
    rate[3:6] = estimate[6:9] + gain**2 * design.beta[1] * innovation + control
    rate[6:9] = gain**3 * design.beta[2] * innovation
    return rate


@jit
def control_law(estimate: np.ndarray, design: ObserverFeedback) -> np.ndarray:
    """u_i = û_i - φ_i (eq. 16) with û_i = -(1/50) g_i · [ζ_i, ψ_i, φ_i] (eq. 15, section 4).

    Row i of ``design.feedback`` acts on axis i's own estimates.
    """
    control = np.empty(3)
    for axis in range(3):
        row = design.feedback[axis]
        feedback = fused_multiply_add(
            row[2],
            estimate[6 + axis],
            fused_multiply_add(row[1], estimate[3 + axis], row[0] * estimate[axis]),
        )
        control[axis] = -feedback - estimate[6 + axis]
    return control
