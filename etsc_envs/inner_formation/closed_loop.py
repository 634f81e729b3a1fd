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

from etsc_envs.core.compiled_loop import ProblemKernels, always_accepts, stored_features
from etsc_envs.core.integration import make_rk4_step
from etsc_envs.core.jit import jit
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
FEATURES = slice(18, 33)  # the sensor's features, see sensor_features
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
    dy = np.empty(15)
    dy[0:3] = y[3:6]
    dy[3:6] = lumped_term(t, y[0:3], y[3:6], model) + control
    dy[6:15] = observer_derivative(estimate, held_position, control, design)
    return dy


integrate_loop = make_rk4_step(loop_derivative)


@jit
def estimation_errors(t: float, y: np.ndarray, control: np.ndarray, model: RelativeMotionModel):
    """|r - ζ|, |ṙ - ψ|, |h - φ| per axis (the left sides of eqs. 8-10), and ḣ, given the
    feedback ``control`` of eq. (16) at ``y``."""
    lumped = lumped_term(t, y[0:3], y[3:6], model)
    rate = lumped_term_rate(t, y[0:3], y[3:6], lumped + control, model)
    return (
        np.abs(y[0:3] - y[6:9]),
        np.abs(y[3:6] - y[9:12]),
        np.abs(lumped - y[12:15]),
        rate,
    )


@jit
def sensor_features(y: np.ndarray, held_position: np.ndarray) -> np.ndarray:
    """``[r(t) - r(t_k), r, ζ, ψ, φ]``: what eqs. (4)-(6) read, the measurement, the estimates."""
    features = np.empty(N_FEATURES)
    features[0:3] = y[0:3] - held_position
    features[3:6] = y[0:3]
    features[6:15] = y[6:15]
    return features


@jit
def closed_loop_step(
    t: float,
    h: float,
    y: np.ndarray,
    held_position: np.ndarray,
    model: RelativeMotionModel,
    design: ObserverFeedback,
):
    """Advance plant, observers and feedback from t_k to t_k + h with r(t_k) held.

    Returns ``(y_next, features_next, position_error, velocity_error, disturbance_error,
    lumped_rate, control)`` at t_k + h, the errors being the per-axis left sides of (8)-(10).
    """
    y_next = integrate_loop(t, y, h, (held_position, model, design))
    t_next = t + h
    control = control_law(y_next[6:15], design)
    position_error, velocity_error, disturbance_error, lumped_rate = estimation_errors(
        t_next, y_next, control, model
    )
    features = sensor_features(y_next, held_position)
    return (
        y_next,
        features,
        position_error,
        velocity_error,
        disturbance_error,
        lumped_rate,
        control,
    )


@jit
def offset_norm(state: np.ndarray) -> float:
    """‖r‖, the inner mass's distance from the cavity's centre (m)."""
    position = state[0:3]
    return np.sqrt(position @ position)


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
def record_extremes(state: np.ndarray, lumped_rate: np.ndarray) -> None:
    """Raise the episode maxima of |r_i(t) - r_i(t_k)|, |r_i|, |ṙ_i| and |ḣ_i|."""
    sampling_error = state[SAMPLING_ERROR_MAX]
    sampling_error[:] = np.maximum(sampling_error, np.abs(state[FEATURES][0:3]))
    extremes = state[EXTREMES]
    extremes[0:3] = np.maximum(extremes[0:3], np.abs(state[0:3]))
    extremes[3:6] = np.maximum(extremes[3:6], np.abs(state[3:6]))
    extremes[6:9] = np.maximum(extremes[6:9], np.abs(lumped_rate))


@jit
def record_steady(
    state: np.ndarray,
    position_error: np.ndarray,
    velocity_error: np.ndarray,
    disturbance_error: np.ndarray,
) -> None:
    """Raise the steady-window maxima of the left sides of (8)-(10) and of ‖r‖."""
    steady = state[STEADY_ERROR_MAX]
    steady[0:3] = np.maximum(steady[0:3], position_error)
    steady[3:6] = np.maximum(steady[3:6], velocity_error)
    steady[6:9] = np.maximum(steady[6:9], disturbance_error)
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
    (
        loop,
        features,
        position_error,
        velocity_error,
        disturbance_error,
        lumped_rate,
        control,
    ) = closed_loop_step(
        step_index * h,
        h,
        state[LOOP],
        held[:, 0],
        episode_model(state, constants),
        constants.design,
    )
    state[LOOP] = loop
    state[FEATURES] = features
    state[CONTROL] = control
    record_extremes(state, lumped_rate)
    if step_index + 1 > constants.steady_start_step:
        record_steady(state, position_error, velocity_error, disturbance_error)
    state[CONTROL_NORM_SUM] += np.sqrt(control @ control)
    channel_costs[:] = np.abs(loop[0:3]) + position_error


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
