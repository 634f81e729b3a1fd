"""The triggering condition eq. (27) of paper 002 as a trigger policy."""

from __future__ import annotations

from typing import ClassVar

import gymnasium as gym
import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.triggers.base import RuleTrigger

PAPER_PSI = 0.1
"""Ψ of Tables 1-3's first event-triggered rows (the paper also runs 1.5 and 2.5)."""


@jit
def attitude_tracking_condition(observation, indices, parameters, statistic, threshold):
    """Eq. (27)'s two sides on one observation: ``trigger_statistic`` (``indices[0]``) against
    Ψ (``parameters[0]``); the rule transmits when the statistic is greater."""
    statistic[0] = observation[indices[0]]
    threshold[0] = parameters[0]


class AttitudeTrackingTrigger(RuleTrigger):
    """Γ(t) of eq. (27): transmit when Σ_i Σ_j |α_ji(e_1i, σ_i)| > Ψ ε_min.

    The environment's ``trigger_statistic`` observation is that sum divided by ε_min, computed by
    :func:`etsc_envs.attitude_tracking.controller.trigger_statistic` at the sensor.

    Args:
        psi: the event-triggering parameter Ψ (> 0).
        observation_names: the environment's ``observation_names`` (to find the statistic).
    """

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        observation_names: tuple[str, ...],
        psi: float = PAPER_PSI,
    ) -> None:
        psi = float(psi)
        if not np.isfinite(psi) or psi <= 0.0:
            raise ValueError(f"psi must be a finite number > 0, got {psi!r}")
        self.psi = psi
        super().__init__(
            observation_space,
            action_space,
            indices=[observation_names.index("trigger_statistic")],
            parameters=[psi],
            keywords={"psi": psi},
        )

    condition = staticmethod(attitude_tracking_condition)
    strict = True
    threshold_groups: ClassVar[dict[str, tuple[str, ...]]] = {"psi": ("psi",)}

    @classmethod
    def paper_thresholds(cls) -> dict[str, float]:
        return {"psi": PAPER_PSI}
