"""The numbers of paper 000 (Zhang, Biggs, Ye, Sun, IEEE TAES 2019, doi:10.1109/TAES.2019.2955257).

Sections II and IV of *Extended-state-observer based event-triggered orbit-attitude tracking
for low-thrust spacecraft*. Values the paper does not state (sampling period, horizon, the
leader's node and phase, observer start) are marked as choices; ``docs/fidelity.md`` gives the
reason and the evidence for each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from etsc_envs.core.validation import (
    require_choice,
    require_field_types,
    require_non_negative,
    require_positive,
    require_spd_matrix,
    require_vector,
)

INITIAL_POINTS = {
    # Section IV, Case 1: Φ (deg) and χ (m) of the initial tracking error, with Ṽ = 0.
    "P1": ((76.71, -14.02, 60.05), (3.61, -28.7, -9.82)),
    "P2": ((63.6, -13.2, 51.0), (-3.4, -55.8, 0.1)),
}
OBSERVERS = ("finite_time", "ref19")
"""'finite_time' is the ESO eq. (14); 'ref19' sets k2 = k4 = k5 = 0, the observer of the
paper's ref. [19] used for the comparison of Figs. 3-4."""
OBSERVER_STARTS = ("zero", "first_measurement")
ESO_INPUTS = ("saturated", "commanded")
"""What the ESO's model is fed as the control: 'saturated' = D sat(D† Γ_c), what the nominal
thrusters deliver; 'commanded' = Γ_c itself, with the saturation loss in Δd as eq. (12) books
it (docs/fidelity.md)."""


def _pair(name: str, value, *, positive: bool = True) -> np.ndarray:
    """A (rotational, translational) pair of gains, each > 0 (or >= 0)."""
    array = require_vector(name, value, 2)
    if positive and np.any(array <= 0.0):
        raise ValueError(f"{name} must have both entries > 0, got {value!r}")
    if not positive and np.any(array < 0.0):
        raise ValueError(f"{name} must have both entries >= 0, got {value!r}")
    return array


@dataclass(frozen=True)
class OrbitAttitudeParams:
    """Plant, leader, actuators, disturbances, observer, controller and scenario of paper 000.

    Gains given as pairs are ``(rotational, translational)``, i.e. the two 3×3 blocks of the
    paper's ``diag(x1 I3, x2 I3)`` matrices. Every field can be overridden as a keyword
    argument of the environment.
    """

    # ------------------------------------------------------------------ Earth (section II-A)
    gravitational_parameter: float = 398600.4e9
    """μ, m³/s²."""
    earth_radius_m: float = 6378.14e3
    """r_e, Earth's mean equatorial radius, m."""
    j2: float = 0.00108263
    """J2 of the chaser's gravity force f_G (0 switches the oblateness off)."""

    # ------------------------------------------------------------------ virtual leader (IV)
    leader_altitude_m: float = 400e3
    """Altitude of the leader's circular orbit, m."""
    leader_inclination_deg: float = 45.0
    """Inclination of the leader's orbit, deg."""
    leader_raan_deg: float = 0.0
    """Right ascension of the ascending node (not stated by the paper), deg."""
    leader_latitude_argument_deg: float = 0.0
    """Argument of latitude of the leader at t = 0 (not stated by the paper), deg."""

    # ------------------------------------------------------------------ chaser (IV)
    nominal_inertia: tuple = ((20.0, 1.0, 0.5), (1.0, 21.0, 0.8), (0.5, 0.8, 20.5))
    """J used by the observer and the controller, kg·m²."""
    nominal_mass_kg: float = 100.0
    """m used by the observer and the controller, kg."""
    inertia_uncertainty_ratio: float = 0.1
    """ΔJ = ratio · J: the plant's inertia is (1 + ratio) J (section IV: ΔJ = 0.1 J)."""
    mass_uncertainty_kg: float = 5.0
    """Δm: the plant's mass is m + Δm, kg."""

    # ------------------------------------------------------------------ thrusters (eqs. 10-12, 35)
    thruster_arms_m: tuple = (0.5, 0.5, 0.5)
    """(d_x, d_y, d_z) of the distribution matrix D of eq. (35), m."""
    thruster_max_force_n: float = 0.5
    """f_max, the saturation of every thruster, N."""
    thruster_bias_ratio: float = 0.005
    """f̄_i = ratio · u_i: the output bias, proportional to the saturated output (docs)."""
    misalignment_std: float = 0.01
    """ΔD_ij = std · N(0, 1): thruster misalignment added to D in the plant only."""
    misalignment_seed: int | None = 0
    """Seed of the paper scenario's fixed ΔD draw; ``None`` draws ΔD from the environment's
    RNG at every reset."""

    # ------------------------------------------------------------------ disturbances (IV)
    disturbances: bool = True
    """False switches d_τ and d_f off."""
    torque_disturbance_offset: tuple = (1.2e-3, 1.5e-3, 1.0e-3)
    """Constant part of d_τ (atmospheric drag), N·m."""
    torque_disturbance_amplitude: tuple = (1e-3, 1e-3, 1e-3)
    """Amplitude of the periodic part of d_τ, N·m."""
    torque_disturbance_frequency: tuple = (0.12, 0.15, 0.18)
    """Angular frequencies of d_τ, rad/s."""
    torque_disturbance_phase: tuple = (1.0, 1.0 + math.pi / 2.0, 1.0)
    """Phases of d_τ written as sines (cos x = sin(x + π/2)), rad."""
    force_disturbance_offset: tuple = (4e-4, 4.5e-4, 3e-4)
    """Constant part of d_f, N."""
    force_disturbance_amplitude: tuple = (5e-4, 5e-4, 1e-4)
    """Amplitude of the periodic part of d_f, N."""
    force_disturbance_phase: tuple = (0.0, math.pi / 2.0, math.pi / 3.0)
    """Phases of d_f written as sines; its angular frequency is 2π‖ω_d‖, rad."""

    # ------------------------------------------------------------------ sliding surface (III-B)
    surface_theta1: tuple = (0.1, 0.02)
    """ϑ1 = diag(0.1 I3, 0.02 I3)."""
    surface_theta2: tuple = (0.1, 0.05)
    """ϑ2 = diag(0.1 I3, 0.05 I3)."""
    surface_alpha: float = 2.0 / 3.0
    """α of sig^α(η̃), in (0.5, 1)."""
    singularity_floor: float = 1e-12
    """|η̃_i| is floored at this value in the term |η̃_i|^(α-1) of H1, which is singular at
    η̃_i = 0 (docs/fidelity.md); in exponential-coordinate units (rad, m)."""

    # ------------------------------------------------------------------ ESO eq. (14)
    observer: str = "finite_time"
    """'finite_time' (eq. 14) or 'ref19' (k2 = k4 = k5 = 0, the comparison of Figs. 3-4)."""
    eso_beta: float = 0.125
    eso_alpha1: float = 2.0 / 3.0
    eso_alpha2: float = 1.0 / 3.0
    eso_k1: tuple = (0.8, 1.2)
    eso_k2: tuple = (0.24, 0.4)
    eso_k3: tuple = (1.3, 1.0)
    eso_k4: tuple = (1.3, 0.7)
    eso_k5: tuple = (4.5, 3.2)
    eso_input: str = "saturated"
    """'saturated' feeds the ESO with D sat(D† Γ_c); 'commanded' with Γ_c (see ESO_INPUTS)."""
    observer_start: str = "zero"
    """Ẑ(0) (not stated): 'zero' starts Ẑ1 = Ẑ2 = 0, 'first_measurement' starts Ẑ1 = S(0)."""

    # ------------------------------------------------------------------ controller eqs. (22)-(24)
    gain_k1: tuple = (6.0, 8.0)
    """K1 = diag(6 I3, 8 I3)."""
    gain_k2: tuple = (3.2, 3.6)
    """K2 = diag(3.2 I3, 3.6 I3); Theorem 2 needs K21 > a1 and K22 > a2."""
    adaptive_ell: tuple = (0.1, 0.1)
    """ℓ1, ℓ2 of eqs. (23)-(24)."""
    adaptive_epsilon: tuple = (1.0, 1.0)
    """ϵ1, ϵ2 of eqs. (23)-(24)."""
    adaptive_sigma: tuple = (0.5, 0.5)
    """σ1, σ2 of eqs. (23)-(24), 1/s."""
    adaptive_phi0: tuple = (1.0, 1.2)
    """ϕ̂1(0), ϕ̂2(0)."""

    # ------------------------------------------------------------------ scenario
    initial_point: str = "P1"
    """'P1' or 'P2' of section IV (Ṽ(0) = 0)."""
    initial_attitude_error_deg: tuple | None = None
    """Overrides the point's Φ(0), deg."""
    initial_position_error_m: tuple | None = None
    """Overrides the point's χ(0), m."""
    initial_velocity_error: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    """Ṽ(0) = [Δω (rad/s), Δv (m/s)]; zero in the paper."""
    sampling_period_s: float = 0.001
    """Period at which the controller computes Γ_cout and the trigger is checked (not stated;
    chosen in docs/fidelity.md)."""
    horizon_s: float = 300.0
    """Length of the scenario (not stated; chosen in docs/fidelity.md), s."""
    plant_substeps: int = 1
    """RK4 steps of the plant per sampling period."""
    max_position_error_m: float = 1000.0
    """Failure bound on ‖χ‖ (the paper's points start within 56 m)."""
    max_rate_error_rad_s: float = 1.0
    """Failure bound on ‖Δω‖."""
    max_velocity_error_m_s: float = 10.0
    """Failure bound on ‖Δv‖."""

    def __post_init__(self) -> None:
        require_field_types(self)
        for name in (
            "gravitational_parameter",
            "earth_radius_m",
            "leader_altitude_m",
            "leader_inclination_deg",
            "nominal_mass_kg",
            "thruster_max_force_n",
            "surface_alpha",
            "singularity_floor",
            "eso_beta",
            "eso_alpha1",
            "eso_alpha2",
            "sampling_period_s",
            "horizon_s",
            "max_position_error_m",
            "max_rate_error_rad_s",
            "max_velocity_error_m_s",
        ):
            require_positive(name, getattr(self, name))
        for name in (
            "j2",
            "inertia_uncertainty_ratio",
            "mass_uncertainty_kg",
            "thruster_bias_ratio",
            "misalignment_std",
        ):
            require_non_negative(name, getattr(self, name))
        for name in ("leader_raan_deg", "leader_latitude_argument_deg"):
            if not np.isfinite(float(getattr(self, name))):
                raise ValueError(f"{name} must be finite, got {getattr(self, name)!r}")
        if self.leader_inclination_deg > 180.0:
            raise ValueError(
                f"leader_inclination_deg must be in (0, 180], got {self.leader_inclination_deg}"
            )
        require_spd_matrix("nominal_inertia", self.nominal_inertia)
        require_vector("thruster_arms_m", self.thruster_arms_m, 3, positive=True)
        for name in (
            "torque_disturbance_offset",
            "torque_disturbance_amplitude",
            "torque_disturbance_frequency",
            "torque_disturbance_phase",
            "force_disturbance_offset",
            "force_disturbance_amplitude",
            "force_disturbance_phase",
        ):
            require_vector(name, getattr(self, name), 3)
        for name in (
            "surface_theta1",
            "surface_theta2",
            "eso_k1",
            "eso_k2",
            "eso_k3",
            "eso_k4",
            "eso_k5",
            "gain_k1",
            "gain_k2",
            "adaptive_ell",
            "adaptive_epsilon",
            "adaptive_sigma",
        ):
            _pair(name, getattr(self, name))
        _pair("adaptive_phi0", self.adaptive_phi0, positive=False)
        if not 0.5 < self.surface_alpha < 1.0:
            raise ValueError(f"surface_alpha must be in (0.5, 1), got {self.surface_alpha}")
        if not 0.5 < self.eso_alpha1 < 1.0:
            raise ValueError(f"eso_alpha1 must be in (0.5, 1), got {self.eso_alpha1}")
        if not math.isclose(self.eso_alpha1, 0.5 * (1.0 + self.eso_alpha2), rel_tol=1e-9):
            raise ValueError(
                "eso_alpha1 and eso_alpha2 must satisfy alpha1 = (1 + alpha2)/2 (section III-B), "
                f"got alpha1={self.eso_alpha1}, alpha2={self.eso_alpha2}"
            )
        self._check_theorem1()
        require_choice("observer", self.observer, OBSERVERS)
        require_choice("observer_start", self.observer_start, OBSERVER_STARTS)
        require_choice("eso_input", self.eso_input, ESO_INPUTS)
        require_choice("initial_point", self.initial_point, tuple(INITIAL_POINTS))
        if self.initial_attitude_error_deg is not None:
            phi = require_vector("initial_attitude_error_deg", self.initial_attitude_error_deg, 3)
            if np.linalg.norm(phi) >= 180.0:
                raise ValueError(
                    "initial_attitude_error_deg must have norm < 180 deg (the logarithm map of "
                    f"SE(3) is unique only there), got {np.linalg.norm(phi):.4g}"
                )
        if self.initial_position_error_m is not None:
            require_vector("initial_position_error_m", self.initial_position_error_m, 3)
        require_vector("initial_velocity_error", self.initial_velocity_error, 6)
        if self.misalignment_seed is not None and (
            isinstance(self.misalignment_seed, bool)
            or int(self.misalignment_seed) != self.misalignment_seed
            or self.misalignment_seed < 0
        ):
            raise ValueError(
                f"misalignment_seed must be an integer >= 0 or None, got {self.misalignment_seed!r}"
            )
        if (
            isinstance(self.plant_substeps, bool)
            or int(self.plant_substeps) != self.plant_substeps
            or self.plant_substeps < 1
        ):
            raise ValueError(f"plant_substeps must be an integer >= 1, got {self.plant_substeps!r}")
        for name in ("disturbances",):
            if not isinstance(getattr(self, name), bool | np.bool_):
                raise ValueError(f"{name} must be True or False, got {getattr(self, name)!r}")

    def _check_theorem1(self) -> None:
        """Theorem 1's gain conditions for the finite-time ESO (both blocks j = 1, 2)."""
        if self.observer != "finite_time":
            return
        a1 = self.eso_alpha1
        k1, k2, k3, k4, k5 = (np.asarray(getattr(self, f"eso_k{i}")) for i in range(1, 6))
        first = a1 * k3 * k5 > k2**2 * k3 + a1 * (1.0 + a1) ** 2 * k1**2 * k2**2
        second = 4.0 * k5 * (k2 * k3 + k1 * k4) > k2 * k4**2
        if not (np.all(first) and np.all(second)):
            raise ValueError(
                "eso_k1..eso_k5 must satisfy Theorem 1: alpha1 k3 k5 > k2^2 k3 + "
                "alpha1 (1 + alpha1)^2 k1^2 k2^2 and 4 k5 (k2 k3 + k1 k4) > k2 k4^2 for both "
                f"blocks, got k1={self.eso_k1}, k2={self.eso_k2}, k3={self.eso_k3}, "
                f"k4={self.eso_k4}, k5={self.eso_k5}"
            )

    # ------------------------------------------------------------------ derived values
    @property
    def true_inertia(self) -> np.ndarray:
        """J + ΔJ of the plant, kg·m²."""
        return (1.0 + self.inertia_uncertainty_ratio) * np.asarray(self.nominal_inertia, float)

    @property
    def true_mass_kg(self) -> float:
        """m + Δm of the plant, kg."""
        return self.nominal_mass_kg + self.mass_uncertainty_kg

    @property
    def leader_radius_m(self) -> float:
        """Radius a of the leader's circular orbit, m."""
        return self.earth_radius_m + self.leader_altitude_m

    @property
    def leader_rate_rad_s(self) -> float:
        """Mean motion n = ‖ω_d‖ of the leader, rad/s."""
        return math.sqrt(self.gravitational_parameter / self.leader_radius_m**3)

    def initial_error(self) -> tuple[np.ndarray, np.ndarray]:
        """Φ(0) (rad) and χ(0) (m) of the chosen initial point, with the overrides applied."""
        phi_deg, chi = INITIAL_POINTS[self.initial_point]
        if self.initial_attitude_error_deg is not None:
            phi_deg = self.initial_attitude_error_deg
        if self.initial_position_error_m is not None:
            chi = self.initial_position_error_m
        return np.deg2rad(np.asarray(phi_deg, dtype=float)), np.asarray(chi, dtype=float)

    def distribution_matrix(self) -> np.ndarray:
        """D of eq. (35): rows τ_x, τ_y, τ_z, f_x, f_y, f_z; one column per thruster."""
        dx, dy, dz = self.thruster_arms_m
        return np.array(
            [
                [0, dz, -dy, 0, dz, -dy, 0, -dz, dy, 0, -dz, dy],
                [dz, 0, -dx, -dz, 0, dx, dz, 0, -dx, -dz, 0, dx],
                [-dy, dx, 0, dy, -dx, 0, dy, -dx, 0, -dy, dx, 0],
                [-1, 0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0],
                [0, 1, 0, 0, -1, 0, 0, 1, 0, 0, -1, 0],
                [0, 0, 1, 0, 0, -1, 0, 0, -1, 0, 0, 1],
            ],
            dtype=float,
        )
