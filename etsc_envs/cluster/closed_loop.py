"""One sampling period of the whole cluster's closed loop, compiled as a single call.

The integrated state is ``y`` of shape N×13, one row per follower: ``[σ_i (3), ω_i (3),
Θ̂_i (6), k̂_i]``. Plant (eqs. 2 and 4) and adaptation laws (eqs. 20-21, which run
continuously) advance together by one RK4 step with every follower's control u_i held at its
value from that follower's last event (eqs. 16 and 19). The value a follower's event sends to
its actuator, and remembers for its triggering condition, is a row of 9 numbers:
``[u_i(t_k) (3), s_i(t_k) (3), Y_i(t_k)Θ̂_i(t_k) (3)]``.

The environment keeps one cluster in a flat state row (layout below: a few cluster-wide
entries, then one record per follower, see :func:`follower_table`) and reaches it through the
kernels of :data:`KERNELS` (see :mod:`etsc_envs.core.compiled_loop`).
"""

from __future__ import annotations

from collections import namedtuple

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
from etsc_envs.core.compiled_loop import ProblemKernels, always_accepts
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import matvec

SAMPLE_WIDTH = 9
N_FEATURES = 19

PEAK_RATE = 0  # the largest max_i ‖ω_i‖ of the episode so far
LAST_FAST_STEP = 1  # the last step at which max_i ‖ω_i‖ exceeded 5 % of that peak (-1: none)
CLUSTER_WIDTH = 2
"""Cluster-wide entries at the start of the state row; the followers' records follow."""

PLANT = slice(0, 13)  # y_i = [σ_i, ω_i, Θ̂_i, k̂_i]
SAMPLE = slice(13, 22)  # [u_i, s_i, Y_iΘ̂_i] that an event would send now
FEATURES = slice(22, 41)  # the follower's observation features, see agent_features
NORMS = slice(41, 43)  # [‖σ_i‖, ‖ω_i‖] (for the failure bounds)
DISTURBANCE_PHASE = slice(43, 47)  # phases of the four periodic terms of eq. (68)
CONVERGENCE_THRESHOLD = 47  # 5 % of the initial ‖σ_i - σ_d,i‖ (at least 1e-6)
LAST_OUTSIDE_STEP = 48  # the last step at which ‖σ_i - σ_d,i‖ exceeded it (-1: none)
FOLLOWER_WIDTH = 49
"""Layout of one follower's record in the state row."""

NON_FINITE, DIVERGED = 1, 2
"""Failure codes of :func:`loop_failure`."""

CONVERGENCE_FRACTION = 0.05
MIN_CONVERGENCE_THRESHOLD = 1e-6

LoopConstants = namedtuple("LoopConstants", ["model", "limits"])
"""What every episode shares: the cluster model (its disturbance phases are taken from the
state row) and the failure bounds ``[max ‖σ_i‖, max ‖ω_i‖ (rad/s)]``."""


def state_width(n_followers: int) -> int:
    """Length of the state row of a cluster of ``n_followers``."""
    return CLUSTER_WIDTH + n_followers * FOLLOWER_WIDTH


@jit
def follower_table(state: np.ndarray) -> np.ndarray:
    """The followers' records of the state row as an N×``FOLLOWER_WIDTH`` view."""
    return state[CLUSTER_WIDTH:].reshape(-1, FOLLOWER_WIDTH)


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


@jit
def episode_model(state: np.ndarray, constants: LoopConstants) -> ClusterModel:
    """The cluster model of the episode: the shared one with the state row's phases."""
    shared = constants.model
    return ClusterModel(
        shared.adjacency,
        shared.leader_attitudes,
        shared.inertia,
        shared.inertia_inverse,
        shared.constant_disturbance,
        shared.periodic_fraction,
        shared.periodic_rates,
        follower_table(state)[:, DISTURBANCE_PHASE],
        shared.alpha,
        shared.control_gain,
        shared.adaptation_gain,
        shared.switching_gain_rate,
        shared.saturating,
        shared.saturation_width,
        shared.torque_limit,
        shared.targets,
    )


@jit
def note_outside_followers(table: np.ndarray, errors: np.ndarray, step: int) -> None:
    """Record ``step`` for every follower whose ‖σ_i - σ_d,i‖ exceeds its threshold."""
    for i in range(table.shape[0]):
        if errors[i] > table[i, CONVERGENCE_THRESHOLD]:
            table[i, LAST_OUTSIDE_STEP] = step


@jit
def note_peak_rate(state: np.ndarray, rate: float, step: int) -> None:
    """Keep the last step at which ``rate`` = max_i ‖ω_i‖ exceeded 5 % of its episode peak.

    A new peak set at ``step`` is the latest step, so it is that last step itself when it
    exceeds 5 % of itself (a positive finite peak) and no step otherwise (an infinite or NaN
    peak, which nothing exceeds); without a new peak, ``step`` counts if above 5 % of the peak.
    """
    peak = state[PEAK_RATE]
    if rate > peak or np.isnan(rate):
        state[PEAK_RATE] = rate
        state[LAST_FAST_STEP] = step if rate > CONVERGENCE_FRACTION * rate else -1
    elif rate > CONVERGENCE_FRACTION * peak:
        state[LAST_FAST_STEP] = step


@jit
def channel_values(state: np.ndarray, constants: LoopConstants, time_s: float) -> np.ndarray:
    """What each follower's event would send now: its ``[u_i, s_i, Y_iΘ̂_i]`` row."""
    return follower_table(state)[:, SAMPLE].copy()


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
    """One sampling period of every follower in the state row; follower i's cost is its
    distance to its containment target ‖σ_i - σ_d,i‖ (eq. 8)."""
    table = follower_table(state)
    y, samples, features, errors, norms = closed_loop_step(
        step_index * h, h, table[:, PLANT], held, episode_model(state, constants)
    )
    table[:, PLANT] = y
    table[:, SAMPLE] = samples
    table[:, FEATURES] = features
    table[:, NORMS] = norms
    channel_costs[:] = errors
    note_outside_followers(table, errors, step_index + 1)
    note_peak_rate(state, norms[:, 1].max(), step_index + 1)


@jit
def loop_failure(state: np.ndarray, constants: LoopConstants) -> int:
    """A non-finite state, or some ‖σ_i‖ or ‖ω_i‖ beyond its bound."""
    table = follower_table(state)
    if not np.isfinite(table[:, PLANT].sum() + table[:, SAMPLE].sum()):
        return NON_FINITE
    if not np.all(table[:, NORMS] <= constants.limits):
        return DIVERGED
    return 0


@jit
def loop_features(state: np.ndarray, constants: LoopConstants, out: np.ndarray) -> None:
    """The observation's features: every follower's, follower after follower."""
    table = follower_table(state)
    for i in range(table.shape[0]):
        out[i * N_FEATURES : (i + 1) * N_FEATURES] = table[i, FEATURES]


KERNELS = ProblemKernels(
    channel_values=channel_values,
    accepts=always_accepts,
    advance=advance_loop,
    failure=loop_failure,
    features=loop_features,
)
"""The compiled loop of paper 001 (one channel per follower)."""
