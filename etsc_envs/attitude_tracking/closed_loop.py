"""One sampling period of the closed loop of paper 002, compiled as a single call.

Section 4 runs observer and controller "by difference approximation with t_s = 0.001 s": the
ET-ESO eq. (16) is advanced by a forward-Euler step and the control u(t_k) of eq. (24) is held
over the period; the plant of eq. (1) and the desired motion of eq. (2) are integrated with RK4.

The environment keeps one loop in a flat state row (layout below) and reaches it through the
kernels of :data:`KERNELS` (see :mod:`etsc_envs.core.compiled_loop`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.attitude_tracking.controller import (
    LoopGains,
    control_law,
    observer_derivative,
    trigger_statistic,
)
from etsc_envs.attitude_tracking.dynamics import (
    PlantModel,
    plant_derivative,
    plant_time_terms,
    tracking_error,
)
from etsc_envs.core import vec3
from etsc_envs.core.compiled_loop import ProblemKernels, always_accepts, stored_features
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import fused_dot

N_FEATURES = 13

PLANT = slice(0, 11)  # y = [q, ω, q_d] of the plant and the desired motion
OBSERVER = slice(11, 17)  # [x̂_1, x̂_2] of the ET-ESO, eq. (16)
MEASUREMENT = slice(17, 20)  # x_1 = z = ω_e + K q_ev at the current instant, eq. (8)
RATE_ERROR = slice(20, 23)  # ω_e of eq. (4)
TORQUE = slice(23, 26)  # u of eq. (24) over the last period
FEATURES = slice(26, 39)  # the sensor's features, see write_sensor_features
ACCUMULATED = slice(39, 43)  # running sums: eq. (50) rate and attitude terms, eq. (52), Σ|u_i|
INERTIA_PHASE = slice(43, 46)  # phases of ΔJ(t), drawn per episode when randomized
DISTURBANCE_PHASE = slice(46, 49)  # phases of d(t)
STATE_WIDTH = 49
"""Layout of the state row."""

NON_FINITE, OMEGA_DIVERGED, RATE_ERROR_DIVERGED = 1, 2, 3
"""Failure codes of :func:`loop_failure`."""

LoopConstants = namedtuple("LoopConstants", ["model", "gains", "max_rate"])
"""What every episode shares: the plant model (its phases are taken from the state row), the
observer and controller gains, and the divergence bound on |ω| and |ω_e| (rad/s)."""

integrate_plant = make_rk4_step(plant_derivative, plant_time_terms)


@jit
def write_sensor_features(features: np.ndarray, z, x_hat: np.ndarray, xi, gains: LoopGains) -> None:
    """Write what the sensor side knows at t_k into ``features``: ``[e_1, σ, z, x̂_2,
    Σ|α|/ε_min]``.

    e_1 = (x_1 - x̂_1)/ε and σ = (x_1(t_k) - x_1(t))/ε are the inputs of eq. (27) (eq. 25 and
    section 2); the sensor mirrors the observer to know x̂.
    """
    epsilon = gains.epsilon
    for i in range(3):
        features[i] = (z[i] - x_hat[i]) / epsilon[i]
        features[3 + i] = (xi[i] - z[i]) / epsilon[i]
        features[6 + i] = z[i]
        features[9 + i] = x_hat[3 + i]
    features[12] = trigger_statistic(features[0:3], features[3:6], gains)


@jit
def tracking_accuracy(y: np.ndarray, omega_d):
    """Integrands of eq. (50): (1/3) Σ|ω_i - ω_di| and (1/4) Σ|q_i - q_di|, for the desired
    rate ``omega_d`` at the instant of ``y``."""
    rate_error = vec3.absolute_sum(vec3.subtract(y[4:7], omega_d)) / 3.0
    attitude_error = 0.0
    for i in range(4):
        attitude_error += abs(y[i] - y[7 + i])
    return rate_error, attitude_error / 4.0


@jit
def kinetic_energy_change(y_next: np.ndarray, y: np.ndarray) -> float:
    """The step's term of eq. (52): Σ_i |½ ω_i(t_k + h)² - ½ ω_i(t_k)²|."""
    change = 0.0
    for i in range(4, 7):
        change += abs(0.5 * y_next[i] ** 2 - 0.5 * y[i] ** 2)
    return change


@jit
def closed_loop_step(
    t: float, h: float, state: np.ndarray, xi: np.ndarray, model: PlantModel, gains: LoopGains
):
    """Advance plant, desired motion and ET-ESO of the state row from t_k to t_k + h with the
    held ξ, and write the torque u(t_k) held over the period, z, ω_e and the sensor's features
    at t_k + h.

    Returns ``(rate_error, attitude_error, energy_increment)``: the eq. (50) integrands at
    t_k + h and the step's term of eq. (52).
    """
    x_hat = state[OBSERVER]
    torque = control_law(x_hat[0:3], x_hat[3:6], gains)
    d_hat1, d_hat2 = observer_derivative(x_hat[0:3], x_hat[3:6], xi, torque, gains)
    for i in range(3):
        x_hat[i] = x_hat[i] + h * d_hat1[i]
        x_hat[3 + i] = x_hat[3 + i] + h * d_hat2[i]
    y = state[PLANT]
    y_next = integrate_plant(t, y, h, (torque, model))
    y_next[0:4] /= np.sqrt(fused_dot(y_next[0:4], y_next[0:4]))
    y_next[7:11] /= np.sqrt(fused_dot(y_next[7:11], y_next[7:11]))
    energy_increment = kinetic_energy_change(y_next, y)
    y[:] = y_next
    t_next = t + h
    _, omega_e, z, _, omega_d = tracking_error(t_next, y, gains.attitude_gain, model)
    vec3.store(state[TORQUE], torque)
    vec3.store(state[MEASUREMENT], z)
    vec3.store(state[RATE_ERROR], omega_e)
    write_sensor_features(state[FEATURES], z, x_hat, xi, gains)
    rate_error, attitude_error = tracking_accuracy(y, omega_d)
    return rate_error, attitude_error, energy_increment


@jit
def episode_model(state: np.ndarray, constants: LoopConstants) -> PlantModel:
    """The plant model of the episode: the shared one with the state row's phases."""
    shared = constants.model
    return PlantModel(
        shared.nominal_inertia,
        shared.inertia_amplitude,
        shared.inertia_frequency,
        state[INERTIA_PHASE],
        shared.disturbance_amplitude,
        shared.disturbance_frequency,
        state[DISTURBANCE_PHASE],
        shared.reference_kind,
        shared.reference_amplitude,
        shared.reference_frequency,
        shared.reference_switch_period,
    )


@jit
def channel_values(state: np.ndarray, constants: LoopConstants, time_s: float) -> np.ndarray:
    """The sensor's transmission: the current measurement x_1(t_k)."""
    return state[MEASUREMENT].copy().reshape(1, 3)


@jit
def advance_loop(
    state: np.ndarray,
    constants: LoopConstants,
    step_index: int,
    h: float,
    held: np.ndarray,
    sent: np.ndarray,
    channel_costs: np.ndarray,
) -> None:
    """One sampling period in the state row; the cost is the eq. (50) integrands' sum."""
    rate_error, attitude_error, energy_increment = closed_loop_step(
        step_index * h, h, state, held[0], episode_model(state, constants), constants.gains
    )
    accumulated = state[ACCUMULATED]
    accumulated[0] += rate_error
    accumulated[1] += attitude_error
    accumulated[2] += energy_increment
    accumulated[3] += vec3.absolute_sum(state[TORQUE])
    channel_costs[0] = rate_error + attitude_error


@jit
def loop_failure(state: np.ndarray, constants: LoopConstants) -> int:
    """A non-finite state, or |ω| or |ω_e| beyond ``max_rate``."""
    if not np.isfinite(state[PLANT].sum() + state[FEATURES].sum()):
        return NON_FINITE
    omega = state[4:7]
    if np.sqrt(fused_dot(omega, omega)) > constants.max_rate:
        return OMEGA_DIVERGED
    omega_e = state[RATE_ERROR]
    if np.sqrt(fused_dot(omega_e, omega_e)) > constants.max_rate:
        return RATE_ERROR_DIVERGED
    return 0


KERNELS = ProblemKernels(
    channel_values=channel_values,
    accepts=always_accepts,
    advance=advance_loop,
    failure=loop_failure,
    features=stored_features(FEATURES),
)
"""The compiled loop of paper 002."""
