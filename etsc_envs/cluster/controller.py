"""Event-triggered adaptive sliding-mode containment controller of paper 001 (section 3).

Per follower i: the auxiliary rate σ̇_ri (eq. 9), the sliding variable s_i (eq. 10), the
regressor Y_i of the Euler-Lagrange form (eqs. 11-13), the control law (eq. 19) computed at the
follower's events, the adaptation laws (eqs. 20-21) running continuously, and the state errors
of the triggering condition (eqs. 14-15).

3-vectors are tuples (:mod:`etsc_envs.core.vec3`) and Y_i is the tuple of its three rows of
six, so nothing here allocates; every sum runs from zero in index order, as the array loops of
:mod:`etsc_envs.core.linalg` these functions replaced did, so the values are theirs.
"""

from __future__ import annotations

import numpy as np

from etsc_envs.cluster.dynamics import ClusterModel
from etsc_envs.core import vec3
from etsc_envs.core.jit import jit
from etsc_envs.core.rotations import mrp_inverse_scale, mrp_kinematics, mrp_kinematics_rate
from etsc_envs.core.vec3 import Mat3, Vec3

Row6 = tuple[float, float, float, float, float, float]
Regressor = tuple[Row6, Row6, Row6]
"""Y_i of eq. (13) as the tuple of its rows."""


@jit
def reference_rates(follower: int, sigma: np.ndarray, sigma_dot: np.ndarray, model: ClusterModel):
    """σ̇_r of eq. (9) and its derivative σ̈_r for ``follower`` (leaders are stationary).

    σ̇_ri = -α Σ_j a_ij (σ_i - σ_j),  σ̈_ri = -α Σ_j a_ij (σ̇_i - σ̇_j), j over followers and
    leaders; ``sigma`` and ``sigma_dot`` hold every follower's σ and σ̇ (N×3). Returns
    ``(sigma_r_dot, sigma_r_ddot)``.
    """
    n = sigma.shape[0]
    adjacency = model.adjacency
    leaders = model.leader_attitudes
    own, own_rate = sigma[follower], sigma_dot[follower]
    rate = (0.0, 0.0, 0.0)
    acceleration = (0.0, 0.0, 0.0)
    for j in range(adjacency.shape[1]):
        weight = adjacency[follower, j]
        if weight == 0.0:
            continue
        if j < n:
            rate = vec3.subtract(rate, vec3.scale(weight, vec3.subtract(own, sigma[j])))
            acceleration = vec3.subtract(
                acceleration, vec3.scale(weight, vec3.subtract(own_rate, sigma_dot[j]))
            )
        else:
            rate = vec3.subtract(rate, vec3.scale(weight, vec3.subtract(own, leaders[j - n])))
            acceleration = vec3.subtract(acceleration, vec3.scale(weight, own_rate))
    return vec3.scale(model.alpha, rate), vec3.scale(model.alpha, acceleration)


@jit
def regressor_inner(acceleration: Vec3, rate: Vec3, omega) -> Regressor:
    """L(a) + r^× L(ω) with L of eq. (12) (J x = L(x) Θ, Θ = [J11, J22, J33, J12, J13, J23]),
    the bracket of eq. (13), written out without the zero entries of L and r^×."""
    a, r, w = acceleration, rate, omega
    return (
        (a[0], -r[2] * w[1], r[1] * w[2],
         a[1] + -r[2] * w[0], a[2] + r[1] * w[0], -r[2] * w[2] + r[1] * w[1]),
        (r[2] * w[0], a[1], -r[0] * w[2],
         a[0] + r[2] * w[1], r[2] * w[2] + -r[0] * w[0], a[2] + -r[0] * w[1]),
        (-r[1] * w[0], r[0] * w[1], a[2],
         -r[1] * w[1] + r[0] * w[0], a[0] + -r[1] * w[2], a[1] + r[0] * w[2]),
    )  # fmt: skip


@jit
def regressor_row(weights: Vec3, inner: Regressor) -> Row6:
    """The row ``weightsᵀ inner`` of six (each entry summed from zero over the three rows)."""
    return (
        vec3.column_dot_from_zero(inner, 0, weights),
        vec3.column_dot_from_zero(inner, 1, weights),
        vec3.column_dot_from_zero(inner, 2, weights),
        vec3.column_dot_from_zero(inner, 3, weights),
        vec3.column_dot_from_zero(inner, 4, weights),
        vec3.column_dot_from_zero(inner, 5, weights),
    )


@jit
def regressor(sigma, omega, sigma_dot: Vec3, sigma_r_dot: Vec3, sigma_r_ddot: Vec3) -> Regressor:
    """Y_i(σ_i, σ̇_i, σ̇_ri, σ̈_ri) of eq. (13), so that Y_i Θ_i = M_i σ̈_ri + C_i σ̇_ri.

    Y = G⁻ᵀ [L(G⁻¹σ̈_r) - L(G⁻¹ Ġ G⁻¹ σ̇_r) + (G⁻¹σ̇_r)^× L(G⁻¹σ̇)] with G⁻¹σ̇ = ω; L is linear,
    so the first two terms are L(G⁻¹(σ̈_r - Ġ G⁻¹ σ̇_r)). ``sigma_dot`` is σ̇ = Gω (eq. 2).
    """
    g = mrp_kinematics(sigma)
    factor = mrp_inverse_scale(sigma)
    inverse_transposed: Mat3 = (  # G⁻ᵀ = 16 G / (1 + σᵀσ)²
        vec3.scale(factor, g[0]),
        vec3.scale(factor, g[1]),
        vec3.scale(factor, g[2]),
    )
    rate_r = vec3.matvec_transposed_from_zero(inverse_transposed, sigma_r_dot)
    g_rate_term = vec3.matvec_from_zero(mrp_kinematics_rate(sigma, sigma_dot), rate_r)
    acceleration_r = vec3.matvec_transposed_from_zero(
        inverse_transposed, vec3.subtract(sigma_r_ddot, g_rate_term)
    )
    inner = regressor_inner(acceleration_r, rate_r, omega)
    return (
        regressor_row(inverse_transposed[0], inner),
        regressor_row(inverse_transposed[1], inner),
        regressor_row(inverse_transposed[2], inner),
    )


@jit
def row_times(row: Row6, theta_hat) -> float:
    """A row of Y_i times Θ̂_i, summed from zero over the six columns."""
    total = 0.0
    for j in range(6):
        total += row[j] * theta_hat[j]
    return total


@jit
def regressor_times(rows: Regressor, theta_hat) -> Vec3:
    """Y_i Θ̂_i (the term of eq. 19 an event samples)."""
    return (
        row_times(rows[0], theta_hat),
        row_times(rows[1], theta_hat),
        row_times(rows[2], theta_hat),
    )


@jit
def clip(value: float, bound: float) -> float:
    """``value`` limited to ±``bound`` (NaN stays NaN, as with ``np.minimum``/``np.maximum``)."""
    if value > bound:
        return bound
    if value < -bound:
        return -bound
    return value


@jit
def switching_term(s: float, saturating: bool, width: float) -> float:
    """A component of sgn(s) of eq. (19), or of sat(s, δ) of eq. (51) with δ = ``width`` when
    ``saturating``. (Given the model's fields, not the model: a call taking the namedtuple of
    arrays costs about 0.1 µs in argument handling.)"""
    if saturating:
        return clip(s / width, 1.0)
    return np.sign(s)


@jit
def control_law(s, y_theta: Vec3, k_hat: float, model: ClusterModel) -> Vec3:
    """u_i = -K_i s_i + Y_i Θ̂_i - k̂_i sgn(s_i) of eq. (19), each component limited to
    ±torque_limit (section 5.1.1: the control torques stay within [-1, 1] N·m)."""
    gain = model.control_gain
    limit = model.torque_limit
    saturating, width = model.saturating, model.saturation_width
    return (
        clip(-gain[0] * s[0] + y_theta[0] - k_hat * switching_term(s[0], saturating, width), limit),
        clip(-gain[1] * s[1] + y_theta[1] - k_hat * switching_term(s[1], saturating, width), limit),
        clip(-gain[2] * s[2] + y_theta[2] - k_hat * switching_term(s[2], saturating, width), limit),
    )


@jit
def write_parameter_rate(out: np.ndarray, rows: Regressor, s: Vec3, model: ClusterModel) -> None:
    """Write dΘ̂_i/dt = -Λ_i Y_iᵀ s_i of eq. (20) into ``out[0:6]``."""
    gain = model.adaptation_gain
    for j in range(6):
        out[j] = -gain[j] * vec3.column_dot_from_zero(rows, j, s)


@jit
def switching_gain_derivative(s: Vec3, model: ClusterModel) -> float:
    """dk̂_i/dt = Γ_i ‖s_i‖₁ of eq. (21)."""
    return model.switching_gain_rate * vec3.absolute_sum(s)


@jit
def trigger_errors(s, y_theta, s_event, y_theta_event) -> tuple[float, float]:
    """‖e_Ji‖ and ‖e_si‖ of eq. (14): e_s = s(t_k) - s(t), e_J = Y(t_k)Θ̂(t_k) - Y(t)Θ̂(t)."""
    e_j = vec3.subtract(y_theta_event, y_theta)
    e_s = vec3.subtract(s_event, s)
    return np.sqrt(vec3.dot(e_j, e_j)), np.sqrt(vec3.dot(e_s, e_s))
