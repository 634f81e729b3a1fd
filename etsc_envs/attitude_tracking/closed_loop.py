"""One sampling period of the closed loop of paper 002, compiled as a single call.

Section 4 runs observer and controller "by difference approximation with t_s = 0.001 s": the
ET-ESO eq. (16) is advanced by a forward-Euler step and the control u(t_k) of eq. (24) is held
over the period; the plant of eq. (1) and the desired motion of eq. (2) are integrated with RK4.
"""

from __future__ import annotations

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
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit

N_FEATURES = 13

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
    y_next[0:4] /= np.sqrt(y_next[0:4] @ y_next[0:4])
    y_next[7:11] /= np.sqrt(y_next[7:11] @ y_next[7:11])
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
