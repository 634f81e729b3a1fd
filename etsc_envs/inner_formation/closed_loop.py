"""One sampling period of paper 004's loop, compiled as a single call.

The observer (eq. 3) and the feedback (eqs. 15-16) are continuous-time in the paper; only the
measurement reaching the observer is sampled. They are therefore integrated together with the
plant (eq. 1) by one RK4 step per sampling period, with the held measurement r(t_k) constant.
"""

from __future__ import annotations

import numpy as np

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
def estimation_errors(t: float, y: np.ndarray, model: RelativeMotionModel, design):
    """|r - ζ|, |ṙ - ψ|, |h - φ| per axis (the left sides of eqs. 8-10), and ḣ."""
    control = control_law(y[6:15], design)
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
    position_error, velocity_error, disturbance_error, lumped_rate = estimation_errors(
        t_next, y_next, model, design
    )
    control = control_law(y_next[6:15], design)
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
