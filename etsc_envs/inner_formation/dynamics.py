"""Relative motion of the inner mass SC2 with respect to the outer spacecraft SC1 (paper 004).

Eq. (1) per axis is r̈_i = h_i + u_i, with the lumped term h of eq. (2):
h = Δa - 2 n × ṙ - n × (n × r) - ṅ × r, and ṅ = 0 for the constant rate of section 4.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.core.rotations import cross

RelativeMotionModel = namedtuple(
    "RelativeMotionModel",
    [
        "orbit_rate",  # n, rad/s
        "disturbance_amplitude",  # Δa_i = a_i sin(w_i t + p_i), m/s²
        "disturbance_frequency",
        "disturbance_phase",
    ],
)
"""Everything eq. (1) depends on besides the state and the control."""


@jit
def disturbance(t: float, model: RelativeMotionModel) -> np.ndarray:
    """Δa(t) of section 4, m/s²."""
    return model.disturbance_amplitude * np.sin(
        model.disturbance_frequency * t + model.disturbance_phase
    )


@jit
def lumped_term(t: float, position: np.ndarray, velocity: np.ndarray, model) -> np.ndarray:
    """h(t) of eq. (2): Δa - 2 n × ṙ - n × (n × r) (ṅ = 0)."""
    n = model.orbit_rate
    return disturbance(t, model) - 2.0 * cross(n, velocity) - cross(n, cross(n, position))


@jit
def lumped_term_rate(
    t: float, position: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, model
) -> np.ndarray:
    """ḣ(t), the quantity Assumption 1 bounds by M_i."""
    n = model.orbit_rate
    disturbance_rate = (
        model.disturbance_amplitude
        * model.disturbance_frequency
        * np.cos(model.disturbance_frequency * t + model.disturbance_phase)
    )
    return disturbance_rate - 2.0 * cross(n, acceleration) - cross(n, cross(n, velocity))
