"""``etsc/InnerFormation-v0``: when should each axis's position measurement reach its ESO?

Paper 004's loop: the relative position r_12 of the inner mass is measured on three axes; each
axis sends its measurement to its own extended state observer (eq. 3) only at its own events
(eqs. 4-6), and the output feedback (eqs. 15-16) acts on the estimates. The agent decides at
every sampling instant, per axis, whether the sensor transmits (``MultiBinary(3)``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from etsc_envs.core.keywords import document_keywords
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.validation import apply_overrides
from etsc_envs.core.vector_env import EventTriggeredVectorEnv
from etsc_envs.inner_formation.closed_loop import (
    CONTROL,
    CONTROL_NORM_SUM,
    DISTURBANCE_PHASE,
    EXTREMES,
    FEATURES,
    KERNELS,
    LOOP,
    NON_FINITE,
    RETRANSMIT_ERROR_MIN,
    SAMPLING_ERROR_MAX,
    STATE_WIDTH,
    STEADY_ERROR_MAX,
    STEADY_OFFSET_MAX,
    LoopConstants,
    episode_model,
    offset_norm,
    write_sensor_features,
)
from etsc_envs.inner_formation.controller import ObserverFeedback
from etsc_envs.inner_formation.design import estimation_bounds, zeno_bound_s
from etsc_envs.inner_formation.dynamics import RelativeMotionModel, lumped_term
from etsc_envs.inner_formation.params import InnerFormationParams
from etsc_envs.inner_formation.picture import PICTURE

AXES = ("x", "y", "z")
FEATURE_NAMES = (
    *(f"sampling_error_m_{a}" for a in AXES),
    *(f"position_m_{a}" for a in AXES),
    *(f"position_estimate_m_{a}" for a in AXES),
    *(f"velocity_estimate_mps_{a}" for a in AXES),
    *(f"disturbance_estimate_mps2_{a}" for a in AXES),
)
"""Observation components before ``time_since_transmission_s_0..2`` (one per axis):

* ``sampling_error_m_*`` — r_i(t) - r_i(t_k), what eqs. (4)-(6) compare with Π_i;
* ``position_m_*`` — the measurement r_i(t) at the sensor;
* ``position_estimate_m_*``, ``velocity_estimate_mps_*``, ``disturbance_estimate_mps2_*`` —
  the observer states ζ_i, ψ_i, φ_i of eq. (3).

Bounds: the sampling errors within ±2R and the positions within ±R (R the cavity radius:
leaving the cavity ends the episode); the observer states are unbounded (±``UNBOUNDED``): the
paper bounds their errors only ultimately (eqs. 8-10), and its high-gain transient is not.
"""

STEADY_FRACTION = 0.2
"""The steady-state metrics are maxima over the last 20 % of the horizon."""
RANDOM_POSITION_MAX_M = 0.02
RANDOM_VELOCITY_MAX_MPS = 1e-3
SETTLED_OFFSET_FRACTION = 0.1
"""``settled`` (not in the paper, which claims practical convergence, Theorem 2): over the
steady window ``ss_pos_err_m`` = max ‖r‖ is at most this fraction of the cavity radius
(5 mm by default; the paper scenario stays within 1.4 mm)."""


def steady_start_step(params: InnerFormationParams) -> int:
    """The first step of the steady-state window, the last :data:`STEADY_FRACTION` of the
    horizon's sampling instants."""
    n_steps = round(params.horizon_s / params.sampling_period_s)
    return int(np.floor((1.0 - STEADY_FRACTION) * n_steps))


@document_keywords(InnerFormationParams)
class InnerFormationEnv(EventTriggeredEnv):
    """Inner-formation relative motion with per-axis event-triggered ESOs (paper 004).

    Args:
        params: the paper's model and scenario; keyword overrides of its fields are applied on
            top (for example ``horizon_s=50``, ``initial_position_m=(0.002, 0, 0)``).
        transmission_penalty: λ, reward lost per transmitted axis.
        cost_scale: the per-step cost Σ_i |r_i| + Σ_i |r_i - ζ_i| (m) is divided by this; axis
            i's share is |r_i| + |r_i - ζ_i|.
        randomize: draw the initial offset (uniform direction, norm up to 2 cm), the initial
            velocity (each axis uniform in ±1 mm/s) and the phases of Δa (uniform in [0, 2π))
            at every reset instead of the fixed defaults.

    Action: ``MultiBinary(3)``; bit i transmits r_i(t_k) to axis i's observer.
    """

    kernels = KERNELS
    picture = PICTURE

    def __init__(
        self,
        params: InnerFormationParams | None = None,
        *,
        transmission_penalty: float = 0.05,
        cost_scale: float = 1e-3,
        randomize: bool = False,
        render_mode: str | None = None,
        **overrides: Any,
    ) -> None:
        self.params = apply_overrides(InnerFormationParams, params, overrides, "InnerFormationEnv")
        p = self.params
        self.design = ObserverFeedback(
            gain=np.array(p.observer_gain, dtype=float),
            beta=np.array(p.observer_beta, dtype=float),
            feedback=p.feedback_scale * np.array(p.feedback_gains, dtype=float),
        )
        self.steady_start_step = steady_start_step(p)
        shared_model = RelativeMotionModel(
            orbit_rate=np.array(p.orbit_rate, dtype=float),
            disturbance_amplitude=np.array(p.disturbance_amplitude, dtype=float),
            disturbance_frequency=np.array(p.disturbance_frequency, dtype=float),
            disturbance_phase=np.zeros(3),
        )
        # |r| stays inside the cavity (leaving it ends the episode), so |r - r(t_k)| < 2 R.
        feature_high = np.concatenate(
            [np.full(3, 2.0 * p.cavity_radius_m), np.full(3, p.cavity_radius_m), np.full(9, np.inf)]
        )
        super().__init__(
            feature_names=FEATURE_NAMES,
            feature_low=-feature_high,
            feature_high=feature_high,
            n_channels=3,
            channel_width=1,
            state_width=STATE_WIDTH,
            constants=LoopConstants(
                model=shared_model,
                design=self.design,
                cavity_radius=float(p.cavity_radius_m),
                steady_start_step=self.steady_start_step,
            ),
            sampling_period_s=p.sampling_period_s,
            horizon_s=p.horizon_s,
            transmission_penalty=transmission_penalty,
            cost_scale=cost_scale,
            randomize=randomize,
            failure_cost=p.cavity_radius_m,
            render_mode=render_mode,
        )

    @property
    def model(self) -> RelativeMotionModel:
        """The relative-motion model of the current episode (with its disturbance phases)."""
        return episode_model(self.state, self.constants)

    # ----------------------------------------------------------------- hooks
    def _reset_problem(self, options: dict[str, Any] | None) -> None:
        p = self.params
        rng = self.np_random
        state = self.state
        if self.randomize:
            direction = rng.normal(size=3)
            position = (
                direction / np.linalg.norm(direction) * rng.uniform(0.0, RANDOM_POSITION_MAX_M)
            )
            velocity = rng.uniform(-RANDOM_VELOCITY_MAX_MPS, RANDOM_VELOCITY_MAX_MPS, size=3)
            state[DISTURBANCE_PHASE] = rng.uniform(0.0, 2.0 * np.pi, size=3)
        else:
            position = np.array(p.initial_position_m, dtype=float)
            velocity = np.array(p.initial_velocity_mps, dtype=float)
            state[DISTURBANCE_PHASE] = p.disturbance_phase
        loop = state[LOOP]
        loop[0:3] = position
        loop[3:6] = velocity
        if p.observer_start == "first_measurement":
            loop[6:9] = position
        write_sensor_features(state[FEATURES], loop, position)
        state[RETRANSMIT_ERROR_MIN] = np.inf

    def _failure_message(self, code: int) -> str:
        if code == NON_FINITE:
            return "non-finite state"
        offset = float(offset_norm(self.state))
        radius = self.params.cavity_radius_m
        return f"collision: |r| = {offset:.3g} m > cavity_radius_m = {radius}"

    def _paper_metrics(self) -> dict[str, Any]:
        state = self.state
        steps = max(self.step_index, 1)
        steady = state[STEADY_ERROR_MAX].reshape(3, 3)  # rows: |r - ζ|, |ṙ - ψ|, |h - φ|
        extremes = state[EXTREMES].reshape(3, 3)  # rows: |r_i|, |ṙ_i|, |ḣ_i|
        sampling_error = state[SAMPLING_ERROR_MAX]
        least = state[RETRANSMIT_ERROR_MIN]
        grown = np.where(np.isfinite(least), least, 0.0)
        bounds = estimation_bounds(self.params, sampling_error)
        per_axis_min = [
            float(interval) if np.isfinite(interval) else None
            for interval in self.arrays.interevent_min_s[0]
        ]
        control_sum = state[CONTROL_NORM_SUM]
        return {
            "ss_pos_est_err_m": float(steady[0].max()),
            "ss_vel_est_err_mps": float(steady[1].max()),
            "ss_dist_est_err_mps2": float(steady[2].max()),
            "ss_pos_err_m": float(state[STEADY_OFFSET_MAX]),
            "ss_pos_est_err_m_per_axis": steady[0].tolist(),
            "ss_vel_est_err_mps_per_axis": steady[1].tolist(),
            "ss_dist_est_err_mps2_per_axis": steady[2].tolist(),
            "transmissions_per_axis": self.transmissions.tolist(),
            "min_interevent_s_per_axis": per_axis_min,
            "zeno_bound_s_per_axis": zeno_bound_s(
                grown, np.maximum(extremes[0], 1e-300), np.maximum(extremes[1], 1e-300)
            ).tolist(),
            "max_sampling_error_m_per_axis": sampling_error.tolist(),
            "bound_pos_est_m_per_axis": bounds["position_m"].tolist(),
            "bound_vel_est_mps_per_axis": bounds["velocity_mps"].tolist(),
            "bound_dist_est_mps2_per_axis": bounds["disturbance_mps2"].tolist(),
            "max_lumped_rate_mps3_per_axis": extremes[2].tolist(),
            "mean_control_accel_mps2": float(control_sum / steps),
            "mean_thrust_n": float(self.params.mass_outer_kg * control_sum / steps),
        }

    def _settled_at_end(self, metrics: dict[str, Any]) -> bool:
        """The steady-window offset within :data:`SETTLED_OFFSET_FRACTION` of the cavity."""
        return metrics["ss_pos_err_m"] <= SETTLED_OFFSET_FRACTION * self.params.cavity_radius_m

    # ----------------------------------------------------------------- diagnostics
    def state_dict(self) -> dict[str, np.ndarray]:
        """Named copies of the loop's signals at the current instant (for plots and tests)."""
        t = self.time_s
        loop = self.state[LOOP]
        return {
            "time_s": np.array(t),
            "position": loop[0:3].copy(),
            "velocity": loop[3:6].copy(),
            "position_estimate": loop[6:9].copy(),
            "velocity_estimate": loop[9:12].copy(),
            "disturbance_estimate": loop[12:15].copy(),
            "lumped_disturbance": np.array(lumped_term(t, loop[0:3], loop[3:6], self.model)),
            "held_position": self.held[:, 0].copy(),
            "control": self.state[CONTROL].copy(),
        }


class InnerFormationVectorEnv(EventTriggeredVectorEnv):
    """``num_envs`` :class:`InnerFormationEnv` stepped in one compiled call (the id's
    ``vector_entry_point``)."""

    single_env_class = InnerFormationEnv
