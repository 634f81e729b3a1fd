"""The per-axis send-on-delta conditions eqs. (4)-(6) of paper 004 as a trigger policy."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs.inner_formation.design import equal_share_thresholds
from etsc_envs.inner_formation.params import InnerFormationParams
from etsc_envs.triggers.base import TriggerPolicy

AXES = ("x", "y", "z")


def default_thresholds() -> np.ndarray:
    """Π_i sized by condition (7) for the paper's parameters (equal shares of the bound (A9))."""
    return equal_share_thresholds(InnerFormationParams())


class InnerFormationTrigger(TriggerPolicy):
    """Axis i transmits when |r_i(t) - r_i(t_k)| > Π_i (the complement of eqs. 4-6).

    Args:
        pi: one threshold Π for all axes (m), or
        pi1, pi2, pi3: per-axis thresholds (m). Unset thresholds default to
            :func:`default_thresholds`, which sizes them from condition (7).
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        pi: float | None = None,
        pi1: float | None = None,
        pi2: float | None = None,
        pi3: float | None = None,
    ) -> None:
        super().__init__(observation_space, action_space)
        thresholds = default_thresholds() if pi is None else np.full(3, float(pi))
        for axis, value in enumerate((pi1, pi2, pi3)):
            if value is not None:
                thresholds[axis] = float(value)
        if not np.all(np.isfinite(thresholds)) or np.any(thresholds <= 0.0):
            raise ValueError(f"pi, pi1, pi2, pi3 must be finite numbers > 0 (m), got {thresholds}")
        self.thresholds = thresholds
        self.error_indices = [observation_names.index(f"sampling_error_m_{a}") for a in AXES]

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        return np.abs(obs[:, self.error_indices]) > self.thresholds, state
