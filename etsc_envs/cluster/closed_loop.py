"""One sampling period of the whole cluster's closed loop, compiled as a single call.

The integrated state is ``y`` of shape N×13, one row per follower: ``[σ_i (3), ω_i (3),
Θ̂_i (6), k̂_i]``. Plant (eqs. 2 and 4) and adaptation laws (eqs. 20-21, which run
continuously) advance together by one RK4 step with every follower's control u_i held at its
value from that follower's last event (eqs. 16 and 19). The value a follower's event sends to
its actuator, and remembers for its triggering condition, is a row of 9 numbers:
``[u_i(t_k) (3), s_i(t_k) (3), Y_i(t_k)Θ̂_i(t_k) (3)]``.
"""

from __future__ import annotations

import numpy as np

from etsc_envs.cluster.controller import (
    control_law,
    parameter_rate,
    reference_rates,
    regressor,
    switching_gain_derivative,
    trigger_errors,
)
from etsc_envs.cluster.dynamics import (
    ClusterModel,
    attitude_rates,
    body_acceleration,
    containment_errors,
)
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import matvec

STATE_WIDTH = 13
SAMPLE_WIDTH = 9
N_FEATURES = 19


@jit
def follower_signals(y: np.ndarray, model: ClusterModel):
    """σ̇, s (eq. 10) and Y (eq. 13) of every follower at state ``y``.

    Returns ``(sigma_dot, s, regressors)`` with shapes N×3, N×3 and N×3×6.
    """
    n = y.shape[0]
    sigma = np.ascontiguousarray(y[:, 0:3])
    omega = np.ascontiguousarray(y[:, 3:6])
    sigma_dot = attitude_rates(sigma, omega)
    sigma_r_dot, sigma_r_ddot = reference_rates(sigma, sigma_dot, model)
    s = sigma_dot - sigma_r_dot
    regressors = np.empty((n, 3, 6))
    for i in range(n):
        regressors[i] = regressor(sigma[i], omega[i], sigma_r_dot[i], sigma_r_ddot[i])
    return sigma_dot, s, regressors


@jit
def loop_derivative(t: float, y: np.ndarray, args) -> np.ndarray:
    """ẏ: eq. (2) σ̇ = Gω, eq. (4) ω̇ with the held controls ``args[0]`` (N×3), eqs. (20)-(21)."""
    control, model = args
    sigma_dot, s, regressors = follower_signals(y, model)
    dy = np.empty_like(y)
    for i in range(y.shape[0]):
        sigma = np.ascontiguousarray(y[i, 0:3])
        omega = np.ascontiguousarray(y[i, 3:6])
        dy[i, 0:3] = sigma_dot[i]
        dy[i, 3:6] = body_acceleration(t, i, sigma, omega, control[i], model)
        dy[i, 6:12] = parameter_rate(regressors[i], s[i], model)
        dy[i, 12] = switching_gain_derivative(s[i], model)
    return dy


integrate_loop = make_rk4_step(loop_derivative)


@jit
def event_samples(y: np.ndarray, model: ClusterModel) -> np.ndarray:
    """What an event of each follower would send now: ``[u_i, s_i, Y_iΘ̂_i]`` (N×9), with u_i
    the control law eq. (19) at the current s_i, Y_iΘ̂_i and k̂_i."""
    _, s, regressors = follower_signals(y, model)
    samples = np.empty((y.shape[0], SAMPLE_WIDTH))
    for i in range(y.shape[0]):
        y_theta = matvec(regressors[i], y[i, 6:12])
        samples[i, 0:3] = control_law(s[i], y_theta, y[i, 12], model)
        samples[i, 3:6] = s[i]
        samples[i, 6:9] = y_theta
    return samples


@jit
def agent_features(
    t: float, y: np.ndarray, samples: np.ndarray, held: np.ndarray, model: ClusterModel
) -> np.ndarray:
    """Each follower's view at ``t`` (N×19, see ``FEATURE_NAMES`` of the environment).

    ``samples`` are the current ``[τ, s, YΘ̂]`` rows and ``held`` the rows of the last event.
    """
    n = y.shape[0]
    features = np.empty((n, N_FEATURES))
    gain_max = model.control_gain.max()
    gain_min = model.control_gain.min()
    for i in range(n):
        s = np.ascontiguousarray(samples[i, 3:6])
        e_j, e_s = trigger_errors(
            s,
            np.ascontiguousarray(samples[i, 6:9]),
            np.ascontiguousarray(held[i, 3:6]),
            np.ascontiguousarray(held[i, 6:9]),
        )
        s_norm = np.sqrt(s @ s)
        features[i, 0] = e_j + gain_max * e_s
        features[i, 1] = 0.5 * gain_min * s_norm
        features[i, 2] = e_j
        features[i, 3] = e_s
        features[i, 4] = s_norm
        features[i, 5] = np.sqrt(gain_min)
        features[i, 6] = t
        features[i, 7:10] = y[i, 0:3]
        features[i, 10:13] = y[i, 3:6]
        features[i, 13:16] = y[i, 0:3] - model.targets[i]
        features[i, 16:19] = held[i, 0:3]
    return features


@jit
def closed_loop_step(t: float, h: float, y: np.ndarray, held: np.ndarray, model: ClusterModel):
    """Advance every follower from t_k to t_k + h with the held event rows ``held`` (N×9).

    Returns ``(y_next, samples_next, features_next, errors_next, norms_next)``: the state,
    what an event would send at t_k + h, each follower's observation features there,
    ‖σ_i - σ_d,i‖, and the N×2 norms [‖σ_i‖, ‖ω_i‖] (for the failure bounds).
    """
    control = np.ascontiguousarray(held[:, 0:3])
    y_next = integrate_loop(t, y, h, (control, model))
    samples = event_samples(y_next, model)
    features = agent_features(t + h, y_next, samples, held, model)
    errors = containment_errors(np.ascontiguousarray(y_next[:, 0:3]), model)
    norms = np.empty((y.shape[0], 2))
    for i in range(y.shape[0]):
        norms[i, 0] = np.sqrt(y_next[i, 0] ** 2 + y_next[i, 1] ** 2 + y_next[i, 2] ** 2)
        norms[i, 1] = np.sqrt(y_next[i, 3] ** 2 + y_next[i, 4] ** 2 + y_next[i, 5] ** 2)
    return y_next, samples, features, errors, norms
