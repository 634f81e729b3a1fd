"""Barrier statistic, impulsive orbit control and adaptive attitude control of paper 003.

Orbit (section 3.1): once eq. (15) triggers, the thrusters fire for a fixed time with the
saturated radial law eqs. (16)-(17), evaluated on the current position. Attitude (section
3.2): the sliding-mode law eq. (18) with the adaptive gain of eq. (19) points the solar panel
(body x axis) at the Sun.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import jit

LoopGains = namedtuple(
    "LoopGains",
    [
        "reference_radius",  # r_0 of eqs. (15)-(16), m
        "shell_half_width",  # r_0 - r_min of eq. (16), m
        "thrust_gain",  # K_1 of eq. (16), N/m
        "max_thrust",  # F_M of eq. (17), N
        "attitude_gain",  # K_2 of eq. (18)
        "sliding_gain",  # k_1 of s = ω + k_1 q_v
        "adaptive_rate",  # c of eq. (19)
        "adaptive_leakage",  # c_1 of eq. (19)
        "tanh_sharpness",  # ρ of eq. (18)
        "desired_attitude",  # q_D: the Sun-pointing frame relative to I (scalar last)
    ],
)
"""Design parameters of the orbit and attitude controllers."""


@jit
def barrier_statistic(r: np.ndarray, v: np.ndarray, reference_radius: float) -> float:
    """(r_0 - ‖r‖) (r·v) / ‖r‖, the left side of eq. (15) without α (m²/s).

    Eq. (15) triggers a burst when this plus α is <= 0: the spacecraft moves away from r_0.
    """
    radius = np.sqrt(vec3.dot(r, r))
    return (reference_radius - radius) * vec3.dot(r, v) / radius


@jit
def thrust_law(r: np.ndarray, gains: LoopGains) -> vec3.Vec3:
    """τ = K_1 sgn(e) e tanh(e / (r_0 - r_min)) r/‖r‖ with e = r_0 - ‖r‖ (eq. 16), replaced by
    F_M sgn(e) r/‖r‖ when ‖τ‖ >= F_M (eq. 17); N, in the asteroid frame."""
    radius = np.sqrt(vec3.dot(r, r))
    error = gains.reference_radius - radius
    unit = vec3.divide(r, (radius, radius, radius))
    magnitude = gains.thrust_gain * abs(error) * np.tanh(error / gains.shell_half_width)
    if abs(magnitude) >= gains.max_thrust:
        return vec3.scale(gains.max_thrust * np.sign(error), unit)
    return vec3.scale(magnitude, unit)


@jit
def sliding_vector(q_error, omega, gains: LoopGains) -> vec3.Vec3:
    """s = ω + k_1 q_v (section 3.2), with q the attitude error and ω the body rate."""
    return vec3.add(omega, vec3.scale(gains.sliding_gain, q_error))


@jit
def attitude_law(s, b_hat: float, gains: LoopGains) -> vec3.Vec3:
    """u = -K_2 s - b̂ Tanh(ρ s) of eq. (18), N·m in the body frame."""
    gain, sharpness = -gains.attitude_gain, gains.tanh_sharpness
    return (
        gain * s[0] - b_hat * np.tanh(sharpness * s[0]),
        gain * s[1] - b_hat * np.tanh(sharpness * s[1]),
        gain * s[2] - b_hat * np.tanh(sharpness * s[2]),
    )


@jit
def adaptive_law(s, b_hat: float, gains: LoopGains) -> float:
    """db̂/dt = c ‖s‖ - c_1 b̂ of eq. (19)."""
    return gains.adaptive_rate * np.sqrt(vec3.dot(s, s)) - gains.adaptive_leakage * b_hat
