"""The numbers of paper 004 (Hao & Zhang, Appl Sci 14 (2024) 3656, section 4)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from etsc_envs.core.validation import (
    require_choice,
    require_field_types,
    require_positive,
    require_vector,
)

OBSERVER_STARTS = ("first_measurement", "zero")


@dataclass(frozen=True)
class InnerFormationParams:
    """Plant, observer, feedback and scenario of paper 004; defaults are the paper's values.

    The paper leaves the initial state, the sampling period, the horizon and the thresholds
    Π_i unstated; the defaults chosen here are explained in docs/fidelity.md. Every field can be
    overridden as a keyword argument of the environment.
    """

    orbit_rate: tuple = (2e-3, 5e-3, 3e-3)
    """n, angular velocity of the outer spacecraft SC1 (section 4), rad/s; constant (ṅ = 0)."""
    mass_outer_kg: float = 250.0
    """m_out = m_1 (section 4); converts the control acceleration u into SC1's thrust force."""
    mass_inner_kg: float = 1.5
    """m_in = m_2 (section 4); Δa already is f_2/m_2 - f_1/m_1, so eq. (1) needs no mass."""
    disturbance_amplitude: tuple = (0.001, -0.003, 0.002)
    """Δa_i = a_i sin(w_i t + p_i) (section 4): the a_i, m/s²."""
    disturbance_frequency: tuple = (2.0, 1.0, 4.0)
    """The w_i of Δa, rad/s."""
    disturbance_phase: tuple = (math.pi / 4.0, math.pi / 8.0, math.pi / 3.0)
    """The p_i of Δa, rad."""
    observer_gain: tuple = (6.0, 6.0, 6.0)
    """High-gain parameters ℓ_i of eq. (3) (section 4: ℓ_1 = ℓ_2 = ℓ_3 = 6)."""
    observer_beta: tuple = (1.2252, 2.2267, 0.7633)
    """K_i(β) = [β_i1, β_i2, β_i3] of eq. (3), the same on every axis (section 4)."""
    feedback_gains: tuple = ((5.2, 5.0, -2.0), (2.5, 3.5, 0.0), (6.0, 5.0, -2.0))
    """Rows g_i of û_i = -(1/50) g_i · [ζ_i, ψ_i, φ_i] (eq. 15, section 4)."""
    feedback_scale: float = 1.0 / 50.0
    """The common factor 1/50 of the section-4 feedback rows."""
    initial_position_m: tuple = (0.01, -0.01, 0.01)
    """r_12(0), m; not stated by the paper (docs/fidelity.md)."""
    initial_velocity_mps: tuple = (0.0, 0.0, 0.0)
    """ṙ_12(0), m/s; not stated by the paper."""
    observer_start: str = "first_measurement"
    """Observer state at t_0, not stated by the paper: 'first_measurement' starts ζ at the
    sample r(t_0) sent at t_0 (section 3.1: "the first sampling happens at the initial time")
    and ψ, φ at 0; 'zero' starts all three at 0 (docs/fidelity.md)."""
    sampling_period_s: float = 0.001
    """Period at which the sensor checks eqs. (4)-(6) and may transmit; not stated."""
    horizon_s: float = 200.0
    """Simulation length; not stated by the paper (docs/fidelity.md)."""
    lyapunov_sigma: float = 0.5
    """σ ∈ (0, 1) of condition (7) and (A6), used to size the thresholds and θ."""
    disturbance_rate_margin: float = 0.05
    """M_i = (1 + margin) |a_i| w_i bounds |ḣ_i| (Assumption 1): the margin covers the
    Coriolis and centripetal terms of h_i, which add less than 1 % here."""
    cavity_radius_m: float = 0.05
    """Failure bound on ‖r_12‖: the inner mass touching its cavity's wall ends the episode."""

    def __post_init__(self) -> None:
        require_field_types(self)
        for name in (
            "orbit_rate",
            "disturbance_amplitude",
            "disturbance_phase",
            "initial_position_m",
            "initial_velocity_mps",
            "observer_beta",
        ):
            require_vector(name, getattr(self, name), 3)
        require_vector("disturbance_frequency", self.disturbance_frequency, 3, positive=True)
        require_choice("observer_start", self.observer_start, OBSERVER_STARTS)
        require_vector("observer_gain", self.observer_gain, 3, positive=True)
        gains = np.asarray(self.feedback_gains, dtype=float)
        if gains.shape != (3, 3) or not np.all(np.isfinite(gains)):
            raise ValueError(f"feedback_gains must be three rows of 3 numbers, got {gains.shape}")
        for name in (
            "mass_outer_kg",
            "mass_inner_kg",
            "feedback_scale",
            "sampling_period_s",
            "horizon_s",
            "cavity_radius_m",
        ):
            require_positive(name, getattr(self, name))
        if not 0.0 < self.lyapunov_sigma < 1.0:
            raise ValueError(f"lyapunov_sigma must be in (0, 1), got {self.lyapunov_sigma}")
        if not self.disturbance_rate_margin >= 0.0:
            raise ValueError(
                f"disturbance_rate_margin must be >= 0, got {self.disturbance_rate_margin}"
            )
        b1, b2, b3 = self.observer_beta
        if not (b1 > 0.0 and b3 > 0.0 and b1 * b2 > b3):
            raise ValueError(
                "observer_beta must make s^3 + b1 s^2 + b2 s + b3 Hurwitz (eq. A4: b1, b3 > 0 "
                f"and b1 b2 > b3), got {self.observer_beta}"
            )
        if np.linalg.norm(self.initial_position_m) >= self.cavity_radius_m:
            raise ValueError(
                f"initial_position_m must lie inside cavity_radius_m = {self.cavity_radius_m} m"
            )
