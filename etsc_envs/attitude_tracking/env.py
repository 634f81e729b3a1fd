"""``etsc/AttitudeTracking-v0``: when should the sensor send the measurement to the ET-ESO?

Paper 002's loop (Figure 1): a sensor measures x_1 = z = ω_e + K q_ev; the event-triggered
ESO (eq. 16) runs on the held measurement ξ (eq. 17); the ADRC law (eq. 24) acts on the
estimates. The agent decides at every 1-ms sampling instant whether the sensor transmits.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from etsc_envs.attitude_tracking.closed_loop import (
    ACCUMULATED,
    DISTURBANCE_PHASE,
    FEATURES,
    INERTIA_PHASE,
    KERNELS,
    MEASUREMENT,
    NON_FINITE,
    OBSERVER,
    OMEGA_DIVERGED,
    PLANT,
    RATE_ERROR,
    STATE_WIDTH,
    TORQUE,
    LoopConstants,
    episode_model,
    write_sensor_features,
)
from etsc_envs.attitude_tracking.controller import LoopGains
from etsc_envs.attitude_tracking.dynamics import (
    SINUSOID,
    SQUARE,
    PlantModel,
    total_disturbance,
    tracking_error,
)
from etsc_envs.attitude_tracking.params import AttitudeTrackingParams
from etsc_envs.attitude_tracking.picture import PICTURE
from etsc_envs.core.keywords import document_keywords
from etsc_envs.core.loop_env import EventTriggeredEnv
from etsc_envs.core.rotations import quat_from_rotation_vector
from etsc_envs.core.validation import apply_overrides
from etsc_envs.core.vector_env import EventTriggeredVectorEnv

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

Bounds: ``trigger_statistic`` >= 0; the others are unbounded (±``UNBOUNDED``): the paper bounds
e_1, σ and x̂_2 only ultimately (Theorem 1, constants not stated), and z until the divergence
bound ends the episode, when the last observation may exceed it.
"""

RANDOM_ATTITUDE_MAX_ANGLE_RAD = np.deg2rad(60.0)
RANDOM_RATE_MAX_RAD_S = 0.05
SETTLED_MEASUREMENT_RAD_S = 0.03
"""``settled`` (not in the paper): at the horizon ‖z‖ = ‖ω_e + K q_ev‖ (eq. 8), the variable
Remark 2 says converges to a small range around zero, is at most this. The paper scenario
ends at 0.005 rad/s with every sample transmitted; the band is six times that."""


@document_keywords(AttitudeTrackingParams)
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

    kernels = KERNELS
    picture = PICTURE

    def __init__(
        self,
        params: AttitudeTrackingParams | None = None,
        *,
        transmission_penalty: float = 0.1,
        cost_scale: float = 0.01,
        randomize: bool = False,
        render_mode: str | None = None,
        **overrides: Any,
    ) -> None:
        self.params = apply_overrides(
            AttitudeTrackingParams, params, overrides, "AttitudeTrackingEnv"
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
        scale = 1.0 if p.uncertainties else 0.0
        sinusoid = p.reference == "sinusoid"
        shared_model = PlantModel(
            nominal_inertia=np.array(p.nominal_inertia, dtype=float),
            inertia_amplitude=scale * np.array(p.inertia_variation_amplitude, dtype=float),
            inertia_frequency=np.array(p.inertia_variation_frequency, dtype=float),
            inertia_phase=np.zeros(3),
            disturbance_amplitude=scale * np.array(p.disturbance_amplitude, dtype=float),
            disturbance_frequency=np.array(p.disturbance_frequency, dtype=float),
            disturbance_phase=np.zeros(3),
            reference_kind=SINUSOID if sinusoid else SQUARE,
            reference_amplitude=(
                np.full(3, p.sinusoid_amplitude)
                if sinusoid
                else np.array(p.square_levels, dtype=float)
            ),
            reference_frequency=np.array(p.sinusoid_frequency, dtype=float),
            reference_switch_period=float(p.square_switch_period_s),
        )
        low = np.full(len(FEATURE_NAMES), -np.inf)
        low[-1] = 0.0
        super().__init__(
            feature_names=FEATURE_NAMES,
            feature_low=low,
            feature_high=np.full(len(FEATURE_NAMES), np.inf),
            n_channels=1,
            channel_width=3,
            state_width=STATE_WIDTH,
            constants=LoopConstants(
                model=shared_model, gains=self.gains, max_rate=float(p.max_rate_rad_s)
            ),
            sampling_period_s=p.sampling_period_s,
            horizon_s=p.horizon_s,
            transmission_penalty=transmission_penalty,
            cost_scale=cost_scale,
            randomize=randomize,
            failure_cost=p.max_rate_rad_s,
            render_mode=render_mode,
        )

    @property
    def model(self) -> PlantModel:
        """The plant model of the current episode (with its disturbance phases)."""
        return episode_model(self.state, self.constants)

    # ----------------------------------------------------------------- hooks
    def _reset_problem(self, options: dict[str, Any] | None) -> None:
        p = self.params
        rng = self.np_random
        state = self.state
        if self.randomize:
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
            angle = rng.uniform(0.0, RANDOM_ATTITUDE_MAX_ANGLE_RAD)
            attitude = quat_from_rotation_vector(angle * axis)
            rate = rng.uniform(-RANDOM_RATE_MAX_RAD_S, RANDOM_RATE_MAX_RAD_S, size=3)
            state[INERTIA_PHASE] = rng.uniform(0.0, 2.0 * np.pi, size=3)
            state[DISTURBANCE_PHASE] = rng.uniform(0.0, 2.0 * np.pi, size=3)
        else:
            attitude = np.array(p.initial_attitude) / np.linalg.norm(p.initial_attitude)
            rate = np.array(p.initial_rate, dtype=float)
        desired = np.array(p.initial_desired_attitude) / np.linalg.norm(p.initial_desired_attitude)
        state[PLANT] = np.concatenate([attitude, rate, desired])
        _, state[RATE_ERROR], state[MEASUREMENT], _, _ = tracking_error(
            0.0, state[PLANT], self.gains.attitude_gain, self.model
        )
        if p.observer_start == "first_measurement":
            state[OBSERVER][0:3] = state[MEASUREMENT]
        write_sensor_features(
            state[FEATURES], state[MEASUREMENT], state[OBSERVER], state[MEASUREMENT], self.gains
        )

    def _failure_message(self, code: int) -> str:
        if code == NON_FINITE:
            return "non-finite state"
        name, rate = (
            ("omega", self.state[4:7])
            if code == OMEGA_DIVERGED
            else (
                "omega_e",
                self.state[RATE_ERROR],
            )
        )
        limit = self.params.max_rate_rad_s
        norm = float(np.sqrt(rate @ rate))
        return f"diverged: |{name}| = {norm:.3g} rad/s > max_rate_rad_s = {limit}"

    def _paper_metrics(self) -> dict[str, Any]:
        steps = max(self.step_index, 1)
        rate_sum, attitude_sum, energy, input_norm_sum = self.state[ACCUMULATED]
        transmissions = int(self.transmissions.sum())
        return {
            "E_v": float(rate_sum) / steps,
            "E_q": float(attitude_sum) / steps,
            "T_A_ms": 1000.0 * self.time_s / transmissions if transmissions else None,
            "E_c": float(energy),
            "mean_input_norm": float(input_norm_sum) / steps,  # time mean of Σ|u_i|, N·m
        }

    def _settled_at_end(self, metrics: dict[str, Any]) -> bool:
        """‖z‖ within :data:`SETTLED_MEASUREMENT_RAD_S` at the horizon."""
        return float(np.linalg.norm(self.state[MEASUREMENT])) <= SETTLED_MEASUREMENT_RAD_S

    # ----------------------------------------------------------------- diagnostics
    def state_dict(self) -> dict[str, np.ndarray]:
        """Named copies of the loop's signals at the current instant (for plots and tests)."""
        t = self.time_s
        state = self.state
        model = self.model
        plant = state[PLANT]
        q_e, omega_e, z, _, omega_d = tracking_error(t, plant, self.gains.attitude_gain, model)
        torque = state[TORQUE].copy()
        return {
            "time_s": np.array(t),
            "q": plant[0:4].copy(),
            "omega": plant[4:7].copy(),
            "q_d": plant[7:11].copy(),
            "omega_d": np.array(omega_d),
            "q_e": np.array(q_e),
            "omega_e": np.array(omega_e),
            "x1": np.array(z),
            "x1_hat": state[OBSERVER][0:3].copy(),
            "x2": total_disturbance(t, plant, torque, self.gains.attitude_gain, model),
            "x2_hat": state[OBSERVER][3:6].copy(),
            "xi": self.held[0].copy(),
            "u": torque,
        }


class AttitudeTrackingVectorEnv(EventTriggeredVectorEnv):
    """``num_envs`` :class:`AttitudeTrackingEnv` stepped in one compiled call (the id's
    ``vector_entry_point``)."""

    single_env_class = AttitudeTrackingEnv
