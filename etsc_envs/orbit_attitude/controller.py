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
from etsc_envs.core.linalg import (
    fused_dot,
    fused_matmul,
    fused_matvec3,
    fused_matvec6,
)
from etsc_envs.core.rotations import (
    se3_ad,
    se3_adjoint,
    se3_inverse,
    se3_right_jacobian_inverse,
)
from etsc_envs.orbit_attitude.dynamics import (
    gravity_gradient_torque,
    j2_acceleration,
    kepler_gravity,
    leader_pose,
    leader_twist,
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


@jit
def block_norms(x: np.ndarray) -> np.ndarray:
    """``[‖x[0:3]‖, ‖x[3:6]‖]``: the rotational and translational parts of a 6-vector."""
    out = np.empty(2)
    out[0] = np.sqrt(fused_dot(x[0:3], x[0:3]))
    out[1] = np.sqrt(fused_dot(x[3:6], x[3:6]))
    return out


@jit
def inertia_times(x: np.ndarray, gains: ControllerGains) -> np.ndarray:
    """``Ξ x = [J x_ω, m x_v]`` with the nominal Ξ."""
    out = np.empty(6)
    out[0:3] = fused_matvec3(gains.inertia, x[0:3])
    out[3:6] = gains.mass * x[3:6]
    return out


@jit
def inertia_solve(x: np.ndarray, gains: ControllerGains) -> np.ndarray:
    """``Ξ⁻¹ x`` with the nominal Ξ."""
    out = np.empty(6)
    out[0:3] = fused_matvec3(gains.inertia_inv, x[0:3])
    out[3:6] = x[3:6] / gains.mass
    return out


@jit
def known_dynamics(
    t: float, g_e: np.ndarray, twist_error: np.ndarray, gains: ControllerGains
) -> np.ndarray:
    """``H + Ξ⁻¹ f(Ξ)`` of eq. (9) with the nominal model: the model part of ``d Ṽ/dt``.

    ``H = Ξ⁻¹ ad*_V Ξ V + ad_Ṽ Ad_{g_e⁻¹} V_d - Ad_{g_e⁻¹} V̇_d``, ``V = Ṽ + Ad_{g_e⁻¹} V_d``,
    ``f(Ξ) = [M_G, f_G]`` at the chaser's pose ``g_a = g_d g_e``. Evaluated as the paper writes it,
    with absolute quantities: the cancellation of ``-ω × v`` against gravity (~8.7 m/s² each)
    leaves float64 rounding of ~1e-15 m/s², far below anything the loop resolves.
    """
    leader = gains.leader
    g_d = leader_pose(t, leader)
    g_a = fused_matmul(g_d, g_e)
    rotation_a = np.ascontiguousarray(g_a[:3, :3])
    position = np.ascontiguousarray(g_a[:3, 3])
    desired = leader_twist(leader)
    desired_in_body = fused_matvec6(se3_adjoint(se3_inverse(g_e)), desired)  # Ad_{g_e⁻¹} V_d
    twist = twist_error + desired_in_body
    omega = np.ascontiguousarray(twist[0:3])
    velocity = np.ascontiguousarray(twist[3:6])

    # Ξ⁻¹ ad*_V Ξ V = [J⁻¹(-ω × Jω - v × m v), -ω × v]; v × m v = 0 is dropped exactly rather
    # than left to rounding (~1e-6 N·m at orbital speed).
    inertia_inv = gains.inertia_inv
    free_rate = vec3.matvec(
        inertia_inv, vec3.negate(vec3.cross(omega, vec3.matvec(gains.inertia, omega)))
    )
    free_acceleration = vec3.negate(vec3.cross(omega, velocity))
    # + ad_Ṽ Ad_{g_e⁻¹} V_d  (V̇_d = 0 on the circular orbit)
    out = fused_matvec6(se3_ad(twist_error), desired_in_body)
    # + Ξ⁻¹ f(Ξ): gravity-gradient moment and gravity force with J2, nominal J and m
    position_body = vec3.matvec_transposed(rotation_a, position)
    gradient_rate = vec3.matvec(
        inertia_inv, gravity_gradient_torque(position_body, gains.inertia, leader.mu)
    )
    acceleration = kepler_gravity(position, leader.mu)
    if gains.j2 != 0.0:
        acceleration = vec3.add(
            acceleration, j2_acceleration(position, leader.mu, gains.earth_radius, gains.j2)
        )
    gravity_body = vec3.matvec_transposed(rotation_a, acceleration)
    for i in range(3):
        out[i] = (free_rate[i] + out[i]) + gradient_rate[i]
        out[3 + i] = (free_acceleration[i] + out[3 + i]) + gravity_body[i]
    return out


@jit
def sliding_surface(eta: np.ndarray, twist_error: np.ndarray, gains: ControllerGains):
    """FTSM ``S = Ṽ + ϑ1 η̃ + ϑ2 sig^α(η̃)`` (section III-B)."""
    theta1, theta2, alpha = gains.theta1, gains.theta2, gains.alpha
    out = np.empty(6)
    for i in range(6):
        out[i] = twist_error[i] + theta1[i] * eta[i] + theta2[i] * signed_power(eta[i], alpha)
    return out


@jit
def surface_drift(
    known: np.ndarray, eta: np.ndarray, twist_error: np.ndarray, gains: ControllerGains
) -> np.ndarray:
    """``H1 = H + Ξ⁻¹f(Ξ) + ϑ1 G(η̃) Ṽ + α ϑ2 |η̃|^(α-1) G(η̃) Ṽ`` (section III-B).

    ``known`` is :func:`known_dynamics`. The factor ``|η̃_i|^(α-1)`` is singular where a
    component of η̃ crosses zero; |η̃_i| is floored at ``gains.singularity_floor``.
    """
    eta_rate = fused_matvec6(se3_right_jacobian_inverse(eta), twist_error)  # η̃̇ = G(η̃)Ṽ, eq. 7
    theta1, theta2, alpha = gains.theta1, gains.theta2, gains.alpha
    floor = gains.singularity_floor
    out = np.empty(6)
    for i in range(6):
        magnitude = np.maximum(np.abs(eta[i]), floor)
        out[i] = (
            known[i]
            + theta1[i] * eta_rate[i]
            + alpha * theta2[i] * magnitude ** (alpha - 1.0) * eta_rate[i]
        )
    return out


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
def eso_derivative(
    z1: np.ndarray,
    z2: np.ndarray,
    surface: np.ndarray,
    drift: np.ndarray,
    command: np.ndarray,
    gains: ControllerGains,
):
    """Right-hand side of the finite-time ESO eq. (14); ``command`` is :func:`eso_input`.

    ``Ẑ1' = H1 + Ξ⁻¹Γ_c + Ẑ2 - k1 β^α1 sig^α1(e1) - k2 β e1``,
    ``Ẑ2' = -k3 β^(2α1) sig^α2(e1) - k4 β^(α1+1) sig^α1(e1) - k5 β² e1``, ``e1 = Ẑ1 - S``.
    Returns ``(dẐ1/dt, dẐ2/dt)``.
    """
    beta, a1, a2 = gains.beta, gains.alpha1, gains.alpha2
    beta_a1, beta_2a1, beta_a1_1 = beta**a1, beta ** (2.0 * a1), beta ** (a1 + 1.0)
    k1, k2, k3, k4, k5 = gains.k1, gains.k2, gains.k3, gains.k4, gains.k5
    fed = inertia_solve(command, gains)
    dz1 = np.empty(6)
    dz2 = np.empty(6)
    for i in range(6):
        e1 = z1[i] - surface[i]
        sig1 = signed_power(e1, a1)
        dz1[i] = drift[i] + fed[i] + z2[i] - k1[i] * beta_a1 * sig1 - k2[i] * beta * e1
        dz2[i] = (
            -k3[i] * beta_2a1 * signed_power(e1, a2)
            - k4[i] * beta_a1_1 * sig1
            - k5[i] * beta * beta * e1
        )
    return dz1, dz2


@jit
def adaptive_denominator(norms: np.ndarray, t: float, gains: ControllerGains) -> np.ndarray:
    """``‖S̄_j‖ + ϵ_j exp(-σ_j t)``, j = 1, 2, from ``norms = ‖S̄_j‖`` (:func:`block_norms`):
    the denominator of K3 in eq. (23) and of eq. (24)."""
    out = np.empty(2)
    for j in range(2):
        out[j] = norms[j] + gains.epsilon[j] * np.exp(-gains.sigma[j] * t)
    return out


@jit
def adaptive_gain(
    phi_hat: np.ndarray, integral: np.ndarray, denominator: np.ndarray, gains: ControllerGains
) -> np.ndarray:
    """``K3j = (ϕ̂_j + ℓ_j ∫_{t_k}^t ϕ̂_j ds) / (‖S̄_j‖ + ϵ_j exp(-σ_j t))`` (eq. 23), j = 1, 2,
    with the denominator of :func:`adaptive_denominator`."""
    return (phi_hat + gains.ell * integral) / denominator


@jit
def adaptive_derivative(
    phi_hat: np.ndarray, surface: np.ndarray, t: float, gains: ControllerGains
) -> np.ndarray:
    """``ϕ̂_j' = -ℓ_j ϕ̂_j + ‖S̄_j‖² / (‖S̄_j‖ + ϵ_j exp(-σ_j t))`` (eq. 24)."""
    norms = block_norms(surface)
    denominator = adaptive_denominator(norms, t, gains)
    out = np.empty(2)
    for j in range(2):
        out[j] = -gains.ell[j] * phi_hat[j] + norms[j] * norms[j] / denominator[j]
    return out


@jit
def fixed_gain_feedback(
    drift: np.ndarray, z2: np.ndarray, surface: np.ndarray, gains: ControllerGains
) -> np.ndarray:
    """``-Ξ(H1 + Ẑ2) - K1 sig^α(S) - K2 S``: the part of eq. (22) without the adaptive K3."""
    total = np.empty(6)
    for i in range(6):
        total[i] = drift[i] + z2[i]
    out = inertia_times(total, gains)
    gain_k1, gain_k2, alpha = gains.gain_k1, gains.gain_k2, gains.alpha
    for i in range(6):
        out[i] = -out[i] - gain_k1[i] * signed_power(surface[i], alpha) - gain_k2[i] * surface[i]
    return out


@jit
def control_law(fixed_gain: np.ndarray, surface: np.ndarray, k3: np.ndarray) -> np.ndarray:
    """``Γ_cout = -Ξ(H1 + Ẑ2) - K1 sig^α(S) - (K2 + K3) S`` (eq. 22): [τ (N·m), u (N)], from
    :func:`fixed_gain_feedback` and the adaptive gains K3 = [K31, K32]."""
    out = np.empty(6)
    for i in range(6):
        out[i] = fixed_gain[i] - surface[i] * k3[i // 3]
    return out


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
