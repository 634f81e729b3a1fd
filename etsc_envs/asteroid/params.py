"""The numbers of paper 003 (barrier-based event-triggered orbit keeping near 25143 Itokawa)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from etsc_envs.core.validation import (
    require_field_types,
    require_non_negative,
    require_positive,
    require_vector,
)

ASTRONOMICAL_UNIT_M = 1.495978707e11


@dataclass(frozen=True)
class AsteroidParams:
    """Asteroid, spacecraft, controllers and scenario of paper 003; defaults are the paper's.

    Where the paper is silent (the initial point on the orbit, the Sun's direction, the failure
    bounds) the defaults are the choices explained in docs/fidelity.md. Every field can be
    overridden as a keyword argument of the environment.
    """

    asteroid_mass_kg: float = 3.58e10
    """M (sections 2 and 4); the shape's density is M / volume (the paper's ρ = 1950 kg/m³ is
    M / 1.836e7 m³)."""
    spin_period_h: float = 12.132
    """Itokawa's rotation period (section 2): Ω_T = [0, 0, 2π / period] of eq. (1)."""
    spacecraft_mass_kg: float = 600.0
    """m of eq. (1) (section 4)."""
    inertia_kg_m2: tuple = (360.0, 480.0, 480.0)
    """diag(J) of eq. (21)."""
    panel_area_m2: float = 40.0
    """A of eq. (8): the solar panel (section 4)."""
    specular_coefficient: float = 0.1
    """C_s of eq. (8) (section 4)."""
    diffuse_coefficient: float = 0.1
    """C_d of eq. (8) (section 4)."""
    absorption_coefficient: float = 0.4
    """C_a of eq. (8) (section 4)."""
    srp_constant: float = 1e17
    """P_0 of P = P_0 / d_s² (section 2), kg·m/s²."""
    sun_distance_m: float = ASTRONOMICAL_UNIT_M
    """d_s: the asteroid-Sun distance, 1 AU (section 4)."""
    srp_offset_m: float = 0.05
    """L of eq. (10): offset of the SRP force's centre along the body y axis (section 4)."""
    thrust_offset_m: float = 0.0
    """Offset of the thrust's line of action along the body y axis, giving a torque
    [0, L_τ, 0] × τ in eq. (9). The paper's eq. (9) has no thrust torque (0); see
    docs/fidelity.md for what a non-zero offset does to the attitude at the bursts."""
    orbit_perturbations: bool = True
    """False removes the gravity-gradient and SRP forces from eq. (1), leaving the polyhedral
    gravity (their torques on the attitude stay): without thrust the orbit then conserves the
    Jacobi integral."""
    sun_azimuth_deg: float = 0.0
    """Direction of the Sun in the asteroid's equatorial plane at t = 0 (not stated; the Sun
    stays within 2° of Itokawa's equator, whose obliquity is 178°)."""
    reference_radius_m: float = 200.0
    """r_0 = (r_max + r_min) / 2 (sections 3.1 and 4)."""
    shell_half_width_m: float = 5.0
    """r_max - r_0 = r_0 - r_min: the allowed shell is ‖r‖ ∈ [195, 205] m (section 4)."""
    thrust_gain: float = 4.0
    """K_1 of eq. (16), N/m."""
    max_thrust_n: float = 22.0
    """F_M of eq. (17), N."""
    burst_duration_s: float = 50.0
    """How long the thrusters fire after each triggering instant (section 4)."""
    attitude_gain: float = 21.0
    """K_2 of eq. (18)."""
    sliding_gain: float = 0.08
    """k_1 of the sliding vector s = ω + k_1 q_v (section 3.2)."""
    adaptive_rate: float = 143.0
    """c of eq. (19)."""
    adaptive_leakage: float = 2.3e-6
    """c_1 of eq. (19)."""
    adaptive_initial: float = 0.0
    """b̂(0) of eq. (19) (not stated; the law only requires b̂(0) >= 0)."""
    tanh_sharpness: float = 22.0
    """ρ of Tanh(ρ s) in eq. (18)."""
    initial_radius_m: float = 200.0
    """‖r(0)‖ = r_0 (section 4)."""
    initial_speed_mps: float | None = None
    """‖v(0)‖ of eq. (20); None means sqrt(G M / r_0)."""
    orbit_plane_azimuth_deg: float = 130.0
    """Azimuth, in the body frame at t = 0, of the initial orbit's plane, which contains the
    spin axis because eq. (20) points v(0) along z. Not stated by the paper (docs/fidelity.md)."""
    initial_orbit_phase_deg: float = 90.0
    """Where on that orbit the spacecraft starts, measured from the equator toward +z: 0 is
    eq. (20) literally (r(0) in the equatorial plane, v(0) = [0, 0, v]); the default 90 starts
    over the north pole on the same orbit, the nearest start whose orbit clears the rotating
    body for the whole horizon (docs/fidelity.md)."""
    initial_attitude_error_deg: tuple = (20.0, -10.0, 0.0)
    """Initial attitude error as roll, pitch, yaw (3-2-1 Euler angles) about the Sun-pointing
    frame (section 4)."""
    initial_rate_rad_s: tuple = (0.0, 0.0, 0.0)
    """ω(0) (section 4)."""
    sampling_period_s: float = 0.25
    """Step of the simulation, at which the trigger is checked (section 4)."""
    horizon_s: float = 12000.0
    """Simulation length (section 4: 12000 s)."""
    operating_region_m: tuple = (170.0, 230.0)
    """Failure bounds on ‖r‖ (not in the paper): leaving this band ends the episode. The
    gravity grid covers it."""
    grid_spacing_m: float = 8.0
    """Node spacing of the gravity grid (docs/fidelity.md gives its interpolation error)."""
    max_rate_rad_s: float = 1.0
    """Failure bound on ‖ω‖: beyond it the attitude loop has diverged."""

    @property
    def spin_rate_rad_s(self) -> float:
        """ω_T of eq. (1)."""
        return 2.0 * math.pi / (self.spin_period_h * 3600.0)

    @property
    def shell_m(self) -> tuple[float, float]:
        """(r_min, r_max), the barriers of section 3.1."""
        return (
            self.reference_radius_m - self.shell_half_width_m,
            self.reference_radius_m + self.shell_half_width_m,
        )

    def __post_init__(self) -> None:
        require_field_types(self)
        require_vector("inertia_kg_m2", self.inertia_kg_m2, 3, positive=True)
        require_vector("initial_attitude_error_deg", self.initial_attitude_error_deg, 3)
        require_vector("initial_rate_rad_s", self.initial_rate_rad_s, 3)
        for name in (
            "asteroid_mass_kg",
            "spin_period_h",
            "spacecraft_mass_kg",
            "panel_area_m2",
            "srp_constant",
            "sun_distance_m",
            "reference_radius_m",
            "shell_half_width_m",
            "thrust_gain",
            "max_thrust_n",
            "burst_duration_s",
            "attitude_gain",
            "sliding_gain",
            "tanh_sharpness",
            "initial_radius_m",
            "sampling_period_s",
            "horizon_s",
            "grid_spacing_m",
            "max_rate_rad_s",
        ):
            require_positive(name, getattr(self, name))
        for name in (
            "specular_coefficient",
            "diffuse_coefficient",
            "absorption_coefficient",
            "srp_offset_m",
            "thrust_offset_m",
            "adaptive_rate",
            "adaptive_leakage",
            "adaptive_initial",
        ):
            require_non_negative(name, getattr(self, name))
        for name in ("sun_azimuth_deg", "orbit_plane_azimuth_deg", "initial_orbit_phase_deg"):
            value = float(getattr(self, name))
            if not np.isfinite(value):
                raise ValueError(f"{name} must be a finite angle in degrees, got {value!r}")
        if not isinstance(self.orbit_perturbations, bool | np.bool_):
            raise ValueError(
                f"orbit_perturbations must be True or False, got {self.orbit_perturbations!r}"
            )
        if self.initial_speed_mps is not None:
            require_positive("initial_speed_mps", self.initial_speed_mps)
        region = require_vector("operating_region_m", self.operating_region_m, 2, positive=True)
        low, high = self.shell_m
        if not region[0] < low < self.reference_radius_m < high < region[1]:
            raise ValueError(
                f"operating_region_m must enclose the shell [{low:g}, {high:g}] m, "
                f"got {tuple(region)}"
            )
        if not region[0] < self.initial_radius_m < region[1]:
            raise ValueError(
                f"initial_radius_m must lie inside operating_region_m {tuple(region)}, "
                f"got {self.initial_radius_m}"
            )
        if self.grid_spacing_m > 0.5 * (region[1] - region[0]):
            raise ValueError(
                "grid_spacing_m must be at most half the width of operating_region_m, "
                f"got {self.grid_spacing_m}"
            )
        bursts = self.burst_duration_s / self.sampling_period_s
        if round(bursts) < 1 or not np.isclose(bursts, round(bursts), rtol=0.0, atol=1e-9):
            raise ValueError(
                f"burst_duration_s must be a whole number (>= 1) of sampling periods of "
                f"{self.sampling_period_s:g} s, got {self.burst_duration_s!r}"
            )
        if self.horizon_s < self.burst_duration_s:
            raise ValueError(
                f"horizon_s must be >= burst_duration_s ({self.burst_duration_s}), "
                f"got {self.horizon_s}"
            )
