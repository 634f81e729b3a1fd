"""``etsc/AttitudeTracking-v0``: when should the sensor send the measurement to the ET-ESO?

Paper 002's loop (Figure 1): a sensor measures x_1 = z = ω_e + K q_ev; the event-triggered
ESO (eq. 16) runs on the held measurement ξ (eq. 17); the ADRC law (eq. 24) acts on the
estimates. The agent decides at every 1-ms sampling instant whether the sensor transmits.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from etsc_envs.attitude_tracking.closed_loop import closed_loop_step, sensor_features
from etsc_envs.attitude_tracking.controller import LoopGains
from etsc_envs.attitude_tracking.dynamics import (
    SINUSOID,
    SQUARE,
    PlantModel,
    desired_rate,
    total_disturbance,
    tracking_error,
)
from etsc_envs.attitude_tracking.params import AttitudeTrackingParams
from etsc_envs.core.loop import EventTriggeredEnv
from etsc_envs.core.rotations import quat_from_rotation_vector
from etsc_envs.core.validation import apply_overrides

FEATURE_NAMES = (
    "e1_x", "e1_y", "e1_z",
    "sigma_x", "sigma_y", "sigma_z",
    "z_x", "z_y", "z_z",
    "x2_hat_x", "x2_hat_y", "x2_hat_z",
    "trigger_statistic",
)  # fmt: skip
"""Observation components before ``time_since_transmission_s``:

* ``e1_*`` — e_1 = (x_1 - x̂_1)/ε, normalised observation error (eq. 25);
* ``sigma_*`` — σ = (x_1(t_k) - x_1(t))/ε, normalised sampling error (section 2);
* ``z_*`` — the measurement x_1 = z = ω_e + K q_ev itself (rad/s);
* ``x2_hat_*`` — the ESO's estimate of the total disturbance x_2 (rad/s²);
* ``trigger_statistic`` — Σ_i Σ_j |α_ji(e_1i, σ_i)| / ε_min, what eq. (27) compares with Ψ.
"""

RANDOM_ATTITUDE_MAX_ANGLE_RAD = np.deg2rad(60.0)
RANDOM_RATE_MAX_RAD_S = 0.05


class AttitudeTrackingEnv(EventTriggeredEnv):
    """Quaternion attitude tracking with an event-triggered ESO (paper 002).

    Args:
        params: the paper's model and scenario; keyword overrides of its fields (for example
            ``reference="square"``, ``uncertainties=False``, ``horizon_s=30``) are applied on top.
        transmission_penalty: λ, reward lost per transmission.
        cost_scale: the per-step cost (integrands of E_v and E_q, eq. 50) is divided by this.
            A diverging episode is charged a cost of ``max_rate_rad_s`` (the rate error at the
            divergence bound) for every step it cuts from the horizon.
        randomize: draw the initial attitude (uniform axis, angle up to 60°), the initial rate
            (each axis uniform in ±0.05 rad/s) and the phases of ΔJ(t) and d(t) (uniform in
            [0, 2π)) at every reset instead of the paper's fixed values.

    Action: ``Discrete(2)``, 1 transmits x_1(t_k) to the observer. Observation: the components
    named in :data:`FEATURE_NAMES` followed by ``time_since_transmission_s``.
    """

    def __init__(
        self,
        params: AttitudeTrackingParams | None = None,
        *,
        transmission_penalty: float = 0.1,
        cost_scale: float = 0.01,
        randomize: bool = False,
        **overrides: Any,
    ) -> None:
        self.params = apply_overrides(
            params if params is not None else AttitudeTrackingParams(),
            overrides,
            "AttitudeTrackingEnv",
        )
        self.randomize = bool(randomize)
        low = np.full(len(FEATURE_NAMES), -np.inf)
        low[-1] = 0.0
        super().__init__(
            feature_names=FEATURE_NAMES,
            feature_low=low,
            feature_high=np.full(len(FEATURE_NAMES), np.inf),
            n_channels=1,
            channel_width=3,
            sampling_period_s=self.params.sampling_period_s,
            horizon_s=self.params.horizon_s,
            transmission_penalty=transmission_penalty,
            cost_scale=cost_scale,
            failure_cost=self.params.max_rate_rad_s,
        )
        p = self.params
        self.gains = LoopGains(
            attitude_gain=np.array(p.attitude_gain, dtype=float),
            control_gain=np.array(p.control_gain, dtype=float),
            epsilon=np.array(p.observer_epsilon, dtype=float),
            b=float(p.observer_b),
            c=float(p.observer_c),
            nominal_inertia=np.array(p.nominal_inertia, dtype=float),
        )
        self.plant_state = np.zeros(11)
        self.observer_state = np.zeros(6)
        self.measurement = np.zeros(3)
        self.rate_error_vector = np.zeros(3)
        self.torque = np.zeros(3)
        self._features_now = np.zeros(len(FEATURE_NAMES))
        self._accumulated = np.zeros(4)

    # ----------------------------------------------------------------- hooks
    def _reset_problem(self, options: dict[str, Any] | None) -> None:
        p = self.params
        rng = self.np_random
        if self.randomize:
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
            angle = rng.uniform(0.0, RANDOM_ATTITUDE_MAX_ANGLE_RAD)
            attitude = quat_from_rotation_vector(angle * axis)
            rate = rng.uniform(-RANDOM_RATE_MAX_RAD_S, RANDOM_RATE_MAX_RAD_S, size=3)
            inertia_phase = rng.uniform(0.0, 2.0 * np.pi, size=3)
            disturbance_phase = rng.uniform(0.0, 2.0 * np.pi, size=3)
        else:
            attitude = np.array(p.initial_attitude) / np.linalg.norm(p.initial_attitude)
            rate = np.array(p.initial_rate, dtype=float)
            inertia_phase = np.zeros(3)
            disturbance_phase = np.zeros(3)
        scale = 1.0 if p.uncertainties else 0.0
        sinusoid = p.reference == "sinusoid"
        self.model = PlantModel(
            nominal_inertia=np.array(p.nominal_inertia, dtype=float),
            inertia_amplitude=scale * np.array(p.inertia_variation_amplitude, dtype=float),
            inertia_frequency=np.array(p.inertia_variation_frequency, dtype=float),
            inertia_phase=inertia_phase,
            disturbance_amplitude=scale * np.array(p.disturbance_amplitude, dtype=float),
            disturbance_frequency=np.array(p.disturbance_frequency, dtype=float),
            disturbance_phase=disturbance_phase,
            reference_kind=SINUSOID if sinusoid else SQUARE,
            reference_amplitude=(
                np.full(3, p.sinusoid_amplitude)
                if sinusoid
                else np.array(p.square_levels, dtype=float)
            ),
            reference_frequency=np.array(p.sinusoid_frequency, dtype=float),
            reference_switch_period=float(p.square_switch_period_s),
        )
        desired = np.array(p.initial_desired_attitude) / np.linalg.norm(p.initial_desired_attitude)
        self.plant_state = np.concatenate([attitude, rate, desired])
        self.torque = np.zeros(3)
        _, self.rate_error_vector, self.measurement, _ = tracking_error(
            0.0, self.plant_state, self.gains.attitude_gain, self.model
        )
        self.observer_state = np.zeros(6)
        if p.observer_start == "first_measurement":
            self.observer_state[0:3] = self.measurement
        self._features_now = sensor_features(
            self.measurement, self.observer_state, self.measurement, self.gains
        )
        # Running sums of eq. (50)-(52) terms: rate error, attitude error, energy, ‖u‖₁ (Table 2).
        self._accumulated = np.zeros(4)

    def _channel_values(self) -> np.ndarray:
        return self.measurement

    def _advance(self) -> float:
        (
            self.plant_state,
            self.observer_state,
            self.torque,
            self.measurement,
            self.rate_error_vector,
            self._features_now,
            rate_error,
            attitude_error,
            energy_increment,
        ) = closed_loop_step(
            self.time_s,
            self.sampling_period_s,
            self.plant_state,
            self.observer_state,
            self.channel.held[0],
            self.model,
            self.gains,
        )
        self._accumulated += (
            rate_error,
            attitude_error,
            energy_increment,
            np.abs(self.torque).sum(),
        )
        return rate_error + attitude_error

    def _failure(self) -> str | None:
        if not np.isfinite(self.plant_state.sum() + self._features_now.sum()):
            return "non-finite state"
        limit = self.params.max_rate_rad_s
        for name, rate in (("omega", self.plant_state[4:7]), ("omega_e", self.rate_error_vector)):
            norm = float(np.sqrt(rate @ rate))
            if norm > limit:
                return f"diverged: |{name}| = {norm:.3g} rad/s > max_rate_rad_s = {limit}"
        return None

    def _features(self) -> np.ndarray:
        return self._features_now

    def _paper_metrics(self) -> dict[str, Any]:
        steps = max(self.step_index, 1)
        rate_sum, attitude_sum, energy, input_norm_sum = self._accumulated
        transmissions = int(self.channel.transmissions.sum())
        return {
            "E_v": rate_sum / steps,
            "E_q": attitude_sum / steps,
            "T_A_ms": 1000.0 * self.time_s / transmissions if transmissions else None,
            "E_c": float(energy),
            "mean_input_norm": input_norm_sum / steps,  # time mean of Σ|u_i|, N·m
        }

    # ----------------------------------------------------------------- diagnostics
    def state_dict(self) -> dict[str, np.ndarray]:
        """Named copies of the loop's signals at the current instant (for plots and tests)."""
        t = self.time_s
        q_e, omega_e, z, _ = tracking_error(
            t, self.plant_state, self.gains.attitude_gain, self.model
        )
        return {
            "time_s": np.array(t),
            "q": self.plant_state[0:4].copy(),
            "omega": self.plant_state[4:7].copy(),
            "q_d": self.plant_state[7:11].copy(),
            "omega_d": desired_rate(t, self.model),
            "q_e": q_e,
            "omega_e": omega_e,
            "x1": z,
            "x1_hat": self.observer_state[0:3].copy(),
            "x2": total_disturbance(
                t, self.plant_state, self.torque, self.gains.attitude_gain, self.model
            ),
            "x2_hat": self.observer_state[3:6].copy(),
            "xi": self.channel.held[0].copy(),
            "u": self.torque.copy(),
        }
