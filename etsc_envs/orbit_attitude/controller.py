"""Finite-time ESO, adaptive event-triggered sliding-mode controller and trigger of paper 000.

The controller side knows the nominal model ``Ξ = diag(J, m I3)``, the leader's orbit (g_d, V_d,
V̇_d) and measures g_e and Ṽ. Every 6-vector is ordered rotation first; gains given per block
(``diag(x1 I3, x2 I3)``) are stored as 6-vectors.

* FTSM (section III-B): ``S = Ṽ + ϑ1 η̃ + ϑ2 sig^α(η̃)``.
* ``H1 = H + Ξ⁻¹ f(Ξ) + ϑ1 G(η̃) Ṽ + α ϑ2 |η̃|^(α-1) G(η̃) Ṽ`` with
  ``H = Ξ⁻¹ ad*_V Ξ V + ad_Ṽ Ad_{g_e⁻¹} V_d - Ad_{g_e⁻¹} V̇_d`` (eq. 9), so that
  ``Ṡ = H1 + Ξ⁻¹ Γ_c + Δd``.
* ESO eq. (14) on ``Z1 = S``, ``Z2 = Δd``.
* Control eq. (22): ``Γ_cout = -Ξ(H1 + Ẑ2) - K1 sig^α(S) - (K2 + K3) S`` with the adaptive
  ``K3`` of eqs. (23)-(24).
* Trigger eq. (21): transmit when ``‖ē_c1‖ ≥ a1 ‖S̄1‖ + γ1`` or ``‖ē_c2‖ ≥ a2 ‖S̄2‖ + γ2``,
  ``e_c = Γ_c - Γ_cout`` (held minus current command).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import as_array
from etsc_envs.core.rotations import (
    block_lower_times,
    pose_inverse,
    pose_product,
    se3_right_jacobian_inverse_times,
    skew_rows,
)
from etsc_envs.orbit_attitude.dynamics import (
    gravity_gradient_torque,
    j2_acceleration,
    kepler_gravity,
    leader_rotation_rows,
    leader_twist_of,
)

ControllerGains = namedtuple(
    "ControllerGains",
    [
        "leader",  # LeaderOrbit (the controller knows the reference)
        "earth_radius",  # r_e of the J2 term in f(Ξ), m
        "j2",
        "inertia",  # nominal J
        "inertia_inv",
        "mass",  # nominal m
        "theta1",  # ϑ1 (6,)
        "theta2",  # ϑ2 (6,)
        "alpha",  # α of the FTSM and of K1 sig^α(S)
        "singularity_floor",  # floor of |η̃_i| in |η̃_i|^(α-1)
        "beta",  # ESO β
        "alpha1",  # ESO α1
        "alpha2",  # ESO α2
        "k1",  # ESO gains (6,) each; ref. [19]'s observer has k2 = k4 = k5 = 0
        "k2",
        "k3",
        "k4",
        "k5",
        "gain_k1",  # K1 (6,)
        "gain_k2",  # K2 (6,)
        "ell",  # ℓ1, ℓ2
        "epsilon",  # ϵ1, ϵ2
        "sigma",  # σ1, σ2
        "distribution",  # nominal D of eq. (35), 6×12
        "allocation",  # D† = Dᵀ(D Dᵀ)⁻¹, 12×6
        "max_force",  # f_max, N
        "eso_sees_saturation",  # True: the ESO is fed D sat(D† Γ_c) (docs/fidelity.md)
    ],
)
"""Design parameters and nominal model of the observer and the controller."""


@jit
def signed_power(x: float, power: float) -> float:
    """``sig^a(x) = |x|^a sign(x)`` of a scalar."""
    return np.sign(x) * np.abs(x) ** power


@jit
def sig(x: np.ndarray, power: float) -> np.ndarray:
    """``sig^a(x) = |x|^a sign(x)`` elementwise (:func:`signed_power`)."""
    out = np.empty(x.size)
    for i in range(x.size):
        out[i] = signed_power(x[i], power)
    return out


# Hot-path functions take 6-vectors as arrays or tuples and return tuples (see
# :mod:`etsc_envs.core.vec3`); the ``*_of`` functions have array-returning forms beside them.


@jit
def block_norms_of(x) -> tuple[float, float]:
    """``(‖x[0:3]‖, ‖x[3:6]‖)``: the rotational and translational parts of a 6-vector."""
    return np.sqrt(vec3.dot(x[0:3], x[0:3])), np.sqrt(vec3.dot(x[3:6], x[3:6]))


@jit
def block_norms(x: np.ndarray) -> np.ndarray:
    """:func:`block_norms_of` as an array."""
    return as_array(block_norms_of(x))


@jit
def inertia_times_of(x, gains: ControllerGains) -> tuple:
    """``Ξ x = [J x_ω, m x_v]`` with the nominal Ξ, as a 6-tuple."""
    rotation = vec3.matvec(gains.inertia, x[0:3])
    mass = gains.mass
    return (
        rotation[0],
        rotation[1],
        rotation[2],
        mass * x[3],
        mass * x[4],
        mass * x[5],
    )


@jit
def inertia_times(x: np.ndarray, gains: ControllerGains) -> np.ndarray:
    """:func:`inertia_times_of` as an array."""
    return as_array(inertia_times_of(x, gains))


@jit
def inertia_solve_of(x, gains: ControllerGains) -> tuple:
    """``Ξ⁻¹ x`` with the nominal Ξ, as a 6-tuple."""
    rotation = vec3.matvec(gains.inertia_inv, x[0:3])
    mass = gains.mass
    return (
        rotation[0],
        rotation[1],
        rotation[2],
        x[3] / mass,
        x[4] / mass,
        x[5] / mass,
    )


@jit
def inertia_solve(x: np.ndarray, gains: ControllerGains) -> np.ndarray:
    """:func:`inertia_solve_of` as an array."""
    return as_array(inertia_solve_of(x, gains))


@jit
def known_dynamics(
    t: float, g_e: np.ndarray, twist_error: np.ndarray, gains: ControllerGains
) -> np.ndarray:
    """``H + Ξ⁻¹ f(Ξ)`` of eq. (9) (:func:`known_dynamics_of`) for the 4×4 pose ``g_e``."""
    return as_array(known_dynamics_of(t, g_e[:3, :3], g_e[:3, 3], twist_error, gains))


@jit
def known_dynamics_of(
    t: float, rotation_e, position_e, twist_error, gains: ControllerGains
) -> tuple:
    """``H + Ξ⁻¹ f(Ξ)`` of eq. (9) with the nominal model: the model part of ``d Ṽ/dt``, as a
    6-tuple, for ``g_e = [[R_e, r_e], [0, 1]]`` given as ``R_e``'s rows and ``r_e``.

    ``H = Ξ⁻¹ ad*_V Ξ V + ad_Ṽ Ad_{g_e⁻¹} V_d - Ad_{g_e⁻¹} V̇_d``, ``V = Ṽ + Ad_{g_e⁻¹} V_d``,
    ``f(Ξ) = [M_G, f_G]`` at the chaser's pose ``g_a = g_d g_e``. Evaluated as the paper writes it,
    with absolute quantities: the cancellation of ``-ω × v`` against gravity (~8.7 m/s² each)
    leaves float64 rounding of ~1e-15 m/s², far below anything the loop resolves.
    """
    leader = gains.leader
    rotation_d = leader_rotation_rows(t, leader)
    position_d = (
        rotation_d[0][0] * leader.radius,
        rotation_d[1][0] * leader.radius,
        rotation_d[2][0] * leader.radius,
    )
    rotation_a, position = pose_product(rotation_d, position_d, rotation_e, position_e)
    desired = leader_twist_of(leader)
    # Ad_{g_e⁻¹} V_d
    rotation_inverse, position_inverse = pose_inverse(rotation_e, position_e)
    desired_in_body = block_lower_times(
        rotation_inverse,
        vec3.product(skew_rows(position_inverse), rotation_inverse),
        desired,
    )
    omega = vec3.add(twist_error[0:3], desired_in_body[0:3])
    velocity = vec3.add(twist_error[3:6], desired_in_body[3:6])

    # Ξ⁻¹ ad*_V Ξ V = [J⁻¹(-ω × Jω - v × m v), -ω × v]; v × m v = 0 is dropped exactly rather
    # than left to rounding (~1e-6 N·m at orbital speed).
    inertia_inv = gains.inertia_inv
    free_rate = vec3.matvec(
        inertia_inv, vec3.negate(vec3.cross(omega, vec3.matvec(gains.inertia, omega)))
    )
    free_acceleration = vec3.negate(vec3.cross(omega, velocity))
    # + ad_Ṽ Ad_{g_e⁻¹} V_d  (V̇_d = 0 on the circular orbit)
    bracket = block_lower_times(
        skew_rows(twist_error[0:3]), skew_rows(twist_error[3:6]), desired_in_body
    )
    # + Ξ⁻¹ f(Ξ): gravity-gradient moment and gravity force with J2, nominal J and m
    position_body = vec3.rows_matvec_transposed(rotation_a, position)
    gradient_rate = vec3.matvec(
        inertia_inv, gravity_gradient_torque(position_body, gains.inertia, leader.mu)
    )
    acceleration = kepler_gravity(position, leader.mu)
    if gains.j2 != 0.0:
        acceleration = vec3.add(
            acceleration, j2_acceleration(position, leader.mu, gains.earth_radius, gains.j2)
        )
    gravity_body = vec3.rows_matvec_transposed(rotation_a, acceleration)
    return (
        (free_rate[0] + bracket[0]) + gradient_rate[0],
        (free_rate[1] + bracket[1]) + gradient_rate[1],
        (free_rate[2] + bracket[2]) + gradient_rate[2],
        (free_acceleration[0] + bracket[3]) + gravity_body[0],
        (free_acceleration[1] + bracket[4]) + gravity_body[1],
        (free_acceleration[2] + bracket[5]) + gravity_body[2],
    )


@jit
def _surface_entry(i: int, eta, twist_error, gains: ControllerGains) -> float:
    return (
        twist_error[i]
        + gains.theta1[i] * eta[i]
        + gains.theta2[i] * signed_power(eta[i], gains.alpha)
    )


@jit
def sliding_surface(eta, twist_error, gains: ControllerGains) -> tuple:
    """FTSM ``S = Ṽ + ϑ1 η̃ + ϑ2 sig^α(η̃)`` (section III-B), as a 6-tuple."""
    return (
        _surface_entry(0, eta, twist_error, gains),
        _surface_entry(1, eta, twist_error, gains),
        _surface_entry(2, eta, twist_error, gains),
        _surface_entry(3, eta, twist_error, gains),
        _surface_entry(4, eta, twist_error, gains),
        _surface_entry(5, eta, twist_error, gains),
    )


@jit
def surface_drift(known, eta, twist_error, gains: ControllerGains) -> tuple:
    """``H1 = H + Ξ⁻¹f(Ξ) + ϑ1 G(η̃) Ṽ + α ϑ2 |η̃|^(α-1) G(η̃) Ṽ`` (section III-B), as a
    6-tuple.

    ``known`` is :func:`known_dynamics_of`. The factor ``|η̃_i|^(α-1)`` is singular where a
    component of η̃ crosses zero; |η̃_i| is floored at ``gains.singularity_floor``.
    """
    eta_rate = se3_right_jacobian_inverse_times(eta[0:3], eta[3:6], twist_error)  # G(η̃)Ṽ, eq. 7
    return (
        _drift_entry(0, known, eta, eta_rate, gains),
        _drift_entry(1, known, eta, eta_rate, gains),
        _drift_entry(2, known, eta, eta_rate, gains),
        _drift_entry(3, known, eta, eta_rate, gains),
        _drift_entry(4, known, eta, eta_rate, gains),
        _drift_entry(5, known, eta, eta_rate, gains),
    )


@jit
def _drift_entry(i: int, known, eta, eta_rate, gains: ControllerGains) -> float:
    alpha = gains.alpha
    magnitude = np.maximum(np.abs(eta[i]), gains.singularity_floor)
    return (
        known[i]
        + gains.theta1[i] * eta_rate[i]
        + alpha * gains.theta2[i] * magnitude ** (alpha - 1.0) * eta_rate[i]
    )


@jit
def eso_input(command: np.ndarray, gains: ControllerGains) -> np.ndarray:
    """The control wrench the ESO's model ``Ż1 = H1 + Ξ⁻¹Γ_c + Z2`` is fed with.

    With ``eso_sees_saturation`` it is ``D sat(D† Γ_c)``, what the nominal thrusters deliver for
    the held command (allocation and f_max are known to the controller; misalignment ΔD, bias
    and ΔΞ stay in Δd). Otherwise it is ``Γ_c = D D† Γ_c`` itself and the saturation loss
    ``D Θ(f)`` is part of Δd, as eq. (12) books it (docs/fidelity.md: that reading winds up).
    """
    if not gains.eso_sees_saturation:
        return command
    limit = gains.max_force
    return gains.distribution @ np.minimum(np.maximum(gains.allocation @ command, -limit), limit)


@jit
def eso_derivative(z1, z2, surface, drift, command, gains: ControllerGains):
    """Right-hand side of the finite-time ESO eq. (14); ``command`` is :func:`eso_input`.

    ``Ẑ1' = H1 + Ξ⁻¹Γ_c + Ẑ2 - k1 β^α1 sig^α1(e1) - k2 β e1``,
    ``Ẑ2' = -k3 β^(2α1) sig^α2(e1) - k4 β^(α1+1) sig^α1(e1) - k5 β² e1``, ``e1 = Ẑ1 - S``.
    Returns ``(dẐ1/dt, dẐ2/dt)``, two 6-tuples.
    """
    beta, a1 = gains.beta, gains.alpha1
    powers = (beta**a1, beta ** (2.0 * a1), beta ** (a1 + 1.0))
    fed = inertia_solve_of(command, gains)
    r0 = _eso_rates(0, z1, z2, surface, drift, fed, powers, gains)
    r1 = _eso_rates(1, z1, z2, surface, drift, fed, powers, gains)
    r2 = _eso_rates(2, z1, z2, surface, drift, fed, powers, gains)
    r3 = _eso_rates(3, z1, z2, surface, drift, fed, powers, gains)
    r4 = _eso_rates(4, z1, z2, surface, drift, fed, powers, gains)
    r5 = _eso_rates(5, z1, z2, surface, drift, fed, powers, gains)
    return (
        (r0[0], r1[0], r2[0], r3[0], r4[0], r5[0]),
        (r0[1], r1[1], r2[1], r3[1], r4[1], r5[1]),
    )


@jit
def _eso_rates(i: int, z1, z2, surface, drift, fed, powers, gains: ControllerGains):
    """Component ``i`` of :func:`eso_derivative`'s two rates; ``powers`` holds β^α1, β^(2α1)
    and β^(α1+1)."""
    beta, a1, a2 = gains.beta, gains.alpha1, gains.alpha2
    beta_a1, beta_2a1, beta_a1_1 = powers
    e1 = z1[i] - surface[i]
    sig1 = signed_power(e1, a1)
    dz1 = drift[i] + fed[i] + z2[i] - gains.k1[i] * beta_a1 * sig1 - gains.k2[i] * beta * e1
    dz2 = (
        -gains.k3[i] * beta_2a1 * signed_power(e1, a2)
        - gains.k4[i] * beta_a1_1 * sig1
        - gains.k5[i] * beta * beta * e1
    )
    return dz1, dz2


@jit
def adaptive_denominator_of(norms, t: float, gains: ControllerGains) -> tuple[float, float]:
    """``‖S̄_j‖ + ϵ_j exp(-σ_j t)``, j = 1, 2, from ``norms = ‖S̄_j‖`` (:func:`block_norms_of`):
    the denominator of K3 in eq. (23) and of eq. (24)."""
    epsilon, sigma = gains.epsilon, gains.sigma
    return (
        norms[0] + epsilon[0] * np.exp(-sigma[0] * t),
        norms[1] + epsilon[1] * np.exp(-sigma[1] * t),
    )


@jit
def adaptive_denominator(norms, t: float, gains: ControllerGains) -> np.ndarray:
    """:func:`adaptive_denominator_of` as an array."""
    return as_array(adaptive_denominator_of(norms, t, gains))


@jit
def adaptive_gain_of(phi_hat, integral, denominator, gains: ControllerGains) -> tuple[float, float]:
    """``K3j = (ϕ̂_j + ℓ_j ∫_{t_k}^t ϕ̂_j ds) / (‖S̄_j‖ + ϵ_j exp(-σ_j t))`` (eq. 23), j = 1, 2,
    with the denominator of :func:`adaptive_denominator_of`."""
    ell = gains.ell
    return (
        (phi_hat[0] + ell[0] * integral[0]) / denominator[0],
        (phi_hat[1] + ell[1] * integral[1]) / denominator[1],
    )


@jit
def adaptive_gain(phi_hat, integral, denominator, gains: ControllerGains) -> np.ndarray:
    """:func:`adaptive_gain_of` as an array."""
    return as_array(adaptive_gain_of(phi_hat, integral, denominator, gains))


@jit
def adaptive_derivative(phi_hat, surface, t: float, gains: ControllerGains) -> tuple[float, float]:
    """``ϕ̂_j' = -ℓ_j ϕ̂_j + ‖S̄_j‖² / (‖S̄_j‖ + ϵ_j exp(-σ_j t))`` (eq. 24), as a pair."""
    norms = block_norms_of(surface)
    denominator = adaptive_denominator_of(norms, t, gains)
    ell = gains.ell
    return (
        -ell[0] * phi_hat[0] + norms[0] * norms[0] / denominator[0],
        -ell[1] * phi_hat[1] + norms[1] * norms[1] / denominator[1],
    )


@jit
def fixed_gain_feedback(drift, z2, surface, gains: ControllerGains) -> tuple:
    """``-Ξ(H1 + Ẑ2) - K1 sig^α(S) - K2 S``: the part of eq. (22) without the adaptive K3, as a
    6-tuple."""
    inertial = inertia_times_of(
        (
            drift[0] + z2[0],
            drift[1] + z2[1],
            drift[2] + z2[2],
            drift[3] + z2[3],
            drift[4] + z2[4],
            drift[5] + z2[5],
        ),
        gains,
    )
    return (
        _feedback_entry(0, inertial, surface, gains),
        _feedback_entry(1, inertial, surface, gains),
        _feedback_entry(2, inertial, surface, gains),
        _feedback_entry(3, inertial, surface, gains),
        _feedback_entry(4, inertial, surface, gains),
        _feedback_entry(5, inertial, surface, gains),
    )


@jit
def _feedback_entry(i: int, inertial, surface, gains: ControllerGains) -> float:
    return (
        -inertial[i]
        - gains.gain_k1[i] * signed_power(surface[i], gains.alpha)
        - gains.gain_k2[i] * surface[i]
    )


@jit
def control_law(fixed_gain, surface, k3) -> tuple:
    """``Γ_cout = -Ξ(H1 + Ẑ2) - K1 sig^α(S) - (K2 + K3) S`` (eq. 22): [τ (N·m), u (N)], from
    :func:`fixed_gain_feedback` and the adaptive gains K3 = [K31, K32], as a 6-tuple."""
    return (
        fixed_gain[0] - surface[0] * k3[0],
        fixed_gain[1] - surface[1] * k3[0],
        fixed_gain[2] - surface[2] * k3[0],
        fixed_gain[3] - surface[3] * k3[1],
        fixed_gain[4] - surface[4] * k3[1],
        fixed_gain[5] - surface[5] * k3[1],
    )


@jit
def trigger_fires(
    command_error: np.ndarray,
    surface: np.ndarray,
    a: np.ndarray,
    gamma: np.ndarray,
) -> bool:
    """Eq. (21): ``‖ē_c1‖ ≥ a1 ‖S̄1‖ + γ1`` or ``‖ē_c2‖ ≥ a2 ‖S̄2‖ + γ2``."""
    error = block_norms(command_error)
    threshold = a * block_norms(surface) + gamma
    return error[0] >= threshold[0] or error[1] >= threshold[1]
