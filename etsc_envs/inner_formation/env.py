"""``etsc/InnerFormation-v0``: when should each axis's position measurement reach its ESO?

Paper 004's loop: the relative position r_12 of the inner mass is measured on three axes; each
axis sends its measurement to its own extended state observer (eq. 3) only at its own events
(eqs. 4-6), and the output feedback (eqs. 15-16) acts on the estimates. The agent decides at
every sampling instant, per axis, whether the sensor transmits (``MultiBinary(3)``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from etsc_envs.core.loop import EventTriggeredEnv
from etsc_envs.core.validation import apply_overrides
from etsc_envs.inner_formation.closed_loop import closed_loop_step, sensor_features
from etsc_envs.inner_formation.controller import ObserverFeedback
from etsc_envs.inner_formation.design import estimation_bounds, zeno_bound_s
from etsc_envs.inner_formation.dynamics import RelativeMotionModel, lumped_term
from etsc_envs.inner_formation.params import InnerFormationParams

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
"""

STEADY_FRACTION = 0.2
"""The steady-state metrics are maxima over the last 20 % of the horizon."""
RANDOM_POSITION_MAX_M = 0.02
RANDOM_VELOCITY_MAX_MPS = 1e-3


class InnerFormationEnv(EventTriggeredEnv):
    """Inner-formation relative motion with per-axis event-triggered ESOs (paper 004).

    Args:
        params: the paper's model and scenario; keyword overrides of its fields are applied on
            top (for example ``horizon_s=50``, ``initial_position_m=(0.002, 0, 0)``).
        transmission_penalty: λ, reward lost per transmitted axis.
        cost_scale: the per-step cost Σ_i |r_i| + Σ_i |r_i - ζ_i| (m) is divided by this.
        randomize: draw the initial offset (uniform direction, norm up to 2 cm), the initial
            velocity (each axis uniform in ±1 mm/s) and the phases of Δa (uniform in [0, 2π))
            at every reset instead of the fixed defaults.

    Action: ``MultiBinary(3)``; bit i transmits r_i(t_k) to axis i's observer.
    """

    def __init__(
        self,
        params: InnerFormationParams | None = None,
        *,
        transmission_penalty: float = 0.05,
        cost_scale: float = 1e-3,
        randomize: bool = False,
        **overrides: Any,
    ) -> None:
        self.params = apply_overrides(
            params if params is not None else InnerFormationParams(), overrides, "InnerFormationEnv"
        )
        self.randomize = bool(randomize)
        p = self.params
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
            sampling_period_s=p.sampling_period_s,
            horizon_s=p.horizon_s,
            transmission_penalty=transmission_penalty,
            cost_scale=cost_scale,
            failure_cost=p.cavity_radius_m,
        )
        self.design = ObserverFeedback(
            gain=np.array(p.observer_gain, dtype=float),
            beta=np.array(p.observer_beta, dtype=float),
            feedback=p.feedback_scale * np.array(p.feedback_gains, dtype=float),
        )
        self.steady_start_step = int(np.floor((1.0 - STEADY_FRACTION) * self.n_steps))
        self.state = np.zeros(15)
        self.control = np.zeros(3)
        self._features_now = np.zeros(len(FEATURE_NAMES))

    # ----------------------------------------------------------------- hooks
    def _reset_problem(self, options: dict[str, Any] | None) -> None:
        p = self.params
        rng = self.np_random
        if self.randomize:
            direction = rng.normal(size=3)
            position = (
                direction / np.linalg.norm(direction) * rng.uniform(0.0, RANDOM_POSITION_MAX_M)
            )
            velocity = rng.uniform(-RANDOM_VELOCITY_MAX_MPS, RANDOM_VELOCITY_MAX_MPS, size=3)
            phase = rng.uniform(0.0, 2.0 * np.pi, size=3)
        else:
            position = np.array(p.initial_position_m, dtype=float)
            velocity = np.array(p.initial_velocity_mps, dtype=float)
            phase = np.array(p.disturbance_phase, dtype=float)
        self.model = RelativeMotionModel(
            orbit_rate=np.array(p.orbit_rate, dtype=float),
            disturbance_amplitude=np.array(p.disturbance_amplitude, dtype=float),
            disturbance_frequency=np.array(p.disturbance_frequency, dtype=float),
            disturbance_phase=phase,
        )
        estimate = np.zeros(9)
        if p.observer_start == "first_measurement":
            estimate[0:3] = position
        self.state = np.concatenate([position, velocity, estimate])
        self.control = np.zeros(3)
        self._features_now = sensor_features(self.state, position)
        self._counts_before = np.zeros(3, dtype=np.int64)
        self._steady_max = np.zeros((3, 3))  # rows: |r - ζ|, |ṙ - ψ|, |h - φ|; columns: axes
        self._steady_max_offset = 0.0  # ‖r‖
        self._max_abs = np.zeros((3, 3))  # rows: |r_i|, |ṙ_i|, |ḣ_i|
        self._max_sampling_error = np.zeros(3)
        self._min_grown_error = np.full(3, np.inf)
        self._accumulated = np.zeros(2)  # Σ ‖u‖ (m/s²), Σ cost

    def _channel_values(self) -> np.ndarray:
        return self.state[0:3]

    def _advance(self) -> float:
        counts = self.channel.transmissions
        sent_again = (counts > self._counts_before) & (self._counts_before > 0)
        grown = np.abs(self._features_now[0:3])
        self._min_grown_error = np.where(
            sent_again, np.minimum(self._min_grown_error, grown), self._min_grown_error
        )
        self._counts_before = counts.copy()
        held = self.channel.held[:, 0]
        (
            self.state,
            self._features_now,
            position_error,
            velocity_error,
            disturbance_error,
            lumped_rate,
            self.control,
        ) = closed_loop_step(
            self.time_s, self.sampling_period_s, self.state, held, self.model, self.design
        )
        sampling_error = np.abs(self._features_now[0:3])
        np.maximum(self._max_sampling_error, sampling_error, out=self._max_sampling_error)
        np.maximum(self._max_abs[0], np.abs(self.state[0:3]), out=self._max_abs[0])
        np.maximum(self._max_abs[1], np.abs(self.state[3:6]), out=self._max_abs[1])
        np.maximum(self._max_abs[2], np.abs(lumped_rate), out=self._max_abs[2])
        if self.step_index + 1 > self.steady_start_step:
            position = self.state[0:3]
            errors = (position_error, velocity_error, disturbance_error)
            np.maximum(self._steady_max, errors, out=self._steady_max)
            self._steady_max_offset = max(self._steady_max_offset, np.sqrt(position @ position))
        cost = np.abs(self.state[0:3]).sum() + position_error.sum()
        self._accumulated += (np.sqrt(self.control @ self.control), cost)
        return float(cost)

    def _failure(self) -> str | None:
        if not np.isfinite(self.state.sum()):
            return "non-finite state"
        offset = float(np.sqrt(self.state[0:3] @ self.state[0:3]))
        if offset > self.params.cavity_radius_m:
            return (
                f"collision: |r| = {offset:.3g} m > cavity_radius_m = {self.params.cavity_radius_m}"
            )
        return None

    def _features(self) -> np.ndarray:
        return self._features_now

    def _paper_metrics(self) -> dict[str, Any]:
        steps = max(self.step_index, 1)
        grown = np.where(np.isfinite(self._min_grown_error), self._min_grown_error, 0.0)
        bounds = estimation_bounds(self.params, self._max_sampling_error)
        per_axis_min = [
            min(intervals) if intervals else None for intervals in self.channel.interevent_s
        ]
        return {
            "ss_pos_est_err_m": float(self._steady_max[0].max()),
            "ss_vel_est_err_mps": float(self._steady_max[1].max()),
            "ss_dist_est_err_mps2": float(self._steady_max[2].max()),
            "ss_pos_err_m": float(self._steady_max_offset),
            "ss_pos_est_err_m_per_axis": self._steady_max[0].tolist(),
            "ss_vel_est_err_mps_per_axis": self._steady_max[1].tolist(),
            "ss_dist_est_err_mps2_per_axis": self._steady_max[2].tolist(),
            "transmissions_per_axis": self.channel.transmissions.tolist(),
            "min_interevent_s_per_axis": per_axis_min,
            "zeno_bound_s_per_axis": zeno_bound_s(
                grown, np.maximum(self._max_abs[0], 1e-300), np.maximum(self._max_abs[1], 1e-300)
            ).tolist(),
            "max_sampling_error_m_per_axis": self._max_sampling_error.tolist(),
            "bound_pos_est_m_per_axis": bounds["position_m"].tolist(),
            "bound_vel_est_mps_per_axis": bounds["velocity_mps"].tolist(),
            "bound_dist_est_mps2_per_axis": bounds["disturbance_mps2"].tolist(),
            "max_lumped_rate_mps3_per_axis": self._max_abs[2].tolist(),
            "mean_control_accel_mps2": float(self._accumulated[0] / steps),
            "mean_thrust_n": float(self.params.mass_outer_kg * self._accumulated[0] / steps),
        }

    # ----------------------------------------------------------------- diagnostics
    def state_dict(self) -> dict[str, np.ndarray]:
        """Named copies of the loop's signals at the current instant (for plots and tests)."""
        t = self.time_s
        return {
            "time_s": np.array(t),
            "position": self.state[0:3].copy(),
            "velocity": self.state[3:6].copy(),
            "position_estimate": self.state[6:9].copy(),
            "velocity_estimate": self.state[9:12].copy(),
            "disturbance_estimate": self.state[12:15].copy(),
            "lumped_disturbance": lumped_term(t, self.state[0:3], self.state[3:6], self.model),
            "held_position": self.channel.held[:, 0].copy(),
            "control": self.control.copy(),
        }
