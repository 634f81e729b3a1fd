"""Relative motion of the inner mass SC2 with respect to the outer spacecraft SC1 (paper 004).

Eq. (1) per axis is r̈_i = h_i + u_i, with the lumped term h of eq. (2):
h = Δa - 2 n × ṙ - n × (n × r) - ṅ × r, and ṅ = 0 for the constant rate of section 4.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import jit

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
def disturbance(t: float, model: RelativeMotionModel) -> vec3.Vec3:
    """Δa(t) of section 4, m/s²."""
    return vec3.sine_wave(
        model.disturbance_amplitude, model.disturbance_frequency, t, model.disturbance_phase
    )


@jit
def lumped_term(t: float, position, velocity, model) -> vec3.Vec3:
    """h(t) of eq. (2): Δa - 2 n × ṙ - n × (n × r) (ṅ = 0)."""
    n = model.orbit_rate
    coriolis = vec3.scale(2.0, vec3.cross(n, velocity))
    centripetal = vec3.cross(n, vec3.cross(n, position))
    return vec3.subtract(vec3.subtract(disturbance(t, model), coriolis), centripetal)


@jit
def lumped_term_rate(t: float, position, velocity, acceleration, model) -> vec3.Vec3:
    """ḣ(t), the quantity Assumption 1 bounds by M_i."""
    n = model.orbit_rate
    amplitude, frequency, phase = (
        model.disturbance_amplitude,
        model.disturbance_frequency,
        model.disturbance_phase,
    )
    disturbance_rate = (
        amplitude[0] * frequency[0] * np.cos(frequency[0] * t + phase[0]),
        amplitude[1] * frequency[1] * np.cos(frequency[1] * t + phase[1]),
        amplitude[2] * frequency[2] * np.cos(frequency[2] * t + phase[2]),
    )
    coriolis_rate = vec3.scale(2.0, vec3.cross(n, acceleration))
    centripetal_rate = vec3.cross(n, vec3.cross(n, velocity))
    return vec3.subtract(vec3.subtract(disturbance_rate, coriolis_rate), centripetal_rate)
