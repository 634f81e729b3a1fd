"""The barrier-based triggering rule eq. (15) of paper 003 as a trigger policy."""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.triggers.base import RuleTrigger

PAPER_ALPHA = 0.05
"""α of eq. (15) in section 4, m²/s."""


@jit
def asteroid_rule(observation, indices, parameters, out):
    """Eq. (15) on one observation: start a burst when ``barrier_m2ps`` (``indices[0]``) + α
    (``parameters[0]``) <= 0 and no burst runs (``burst_active``, ``indices[1]``, below 0.5)."""
    fires = observation[indices[0]] + parameters[0] <= 0.0 and observation[indices[1]] < 0.5
    out[0] = 1 if fires else 0


class AsteroidOrbitKeepingTrigger(RuleTrigger):
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
        alpha = float(alpha)
        if not np.isfinite(alpha) or alpha <= 0.0:
            raise ValueError(f"alpha must be a finite number > 0 (m^2/s), got {alpha!r}")
        self.alpha = alpha
        super().__init__(
            observation_space,
            action_space,
            indices=[observation_names.index(name) for name in ("barrier_m2ps", "burst_active")],
            parameters=[alpha],
            keywords={"alpha": alpha},
        )

    rule = staticmethod(asteroid_rule)
