"""The barrier-based triggering rule eq. (15) of paper 003 as a trigger policy."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from etsc_envs.triggers.base import TriggerPolicy

PAPER_ALPHA = 0.05
"""α of eq. (15) in section 4, m²/s."""


class AsteroidOrbitKeepingTrigger(TriggerPolicy):
    """Eq. (15): start a burst when (r_0 - ‖r‖) r·ṙ / ‖r‖ + α <= 0 and none is running.

    The environment's ``barrier_m2ps`` observation is (r_0 - ‖r‖) r·ṙ / ‖r‖; the statistic is
    negative when the spacecraft moves away from r_0, and α sets how far it may go.

    Args:
        alpha: the design parameter α of eq. (15) (> 0), m²/s.
        observation_names: the environment's ``observation_names``.
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        alpha: float = PAPER_ALPHA,
    ) -> None:
        super().__init__(observation_space, action_space)
        alpha = float(alpha)
        if not np.isfinite(alpha) or alpha <= 0.0:
            raise ValueError(f"alpha must be a finite number > 0 (m^2/s), got {alpha!r}")
        self.alpha = alpha
        self.barrier_index = observation_names.index("barrier_m2ps")
        self.burst_index = observation_names.index("burst_active")

    def transmit(self, obs: np.ndarray, state: Any) -> tuple[np.ndarray, Any]:
        fires = obs[:, self.barrier_index] + self.alpha <= 0.0
        return fires & (obs[:, self.burst_index] < 0.5), state
