"""The numbers of paper 002 (Cai, Zou, Wang, Huang, Shi, Sci China Inf Sci 2019, section 4)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from etsc_envs.core.validation import (
    require_choice,
    require_field_types,
    require_positive,
    require_spd_matrix,
    require_unit_quaternion,
    require_vector,
)

REFERENCES = ("sinusoid", "square")
OBSERVER_STARTS = ("first_measurement", "zero")


@dataclass(frozen=True)
class AttitudeTrackingParams:
    """Model, reference, controller and scenario of paper 002; defaults are the paper's values.

    Every field can be overridden as a keyword argument of the environment.
    """

    nominal_inertia: tuple = ((20.0, 1.2, 0.9), (1.2, 17.0, 1.4), (0.9, 1.4, 15.0))
    """J0 of eq. (49), kg·m²."""
    inertia_variation_amplitude: tuple = (1.0, 2.0, 3.0)
    """ΔJ(t) = diag(a_i sin(w_i t)) (section 4): the a_i, kg·m²."""
    inertia_variation_frequency: tuple = (0.1, 0.2, 0.3)
    """The w_i of ΔJ(t), rad/s."""
    disturbance_amplitude: tuple = (0.1, 0.2, 0.3)
    """d(t) = [a_i sin(w_i t)] (section 4): the a_i, N·m."""
    disturbance_frequency: tuple = (0.1, 0.2, 0.3)
    """The w_i of d(t), rad/s."""
    uncertainties: bool = True
    """False switches ΔJ and d off (the 'without uncertainties' rows of Table 2)."""
    reference: str = "sinusoid"
    """'sinusoid' (eq. 53, section 4.1) or 'square' (eqs. 54-55, section 4.2)."""
    sinusoid_amplitude: float = 0.05
    """Amplitude of ω_d in eq. (53), rad/s."""
    sinusoid_frequency: tuple = (math.pi / 20.0, 2.0 * math.pi / 20.0, 3.0 * math.pi / 20.0)
    """Angular frequencies of the three components of ω_d in eq. (53), rad/s."""
    square_levels: tuple = (0.05, 0.03, 0.02)
    """ω_d on the first half-period of eqs. (54)-(55), rad/s."""
    square_switch_period_s: float = 10.0
    """T of eqs. (54)-(55): ω_d changes sign every T seconds."""
    initial_attitude: tuple = (0.3, -0.2, -0.3, 0.8832)
    """q(0), scalar last (section 4); normalised on construction (its norm is 1.00002)."""
    initial_rate: tuple = (0.0, 0.0, 0.0)
    """ω(0), rad/s."""
    initial_desired_attitude: tuple = (0.0, 0.0, 0.0, 1.0)
    """q_d(0)."""
    attitude_gain: tuple = (2.0, 2.0, 2.0)
    """diag(K) of z = ω_e + K q_ev (eq. (8), section 4.1: K = 2 I)."""
    control_gain: tuple = (4.0, 4.0, 4.0)
    """diag(K̃) of the control law eq. (24) (section 4.1: K̃ = 4 I)."""
    observer_epsilon: tuple = (0.4, 0.4, 0.4)
    """High-gain parameters ε_i of the ET-ESO eq. (16)."""
    observer_b: float = 2.0
    """b of g_1(y) = b y + φ(y) (section 4.1: g_1(y) = 2y + φ(y))."""
    observer_c: float = 1.0
    """c of g_2(y) = c y (section 4.1: g_2(y) = y)."""
    observer_start: str = "first_measurement"
    """x̂(t_0) of eq. (16), not stated by the paper: 'first_measurement' starts x̂_1 at the
    measurement x_1(t_0) sent at t_0 and x̂_2 at 0; 'zero' starts both at 0 (docs/fidelity.md)."""
    sampling_period_s: float = 0.001
    """t_s of section 4: observer and controller run by difference approximation at 1 ms."""
    horizon_s: float = 50.0
    """Simulation length T of eq. (50); not stated by the paper (see docs/fidelity.md)."""
    max_rate_rad_s: float = 10.0
    """Failure bound on ‖ω‖ and ‖ω_e‖: beyond it the episode terminates as diverged."""

    def __post_init__(self) -> None:
        require_field_types(self)
        require_spd_matrix("nominal_inertia", self.nominal_inertia)
        for name in (
            "inertia_variation_amplitude",
            "inertia_variation_frequency",
            "disturbance_amplitude",
            "disturbance_frequency",
            "square_levels",
            "sinusoid_frequency",
            "initial_rate",
        ):
            require_vector(name, getattr(self, name), 3)
        for name in ("attitude_gain", "control_gain", "observer_epsilon"):
            require_vector(name, getattr(self, name), 3, positive=True)
        require_unit_quaternion("initial_attitude", self.initial_attitude)
        require_unit_quaternion("initial_desired_attitude", self.initial_desired_attitude)
        require_choice("reference", self.reference, REFERENCES)
        require_choice("observer_start", self.observer_start, OBSERVER_STARTS)
        for name in (
            "observer_b",
            "observer_c",
            "sinusoid_amplitude",
            "square_switch_period_s",
            "sampling_period_s",
            "horizon_s",
            "max_rate_rad_s",
        ):
            require_positive(name, getattr(self, name))
        if not isinstance(self.uncertainties, bool | np.bool_):
            raise ValueError(f"uncertainties must be True or False, got {self.uncertainties!r}")
        if (1.0 + self.observer_c) / self.observer_b + self.observer_b >= 4.0:
            raise ValueError(
                "observer_b and observer_c must satisfy (1 + c)/b + b < 4 (paper 002, section 2), "
                f"got b={self.observer_b}, c={self.observer_c}"
            )
