"""Event-triggered adaptive sliding-mode containment controller of paper 001 (section 3).

Per follower i: the auxiliary rate σ̇_ri (eq. 9), the sliding variable s_i (eq. 10), the
regressor Y_i of the Euler-Lagrange form (eqs. 11-13), the control law (eq. 19) computed at the
follower's events, the adaptation laws (eqs. 20-21) running continuously, and the state errors
of the triggering condition (eqs. 14-15).
"""

from __future__ import annotations

import numpy as np

from etsc_envs.cluster.dynamics import ClusterModel
from etsc_envs.core.jit import jit
from etsc_envs.core.linalg import matmul, matvec, matvec_transposed
from etsc_envs.core.rotations import (
    mrp_kinematics_matrix,
    mrp_kinematics_matrix_inverse,
    mrp_kinematics_matrix_rate,
    skew,
)


@jit
def reference_rates(sigma: np.ndarray, sigma_dot: np.ndarray, model: ClusterModel):
    """σ̇_r of eq. (9) and its derivative σ̈_r for every follower (leaders are stationary).

    σ̇_ri = -α Σ_j a_ij (σ_i - σ_j),  σ̈_ri = -α Σ_j a_ij (σ̇_i - σ̇_j), j over followers and
    leaders. Returns ``(sigma_r_dot, sigma_r_ddot)``, both N×3.
    """
    n = sigma.shape[0]
    sigma_r_dot = np.zeros((n, 3))
    sigma_r_ddot = np.zeros((n, 3))
    adjacency = model.adjacency
    leaders = model.leader_attitudes
    for i in range(n):
        for j in range(adjacency.shape[1]):
            weight = adjacency[i, j]
            if weight == 0.0:
                continue
            for axis in range(3):  # component by component: no temporary arrays
                if j < n:
                    sigma_r_dot[i, axis] -= weight * (sigma[i, axis] - sigma[j, axis])
                    sigma_r_ddot[i, axis] -= weight * (sigma_dot[i, axis] - sigma_dot[j, axis])
                else:
                    sigma_r_dot[i, axis] -= weight * (sigma[i, axis] - leaders[j - n, axis])
                    sigma_r_ddot[i, axis] -= weight * sigma_dot[i, axis]
    return model.alpha * sigma_r_dot, model.alpha * sigma_r_ddot


@jit
def regressor_operator(x: np.ndarray) -> np.ndarray:
    """L(x) of eq. (12): J x = L(x) Θ with Θ = [J11, J22, J33, J12, J13, J23]."""
    out = np.zeros((3, 6))
    out[0, 0], out[0, 3], out[0, 4] = x[0], x[1], x[2]
    out[1, 1], out[1, 3], out[1, 5] = x[1], x[0], x[2]
    out[2, 2], out[2, 4], out[2, 5] = x[2], x[0], x[1]
    return out


@jit
def regressor(
    sigma: np.ndarray, omega: np.ndarray, sigma_r_dot: np.ndarray, sigma_r_ddot: np.ndarray
) -> np.ndarray:
    """Y_i(σ_i, σ̇_i, σ̇_ri, σ̈_ri) of eq. (13), so that Y_i Θ_i = M_i σ̈_ri + C_i σ̇_ri.

    Y = G⁻ᵀ [L(G⁻¹σ̈_r) - L(G⁻¹ Ġ G⁻¹ σ̇_r) + (G⁻¹σ̇_r)^× L(G⁻¹σ̇)] with G⁻¹σ̇ = ω; L is linear,
    so the first two terms are L(G⁻¹(σ̈_r - Ġ G⁻¹ σ̇_r)).
    """
    g_inverse = mrp_kinematics_matrix_inverse(sigma)
    sigma_dot = matvec(mrp_kinematics_matrix(sigma), omega)
    g_rate = mrp_kinematics_matrix_rate(sigma, sigma_dot)
    rate_r = matvec(g_inverse, sigma_r_dot)
    acceleration_r = matvec(g_inverse, sigma_r_ddot - matvec(g_rate, rate_r))
    inner = regressor_operator(acceleration_r) + matmul(skew(rate_r), regressor_operator(omega))
    return matmul(np.ascontiguousarray(g_inverse.T), inner)


@jit
def switching_term(s: np.ndarray, model: ClusterModel) -> np.ndarray:
    """sgn(s) of eq. (19), or sat(s, δ) of eq. (51) when ``model.saturating``."""
    if model.saturating:
        return np.minimum(np.maximum(s / model.saturation_width, -1.0), 1.0)
    return np.sign(s)


@jit
def control_law(
    s: np.ndarray, y_theta: np.ndarray, k_hat: float, model: ClusterModel
) -> np.ndarray:
    """u_i = -K_i s_i + Y_i Θ̂_i - k̂_i sgn(s_i) of eq. (19), each component limited to
    ±torque_limit (section 5.1.1: the control torques stay within [-1, 1] N·m)."""
    u = -model.control_gain * s + y_theta - k_hat * switching_term(s, model)
    return np.minimum(np.maximum(u, -model.torque_limit), model.torque_limit)


@jit
def parameter_rate(y: np.ndarray, s: np.ndarray, model: ClusterModel) -> np.ndarray:
    """dΘ̂_i/dt = -Λ_i Y_iᵀ s_i of eq. (20)."""
    return -model.adaptation_gain * matvec_transposed(y, s)


@jit
def switching_gain_derivative(s: np.ndarray, model: ClusterModel) -> float:
    """dk̂_i/dt = Γ_i ‖s_i‖₁ of eq. (21)."""
    return model.switching_gain_rate * np.abs(s).sum()


@jit
def trigger_errors(
    s: np.ndarray, y_theta: np.ndarray, s_event: np.ndarray, y_theta_event: np.ndarray
):
    """‖e_Ji‖ and ‖e_si‖ of eq. (14): e_s = s(t_k) - s(t), e_J = Y(t_k)Θ̂(t_k) - Y(t)Θ̂(t)."""
    e_j = y_theta_event - y_theta
    e_s = s_event - s
    return np.sqrt(e_j @ e_j), np.sqrt(e_s @ e_s)
