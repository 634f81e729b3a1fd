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
    desired_rate,
    plant_derivative,
    tracking_error,
)
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
FEATURES = slice(26, 39)  # the sensor's features, see sensor_features
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

integrate_plant = make_rk4_step(plant_derivative)


@jit
def sensor_features(
    z: np.ndarray, x_hat: np.ndarray, xi: np.ndarray, gains: LoopGains
) -> np.ndarray:
    """What the sensor side knows at t_k, as ``[e_1, σ, z, x̂_2, Σ|α|/ε_min]``.

    e_1 = (x_1 - x̂_1)/ε and σ = (x_1(t_k) - x_1(t))/ε are the inputs of eq. (27) (eq. 25 and
    section 2); the sensor mirrors the observer to know x̂.
    """
    features = np.empty(N_FEATURES)
    e1 = (z - x_hat[0:3]) / gains.epsilon
    sigma = (xi - z) / gains.epsilon
    features[0:3] = e1
    features[3:6] = sigma
    features[6:9] = z
    features[9:12] = x_hat[3:6]
    features[12] = trigger_statistic(e1, sigma, gains)
    return features


@jit
def tracking_accuracy(t: float, y: np.ndarray, model: PlantModel):
    """Integrands of eq. (50): (1/3) Σ|ω_i - ω_di| and (1/4) Σ|q_i - q_di|."""
    rate_error = np.abs(y[4:7] - desired_rate(t, model)).sum() / 3.0
    attitude_error = np.abs(y[0:4] - y[7:11]).sum() / 4.0
    return rate_error, attitude_error


@jit
def closed_loop_step(
    t: float,
    h: float,
    y: np.ndarray,
    x_hat: np.ndarray,
    xi: np.ndarray,
    model: PlantModel,
    gains: LoopGains,
):
    """Advance plant, desired motion and ET-ESO from t_k to t_k + h with the held ξ.

    Returns ``(y_next, x_hat_next, u, z_next, omega_e_next, features_next, rate_error,
    attitude_error,
    energy_increment)`` where the errors are the eq. (50) integrands at t_k + h and the energy
    increment is the step's term of eq. (52).
    """
    torque = control_law(x_hat[0:3], x_hat[3:6], gains)
    d_hat1, d_hat2 = observer_derivative(x_hat[0:3], x_hat[3:6], xi, torque, gains)
    x_hat_next = np.empty(6)
    x_hat_next[0:3] = x_hat[0:3] + h * d_hat1
    x_hat_next[3:6] = x_hat[3:6] + h * d_hat2
    y_next = integrate_plant(t, y, h, (torque, model))
    y_next[0:4] /= np.sqrt(fused_dot(y_next[0:4], y_next[0:4]))
    y_next[7:11] /= np.sqrt(fused_dot(y_next[7:11], y_next[7:11]))
    t_next = t + h
    _, omega_e_next, z_next, _ = tracking_error(t_next, y_next, gains.attitude_gain, model)
    features = sensor_features(z_next, x_hat_next, xi, gains)
    rate_error, attitude_error = tracking_accuracy(t_next, y_next, model)
    energy_increment = np.abs(0.5 * y_next[4:7] ** 2 - 0.5 * y[4:7] ** 2).sum()
    return (
        y_next,
        x_hat_next,
        torque,
        z_next,
        omega_e_next,
        features,
        rate_error,
        attitude_error,
        energy_increment,
    )


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
    model = episode_model(state, constants)
    (
        plant,
        observer,
        torque,
        measurement,
        rate_error_vector,
        features,
        rate_error,
        attitude_error,
        energy_increment,
    ) = closed_loop_step(
        step_index * h, h, state[PLANT], state[OBSERVER], held[0], model, constants.gains
    )
    state[PLANT] = plant
    state[OBSERVER] = observer
    state[TORQUE] = torque
    state[MEASUREMENT] = measurement
    state[RATE_ERROR] = rate_error_vector
    state[FEATURES] = features
    accumulated = state[ACCUMULATED]
    accumulated[0] += rate_error
    accumulated[1] += attitude_error
    accumulated[2] += energy_increment
    accumulated[3] += np.abs(torque).sum()
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
