"""The triggering condition eq. (15) of paper 001 as a trigger policy (per follower)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs.triggers.base import TriggerPolicy

PAPER_C, PAPER_RHO, PAPER_NU = 0.6, 2.0, 0.5
"""c_i, ρ_i, ν_i of section 5.1 (the same for every follower)."""


def trigger_threshold(
    state_threshold: np.ndarray,
    sqrt_lambda_min_k: np.ndarray,
    time_s: np.ndarray,
    c: float = PAPER_C,
    rho: float = PAPER_RHO,
    nu: float = PAPER_NU,
) -> np.ndarray:
    """Right side of eq. (15): (c/2) λ_min(K) ‖s‖ + ρ √λ_min(K) exp(-ν t).

    ``state_threshold`` is the environment's ½ λ_min(K) ‖s‖.
    """
    return c * state_threshold + rho * sqrt_lambda_min_k * np.exp(-nu * time_s)


class ClusterContainmentTrigger(TriggerPolicy):
    """Eq. (15): follower i's event fires when ‖e_J‖ + λ_max(K)‖e_s‖ ≥ (c/2) λ_min(K)‖s‖ + μ(t),
    with μ(t) = ρ √λ_min(K) exp(-ν t).

    Works for one follower (``Discrete(2)``, an agent of ``etsc/ClusterContainment-v0``, whose
    observation names are unsuffixed) and for the central env (``MultiBinary(N)``, names
    suffixed ``_0 .. _{N-1}``).

    Args:
        c: 0 < c < 1, weight of the state-dependent threshold.
        rho: ρ > 0, amplitude of the time-dependent threshold.
        nu: 0 < ν < 1, its decay rate (1/s).
        observation_names: the environment's (or the agent's) observation names.
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        c: float = PAPER_C,
        rho: float = PAPER_RHO,
        nu: float = PAPER_NU,
    ) -> None:
        super().__init__(observation_space, action_space)
        self.c, self.rho, self.nu = float(c), float(rho), float(nu)
        if not 0.0 < self.c < 1.0:
            raise ValueError(f"c must satisfy 0 < c < 1 (eq. 15), got {c!r}")
        if not (np.isfinite(self.rho) and self.rho > 0.0):
            raise ValueError(f"rho must be a finite number > 0 (eq. 15), got {rho!r}")
        if not 0.0 < self.nu < 1.0:
            raise ValueError(f"nu must satisfy 0 < nu < 1 (eq. 15), got {nu!r}")
        names = ("event_error", "state_threshold", "sqrt_lambda_min_K", "time_s")
        if self.n_bits is None and "event_error" in observation_names:
            suffixes = [""]
        else:
            suffixes = [f"_{i}" for i in range(self.n_bits or 1)]
        self.indices = np.array(
            [[observation_names.index(name + suffix) for suffix in suffixes] for name in names]
        )

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        event_error, state_threshold, sqrt_lambda, time_s = (
            obs[:, rows].astype(np.float64) for rows in self.indices
        )
        threshold = trigger_threshold(
            state_threshold, sqrt_lambda, time_s, self.c, self.rho, self.nu
        )
        fire = event_error >= threshold
        return (fire[:, 0] if self.n_bits is None else fire), state
