"""The triggering condition eq. (15) of paper 001 as a trigger policy (per follower)."""

from __future__ import annotations

from typing import ClassVar

import gymnasium as gym
import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.triggers.base import RuleTrigger, transmit_bits

PAPER_C, PAPER_RHO, PAPER_NU = 0.6, 2.0, 0.5
"""c_i, ρ_i, ν_i of section 5.1 (the same for every follower)."""


@jit
def trigger_threshold(
    state_threshold: np.ndarray,
    sqrt_lambda_min_k: np.ndarray,
    time_s: np.ndarray,
    c: float = PAPER_C,
    rho: float = PAPER_RHO,
    nu: float = PAPER_NU,
) -> np.ndarray:
    """Right side of eq. (15): (c/2) λ_min(K) ‖s‖ + ρ √λ_min(K) exp(-ν t).

    ``state_threshold`` is the environment's ½ λ_min(K) ‖s‖ (numbers or arrays alike).
    """
    return c * state_threshold + rho * sqrt_lambda_min_k * np.exp(-nu * time_s)


@jit
def cluster_condition(observation, indices, parameters, statistic, threshold):
    """Eq. (15)'s two sides on one observation, for each of the ``n = len(statistic)``
    followers i: ``event_error_i`` against ``trigger_threshold(state_threshold_i,
    sqrt_lambda_min_K_i, time_s_i)``; follower i's event fires when the error reaches it.

    ``indices`` holds the n indices of each of those four names in turn; ``parameters`` holds
    c, ρ, ν.
    """
    n = statistic.shape[0]
    for i in range(n):
        statistic[i] = float(observation[indices[i]])
        threshold[i] = trigger_threshold(
            float(observation[indices[n + i]]),
            float(observation[indices[2 * n + i]]),
            float(observation[indices[3 * n + i]]),
            parameters[0],
            parameters[1],
            parameters[2],
        )


class ClusterContainmentTrigger(RuleTrigger):
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
        self.c, self.rho, self.nu = float(c), float(rho), float(nu)
        if not 0.0 < self.c < 1.0:
            raise ValueError(f"c must satisfy 0 < c < 1 (eq. 15), got {c!r}")
        if not (np.isfinite(self.rho) and self.rho > 0.0):
            raise ValueError(f"rho must be a finite number > 0 (eq. 15), got {rho!r}")
        if not 0.0 < self.nu < 1.0:
            raise ValueError(f"nu must satisfy 0 < nu < 1 (eq. 15), got {nu!r}")
        names = ("event_error", "state_threshold", "sqrt_lambda_min_K", "time_s")
        n_bits = transmit_bits(action_space)
        if n_bits is None and "event_error" in observation_names:
            suffixes = [""]
        else:
            suffixes = [f"_{i}" for i in range(n_bits or 1)]
        super().__init__(
            observation_space,
            action_space,
            indices=[
                observation_names.index(name + suffix) for name in names for suffix in suffixes
            ],
            parameters=[self.c, self.rho, self.nu],
            keywords={"c": self.c, "rho": self.rho, "nu": self.nu},
        )

    condition = staticmethod(cluster_condition)
    threshold_groups: ClassVar[dict[str, tuple[str, ...]]] = {"c": ("c",), "rho": ("rho",)}
    factor_bounds: ClassVar[dict[str, tuple[float, float]]] = {"c": (0.0, 1.0 / PAPER_C)}

    @classmethod
    def paper_thresholds(cls) -> dict[str, float]:
        return {"c": PAPER_C, "rho": PAPER_RHO}
