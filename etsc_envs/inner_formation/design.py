"""Theorem 1 and Theorem 3 of paper 004 evaluated for a parameter set.

The observer error of axis i in the scaled coordinates of (A1),
ζ_i = [r̃_i/ℓ_i, ψ̃_i/ℓ_i², φ̃_i/ℓ_i³], obeys (A2) with A_K = A - K(β)C Hurwitz (A4). With
P_i A_K + A_Kᵀ P_i = -λ I (λ = 1 here), (A5)-(A9) bound it ultimately by

    ‖ζ_i‖ ≤ sqrt(ω̄/ω̲) · 2/(λ σ ℓ_i) · (‖P K‖ Π_i + ‖P‖ M_i / ℓ_i³)  =: θ_i / ℓ_i⁴,

which gives the bounds (8)-(10): |r̃_i| ≤ θ_i/ℓ_i³, |ψ̃_i| ≤ θ_i/ℓ_i², |φ̃_i| ≤ θ_i/ℓ_i.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_continuous_lyapunov

from etsc_envs.inner_formation.params import InnerFormationParams

LYAPUNOV_DECAY = 1.0
"""λ of (A5): P solves P A_K + A_Kᵀ P = -λ I."""


@dataclass(frozen=True)
class ObserverCertificate:
    """The constants of the proof of Theorem 1 for one β (shared by the three axes)."""

    lyapunov_matrix: np.ndarray
    """P of (A3)."""
    characteristic_roots: np.ndarray
    """Roots of s³ + β_1 s² + β_2 s + β_3 (A4); all have negative real parts."""

    @property
    def norm_p(self) -> float:
        return float(np.linalg.norm(self.lyapunov_matrix, 2))

    @property
    def eigen_ratio(self) -> float:
        """ω̄/ω̲, ratio of P's extreme eigenvalues."""
        eigenvalues = np.linalg.eigvalsh(self.lyapunov_matrix)
        return float(eigenvalues[-1] / eigenvalues[0])


def observer_certificate(beta: tuple[float, float, float]) -> ObserverCertificate:
    """P and the (A4) roots for K(β) = β; ``ValueError`` if A - K(β)C is not Hurwitz."""
    roots = np.roots([1.0, *beta])
    if np.any(roots.real >= 0.0):
        raise ValueError(f"observer_beta gives a non-Hurwitz (A4) polynomial: roots {roots}")
    closed = np.diag([1.0, 1.0], 1) - np.outer(beta, [1.0, 0.0, 0.0])
    lyapunov = solve_continuous_lyapunov(closed.T, -LYAPUNOV_DECAY * np.eye(3))
    return ObserverCertificate(lyapunov_matrix=lyapunov, characteristic_roots=roots)


def disturbance_rate_bound(params: InnerFormationParams) -> np.ndarray:
    """M_i of Assumption 1: (1 + margin) |a_i| w_i, the amplitude of Δȧ_i with a margin."""
    amplitude = np.abs(np.asarray(params.disturbance_amplitude))
    return (1.0 + params.disturbance_rate_margin) * amplitude * params.disturbance_frequency


def equal_share_thresholds(params: InnerFormationParams) -> np.ndarray:
    """Π_i that make sampling and disturbance contribute equally to the bound of (A9):
    ‖P K‖ Π_i = ‖P‖ M_i / ℓ_i³, so the event-triggered bound is twice the continuous one."""
    certificate = observer_certificate(params.observer_beta)
    gain = np.asarray(params.observer_gain)
    share = certificate.norm_p * disturbance_rate_bound(params) / gain**3
    return share / np.linalg.norm(certificate.lyapunov_matrix @ np.asarray(params.observer_beta))


def error_bound_theta(params: InnerFormationParams, thresholds: np.ndarray) -> np.ndarray:
    """θ_i of Theorem 1 for thresholds Π_i (zero thresholds: the continuous ESO of eq. 14)."""
    certificate = observer_certificate(params.observer_beta)
    gain = np.asarray(params.observer_gain)
    beta = np.asarray(params.observer_beta)
    norm_pk = np.linalg.norm(certificate.lyapunov_matrix @ beta)
    drive = gain**3 * norm_pk * np.asarray(
        thresholds
    ) + certificate.norm_p * disturbance_rate_bound(params)
    return np.sqrt(certificate.eigen_ratio) * 2.0 / (LYAPUNOV_DECAY * params.lyapunov_sigma) * drive


def estimation_bounds(
    params: InnerFormationParams, thresholds: np.ndarray
) -> dict[str, np.ndarray]:
    """The bounds (8)-(10): θ/ℓ³ (m), θ/ℓ² (m/s), θ/ℓ (m/s²) per axis."""
    theta = error_bound_theta(params, thresholds)
    gain = np.asarray(params.observer_gain)
    return {
        "position_m": theta / gain**3,
        "velocity_mps": theta / gain**2,
        "disturbance_mps2": theta / gain,
    }


def zeno_bound_s(thresholds: np.ndarray, max_position_m: np.ndarray, max_speed_mps: np.ndarray):
    """Minimum inter-event time of (A23)-(A24): Π_i² / (4 B_r,i B_v,i).

    (A23) bounds d(r_i - r_i(t_k))²/dt by 2 (|r_i| + |r_i(t_k)|) |ṙ_i| ≤ 4 B_r B_v, where the
    paper's √R_i/a_1 is replaced by the tightest valid constants, the largest |r_i| and |ṙ_i|
    of the trajectory (the W of Proposition 1 that would give R_i is not specified).
    """
    return np.asarray(thresholds) ** 2 / (4.0 * max_position_m * max_speed_mps)
