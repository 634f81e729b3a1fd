"""Inner-formation relative motion with per-axis event-triggered ESOs (paper 004)."""

from etsc_envs.inner_formation.env import InnerFormationEnv
from etsc_envs.inner_formation.params import InnerFormationParams

__all__ = ["InnerFormationEnv", "InnerFormationParams"]
