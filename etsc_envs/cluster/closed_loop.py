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
    reference_rates,
    regressor,
    regressor_times,
    switching_gain_derivative,
    trigger_errors,
    write_parameter_rate,
)
from etsc_envs.cluster.dynamics import (
    ClusterModel,
    body_acceleration,
    containment_error,
    write_attitude_rates,
)
from etsc_envs.core import vec3
from etsc_envs.core.compiled_loop import ProblemKernels, always_accepts
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit

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
def sliding_signals(follower: int, y: np.ndarray, sigma_dot: np.ndarray, model: ClusterModel):
    """s_i of eq. (10) and Y_i of eq. (13) of ``follower`` at the N×13 state ``y``, given every
    follower's σ̇ (eq. 2) in ``sigma_dot`` (N×3). Returns ``(s, regressor_rows)``."""
    sigma_r_dot, sigma_r_ddot = reference_rates(follower, y[:, 0:3], sigma_dot, model)
    own_rate = vec3.as_vec3(sigma_dot[follower])
    s = vec3.subtract(own_rate, sigma_r_dot)
    rows = regressor(y[follower, 0:3], y[follower, 3:6], own_rate, sigma_r_dot, sigma_r_ddot)
    return s, rows


@jit
def follower_signals(y: np.ndarray, model: ClusterModel):
    """σ̇ (eq. 2), s (eq. 10) and Y (eq. 13) of every follower at state ``y``, as arrays (for
    diagnostics; the step uses :func:`sliding_signals`).

    Returns ``(sigma_dot, s, regressors)`` with shapes N×3, N×3 and N×3×6.
    """
    n = y.shape[0]
    sigma_dot = np.empty((n, 3))
    s = np.empty((n, 3))
    regressors = np.empty((n, 3, 6))
    write_attitude_rates(y, sigma_dot)
    for i in range(n):
        s_i, rows = sliding_signals(i, y, sigma_dot, model)
        vec3.store(s[i], s_i)
        for row in range(3):
            for column in range(6):
                regressors[i, row, column] = rows[row][column]
    return sigma_dot, s, regressors


@jit
def loop_derivative(t: float, y: np.ndarray, args) -> np.ndarray:
    """ẏ: eq. (2) σ̇ = Gω, eq. (4) ω̇ with the held controls u_i = ``args[0][i, 0:3]``,
    eqs. (20)-(21)."""
    control, model = args
    dy = np.empty_like(y)
    sigma_dot = dy[:, 0:3]
    write_attitude_rates(y, sigma_dot)
    for i in range(y.shape[0]):
        s, rows = sliding_signals(i, y, sigma_dot, model)
        vec3.store(dy[i, 3:6], body_acceleration(t, i, y[i, 0:3], y[i, 3:6], control[i], model))
        write_parameter_rate(dy[i, 6:12], rows, s, model)
        dy[i, 12] = switching_gain_derivative(s, model)
    return dy


integrate_loop = make_rk4_step(loop_derivative)


@jit
def write_event_samples(y: np.ndarray, model: ClusterModel, out: np.ndarray) -> None:
    """Write what an event of each follower would send now into ``out`` (N×9):
    ``[u_i, s_i, Y_iΘ̂_i]``, with u_i the control law eq. (19) at the current s_i, Y_iΘ̂_i
    and k̂_i."""
    sigma_dot = np.empty((y.shape[0], 3))
    write_attitude_rates(y, sigma_dot)
    for i in range(y.shape[0]):
        s, rows = sliding_signals(i, y, sigma_dot, model)
        y_theta = regressor_times(rows, y[i, 6:12])
        vec3.store(out[i, 0:3], control_law(s, y_theta, y[i, 12], model))
        vec3.store(out[i, 3:6], s)
        vec3.store(out[i, 6:9], y_theta)


@jit
def write_agent_features(
    t: float,
    y: np.ndarray,
    samples: np.ndarray,
    held: np.ndarray,
    model: ClusterModel,
    out: np.ndarray,
) -> None:
    """Write each follower's view at ``t`` into ``out`` (N×19, see ``FEATURE_NAMES`` of the
    environment).

    ``samples`` are the current ``[τ, s, YΘ̂]`` rows and ``held`` the rows of the last event.
    """
    gain_max = model.control_gain.max()
    gain_min = model.control_gain.min()
    for i in range(y.shape[0]):
        features = out[i]
        s = samples[i, 3:6]
        e_j, e_s = trigger_errors(s, samples[i, 6:9], held[i, 3:6], held[i, 6:9])
        s_norm = np.sqrt(vec3.dot(s, s))
        features[0] = e_j + gain_max * e_s
        features[1] = 0.5 * gain_min * s_norm
        features[2] = e_j
        features[3] = e_s
        features[4] = s_norm
        features[5] = np.sqrt(gain_min)
        features[6] = t
        vec3.store(features[7:10], y[i, 0:3])
        vec3.store(features[10:13], y[i, 3:6])
        vec3.store(features[13:16], vec3.subtract(y[i, 0:3], model.targets[i]))
        vec3.store(features[16:19], held[i, 0:3])


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
def write_norms(table: np.ndarray) -> None:
    """Write every follower's [‖σ_i‖, ‖ω_i‖] (for the failure bounds) into its record."""
    for i in range(table.shape[0]):
        table[i, NORMS.start] = np.sqrt(table[i, 0] ** 2 + table[i, 1] ** 2 + table[i, 2] ** 2)
        table[i, NORMS.start + 1] = np.sqrt(table[i, 3] ** 2 + table[i, 4] ** 2 + table[i, 5] ** 2)


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
    """One sampling period of every follower in the state row: one RK4 step of plant (eqs. 2
    and 4) and adaptation laws (eqs. 20-21) with the held controls, then what an event would
    send and each follower's features at t_k + h. Follower i's cost is its distance to its
    containment target ‖σ_i - σ_d,i‖ (eq. 8)."""
    table = follower_table(state)
    model = episode_model(state, constants)
    t = step_index * h
    plant = table[:, PLANT]
    plant[:, :] = integrate_loop(t, np.ascontiguousarray(plant), h, (held, model))
    samples = table[:, SAMPLE]
    write_event_samples(plant, model, samples)
    write_agent_features(t + h, plant, samples, held, model, table[:, FEATURES])
    write_norms(table)
    for i in range(table.shape[0]):
        channel_costs[i] = containment_error(plant[i, 0:3], model.targets[i])
    note_outside_followers(table, channel_costs, step_index + 1)
    note_peak_rate(state, table[:, NORMS.start + 1].max(), step_index + 1)


@jit
def loop_failure(state: np.ndarray, constants: LoopConstants) -> int:
    """A non-finite state, or some ‖σ_i‖ or ‖ω_i‖ beyond its bound."""
    table = follower_table(state)
    if not np.isfinite(table[:, PLANT].sum() + table[:, SAMPLE].sum()):
        return NON_FINITE
    limits = constants.limits
    for i in range(table.shape[0]):
        if not (table[i, NORMS.start] <= limits[0] and table[i, NORMS.start + 1] <= limits[1]):
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
