"""Followers' attitude motion and disturbances of paper 001, as compiled pure functions.

Each follower i has MRP attitude σ_i (eqs. 1-2) and body rate ω_i obeying the rigid-body
equation (4) with the true inertia J_i = J_0i + ΔJ_i (eq. 5). Control u_i and disturbance d_i
are those of the Euler-Lagrange form (5), as the paper writes eqs. (19) and (66); the body
receives τ_i = G(σ_i)ᵀ u_i and τ_di = G(σ_i)ᵀ d_i. The leaders are stationary (section 5): σ̇_L = 0.
Arrays are followers-major: ``sigma[i]`` is σ_{i+1} of the paper.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from etsc_envs.core import vec3
from etsc_envs.core.jit import jit
from etsc_envs.core.rotations import mrp_kinematics
from etsc_envs.core.vec3 import Vec3

ClusterModel = namedtuple(
    "ClusterModel",
    [
        "adjacency",  # (N+M)×(N+M), a_ij > 0 when i receives from j (section 2.3)
        "leader_attitudes",  # M×3 stationary σ_L, eq. (63)
        "inertia",  # N×3×3 true J_i = J_0i + ΔJ_i, eq. (5)
        "inertia_inverse",  # N×3×3 J_i⁻¹
        "constant_disturbance",  # N×3 d_li, eq. (67)
        "periodic_fraction",  # the 1/5 of eq. (68)
        "periodic_rates",  # (4,) rates of sin(w1 t), cos(w2 t), sin(w3 t) cos(w4 t), rad/s
        "disturbance_phase",  # N×4 phases added to those four arguments (0 in the paper)
        "alpha",  # α of eqs. (9)-(10)
        "control_gain",  # (3,) diag(K_i), eq. (19)
        "adaptation_gain",  # (6,) diag(Λ_i), eq. (20)
        "switching_gain_rate",  # Γ_i, eq. (21)
        "saturating",  # False: sgn of eq. (19); True: sat(·, δ) of eq. (51)
        "saturation_width",  # δ of eq. (51)
        "torque_limit",  # bound on each body-torque component, N·m
        "targets",  # N×3 σ_d = -(L_F⁻¹ L_FL ⊗ I3) σ_L, eq. (8)
    ],
)
"""Everything the followers' plant and controllers depend on, as arrays and scalars."""


@jit
def disturbance(t: float, follower: int, model: ClusterModel) -> Vec3:
    """d_i = d_li + d_uni of eqs. (66)-(68), the disturbance of the Euler-Lagrange form (5).

    d_uni = (1/5) [d_li(1) sin(t/12), d_li(2) cos(t/15), d_li(3) sin(t/10) cos(t/15)].
    """
    constant = model.constant_disturbance[follower]
    rates = model.periodic_rates
    phase = model.disturbance_phase[follower]
    fraction = model.periodic_fraction
    first = constant[0] * np.sin(rates[0] * t + phase[0])
    second = constant[1] * np.cos(rates[1] * t + phase[1])
    third = constant[2] * np.sin(rates[2] * t + phase[2]) * np.cos(rates[3] * t + phase[3])
    return (
        constant[0] + fraction * first,
        constant[1] + fraction * second,
        constant[2] + fraction * third,
    )


@jit
def attitude_rate(sigma, omega) -> Vec3:
    """σ̇_i = G(σ_i) ω_i of eq. (2)."""
    return vec3.matvec_from_zero(mrp_kinematics(sigma), omega)


@jit
def write_attitude_rates(y: np.ndarray, out: np.ndarray) -> None:
    """Write σ̇_i of eq. (2) of every follower of the N×13 state ``y`` into row i of ``out``."""
    for i in range(y.shape[0]):
        vec3.store(out[i], attitude_rate(y[i, 0:3], y[i, 3:6]))


@jit
def body_acceleration(
    t: float,
    follower: int,
    sigma,
    omega,
    control,
    model: ClusterModel,
) -> Vec3:
    """ω̇_i from eq. (4), J_i ω̇_i = -ω_i^× J_i ω_i + τ_i + τ_di, where the body torques are
    τ_i = G(σ_i)ᵀ u_i and τ_di = G(σ_i)ᵀ d_i (u_i = G⁻ᵀτ_i and d_i = G⁻ᵀτ_di in eq. 5)."""
    torque = vec3.matvec_transposed_from_zero(
        mrp_kinematics(sigma), vec3.add(control, disturbance(t, follower, model))
    )
    momentum = vec3.matvec_from_zero(model.inertia[follower], omega)
    return vec3.matvec_from_zero(
        model.inertia_inverse[follower], vec3.subtract(torque, vec3.cross(omega, momentum))
    )


@jit
def containment_error(sigma, target) -> float:
    """‖σ_i - σ_d,i‖: a follower's distance to its containment target (eq. 8)."""
    difference = vec3.subtract(sigma, target)
    return np.sqrt(vec3.dot(difference, difference))
