"""The triggering condition eq. (21) of paper 000 as a trigger policy."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs.triggers.base import TriggerPolicy

PAPER_A = (0.6, 0.8)
"""a1, a2 of section IV (Theorem 2 needs K21 = 3.2 > a1 and K22 = 3.6 > a2)."""
PAPER_GAMMA = (0.001, 0.003)
"""γ1 (N·m), γ2 (N) of Case 1; Case 2 uses γ1 = 0.1, γ2 = 0.2."""


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not np.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


class OrbitAttitudeTrigger(TriggerPolicy):
    """Eq. (21): transmit when ``‖ē_c1‖ ≥ a1 ‖S̄1‖ + γ1`` or ``‖ē_c2‖ ≥ a2 ‖S̄2‖ + γ2``.

    ``e_c = Γ_c - Γ_cout`` is the held command minus the controller's current one (observation
    ``ec1_*`` torque, ``ec2_*`` force) and ``S̄1``, ``S̄2`` are the rotational and translational
    parts of the sliding variable (``s1_*``, ``s2_*``).

    Args:
        a1, a2: relative thresholds (> 0; the paper's Theorem 2 also needs a1 < K21, a2 < K22).
        gamma1: absolute threshold on the torque error, N·m (> 0).
        gamma2: absolute threshold on the force error, N (> 0).
        observation_names: the environment's ``observation_names``.
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        a1: float = PAPER_A[0],
        a2: float = PAPER_A[1],
        gamma1: float = PAPER_GAMMA[0],
        gamma2: float = PAPER_GAMMA[1],
    ) -> None:
        super().__init__(observation_space, action_space)
        self.a = np.array([_positive("a1", a1), _positive("a2", a2)])
        self.gamma = np.array([_positive("gamma1", gamma1), _positive("gamma2", gamma2)])

        def index(prefix: str) -> list[int]:
            return [observation_names.index(f"{prefix}_{axis}") for axis in "xyz"]

        # (2, 3) index blocks: rows j = 1, 2 of eq. (21)
        self.ec = np.array([index("ec1"), index("ec2")])
        self.s = np.array([index("s1"), index("s2")])

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        obs = np.asarray(obs, dtype=np.float64)
        error = obs[:, self.ec]  # (batch, 2, 3)
        surface = obs[:, self.s]
        error_norm = np.sqrt(np.einsum("bij,bij->bi", error, error))
        surface_norm = np.sqrt(np.einsum("bij,bij->bi", surface, surface))
        return (error_norm >= self.a * surface_norm + self.gamma).any(axis=1), state
