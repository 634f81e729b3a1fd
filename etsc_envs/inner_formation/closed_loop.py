"""One sampling period of paper 004's loop, compiled as a single call.

The observer (eq. 3) and the feedback (eqs. 15-16) are continuous-time in the paper; only the
measurement reaching the observer is sampled. They are therefore integrated together with the
plant (eq. 1) by one RK4 step per sampling period, with the held measurement r(t_k) constant.

The environment keeps one loop in a flat state row (layout below) and reaches it through the
kernels of :data:`KERNELS` (see :mod:`etsc_envs.core.compiled_loop`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.compiled_loop import ProblemKernels, always_accepts, stored_features
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import fused_dot
from etsc_envs.inner_formation.controller import (
    ObserverFeedback,
    control_law,
    observer_derivative,
)
from etsc_envs.inner_formation.dynamics import (
    RelativeMotionModel,
    lumped_term,
    lumped_term_rate,
)

N_FEATURES = 15

LOOP = slice(0, 15)  # y = [r, ṙ, ζ, ψ, φ] of eqs. (1) and (3)
CONTROL = slice(15, 18)  # u of eq. (16) at the current instant
FEATURES = slice(18, 33)  # the sensor's features, see write_sensor_features
DISTURBANCE_PHASE = slice(33, 36)  # the p_i of Δa, drawn per episode when randomized
STEADY_ERROR_MAX = slice(36, 45)  # steady-window maxima: |r - ζ|, |ṙ - ψ|, |h - φ| (3 axes each)
STEADY_OFFSET_MAX = 45  # steady-window maximum of ‖r‖
EXTREMES = slice(46, 55)  # episode maxima: |r_i|, |ṙ_i|, |ḣ_i| (3 axes each)
SAMPLING_ERROR_MAX = slice(55, 58)  # episode maximum of |r_i(t) - r_i(t_k)|
RETRANSMIT_ERROR_MIN = slice(58, 61)  # least |r_i(t) - r_i(t_k)| just before a re-transmission
SENT_BEFORE = slice(61, 64)  # 1 once axis i has transmitted in the episode
CONTROL_NORM_SUM = 64  # Σ ‖u‖ over the steps (m/s²)
STATE_WIDTH = 65
"""Layout of the state row."""

NON_FINITE, COLLISION = 1, 2
"""Failure codes of :func:`loop_failure`."""

LoopConstants = namedtuple(
    "LoopConstants", ["model", "design", "cavity_radius", "steady_start_step"]
)
"""What every episode shares: the relative-motion model (its phases are taken from the state
row), the observer and feedback design, the failure bound on ‖r‖ (m) and the sampling instant
after which the steady-state window begins."""


@jit
def loop_derivative(t: float, y: np.ndarray, args) -> np.ndarray:
    """ẏ for ``y = [r, ṙ, ζ, ψ, φ]`` (15) with the held measurement ``args[0]``."""
    held_position, model, design = args
    estimate = y[6:15]
    control = control_law(estimate, design)
    acceleration = vec3.add(lumped_term(t, y[0:3], y[3:6], model), control)
    position_rate, velocity_rate, disturbance_rate = observer_derivative(
        estimate, held_position, control, design
    )
    dy = np.empty(15)
    for axis in range(3):
        dy[axis] = y[3 + axis]
        dy[3 + axis] = acceleration[axis]
        dy[6 + axis] = position_rate[axis]
        dy[9 + axis] = velocity_rate[axis]
        dy[12 + axis] = disturbance_rate[axis]
    return dy


integrate_loop = make_rk4_step(loop_derivative)


@jit
def estimation_errors(t: float, y: np.ndarray, control, model: RelativeMotionModel):
    """|r - ζ|, |ṙ - ψ|, |h - φ| per axis (the left sides of eqs. 8-10), and ḣ, given the
    feedback ``control`` of eq. (16) at ``y``; 3-tuples."""
    lumped = lumped_term(t, y[0:3], y[3:6], model)
    rate = lumped_term_rate(t, y[0:3], y[3:6], vec3.add(lumped, control), model)
    position_error = (abs(y[0] - y[6]), abs(y[1] - y[7]), abs(y[2] - y[8]))
    velocity_error = (abs(y[3] - y[9]), abs(y[4] - y[10]), abs(y[5] - y[11]))
    disturbance_error = (abs(lumped[0] - y[12]), abs(lumped[1] - y[13]), abs(lumped[2] - y[14]))
    return position_error, velocity_error, disturbance_error, rate


@jit
def write_sensor_features(features: np.ndarray, y: np.ndarray, held_position) -> None:
    """Write ``[r(t) - r(t_k), r, ζ, ψ, φ]`` into ``features``: what eqs. (4)-(6) read, the
    measurement, the estimates."""
    for axis in range(3):
        features[axis] = y[axis] - held_position[axis]
        features[3 + axis] = y[axis]
    features[6:15] = y[6:15]


@jit
def closed_loop_step(
    t: float,
    h: float,
    state: np.ndarray,
    held_position: np.ndarray,
    model: RelativeMotionModel,
    design: ObserverFeedback,
):
    """Advance plant, observers and feedback of the state row from t_k to t_k + h with r(t_k)
    held, and write the feedback u and the sensor's features at t_k + h.

    Returns ``(position_error, velocity_error, disturbance_error, lumped_rate)`` at t_k + h,
    the errors being the per-axis left sides of (8)-(10).
    """
    loop = state[LOOP]
    loop[:] = integrate_loop(t, loop, h, (held_position, model, design))
    control = control_law(loop[6:15], design)
    vec3.store(state[CONTROL], control)
    write_sensor_features(state[FEATURES], loop, held_position)
    return estimation_errors(t + h, loop, control, model)


@jit
def offset_norm(state: np.ndarray) -> float:
    """‖r‖, the inner mass's distance from the cavity's centre (m)."""
    position = state[0:3]
    return np.sqrt(fused_dot(position, position))


@jit
def episode_model(state: np.ndarray, constants: LoopConstants) -> RelativeMotionModel:
    """The relative-motion model of the episode: the shared one with the state row's phases."""
    shared = constants.model
    return RelativeMotionModel(
        shared.orbit_rate,
        shared.disturbance_amplitude,
        shared.disturbance_frequency,
        state[DISTURBANCE_PHASE],
    )


@jit
def channel_values(state: np.ndarray, constants: LoopConstants, time_s: float) -> np.ndarray:
    """Axis i's transmission: the measurement r_i(t_k)."""
    return state[0:3].copy().reshape(3, 1)


@jit
def record_retransmissions(state: np.ndarray, sent: np.ndarray) -> None:
    """Keep, per axis, the least sampling error |r_i(t_k) - r_i(t_k')| at which the axis
    re-transmitted (t_k' its previous transmission): the Π_i that Theorem 3's (A24) bound is
    evaluated with."""
    grown = np.abs(state[FEATURES][0:3])
    least = state[RETRANSMIT_ERROR_MIN]
    sent_before = state[SENT_BEFORE]
    for axis in range(3):
        if sent[axis] != 0:
            if sent_before[axis] != 0.0:
                least[axis] = min(least[axis], grown[axis])
            sent_before[axis] = 1.0


@jit
def record_extremes(state: np.ndarray, lumped_rate) -> None:
    """Raise the episode maxima of |r_i(t) - r_i(t_k)|, |r_i|, |ṙ_i| and |ḣ_i|."""
    sampling_error = state[SAMPLING_ERROR_MAX]
    features = state[FEATURES]
    extremes = state[EXTREMES]
    for axis in range(3):
        sampling_error[axis] = max(sampling_error[axis], abs(features[axis]))
        extremes[axis] = max(extremes[axis], abs(state[axis]))
        extremes[3 + axis] = max(extremes[3 + axis], abs(state[3 + axis]))
        extremes[6 + axis] = max(extremes[6 + axis], abs(lumped_rate[axis]))


@jit
def record_steady(state: np.ndarray, position_error, velocity_error, disturbance_error) -> None:
    """Raise the steady-window maxima of the left sides of (8)-(10) and of ‖r‖."""
    steady = state[STEADY_ERROR_MAX]
    for axis in range(3):
        steady[axis] = max(steady[axis], position_error[axis])
        steady[3 + axis] = max(steady[3 + axis], velocity_error[axis])
        steady[6 + axis] = max(steady[6 + axis], disturbance_error[axis])
    state[STEADY_OFFSET_MAX] = max(state[STEADY_OFFSET_MAX], offset_norm(state))


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
    """One sampling period in the state row; axis i's cost is |r_i| + |r_i - ζ_i| (m)."""
    record_retransmissions(state, sent)
    position_error, velocity_error, disturbance_error, lumped_rate = closed_loop_step(
        step_index * h,
        h,
        state,
        held[:, 0],
        episode_model(state, constants),
        constants.design,
    )
    record_extremes(state, lumped_rate)
    if step_index + 1 > constants.steady_start_step:
        record_steady(state, position_error, velocity_error, disturbance_error)
    state[CONTROL_NORM_SUM] += np.sqrt(vec3.dot(state[CONTROL], state[CONTROL]))
    for axis in range(3):
        channel_costs[axis] = abs(state[axis]) + position_error[axis]


@jit
def loop_failure(state: np.ndarray, constants: LoopConstants) -> int:
    """A non-finite state, or the inner mass leaving its cavity (‖r‖ > ``cavity_radius``)."""
    if not np.isfinite(state[LOOP].sum()):
        return NON_FINITE
    if offset_norm(state) > constants.cavity_radius:
        return COLLISION
    return 0


KERNELS = ProblemKernels(
    channel_values=channel_values,
    accepts=always_accepts,
    advance=advance_loop,
    failure=loop_failure,
    features=stored_features(FEATURES),
)
"""The compiled loop of paper 004."""
