"""The triggering condition eq. (21) of paper 000 as a trigger policy."""

from __future__ import annotations

from typing import ClassVar

import gymnasium as gym
import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.triggers.base import RuleTrigger

PAPER_A = (0.6, 0.8)
"""a1, a2 of section IV (Theorem 2 needs K21 = 3.2 > a1 and K22 = 3.6 > a2)."""
THEOREM_2_K2 = (3.2, 3.6)
"""K21, K22 of section IV: Theorem 2 needs a1 < K21 and a2 < K22."""
PAPER_GAMMA = (0.001, 0.003)
"""γ1 (N·m), γ2 (N) of Case 1; Case 2 uses γ1 = 0.1, γ2 = 0.2."""


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not np.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return value


@jit
def orbit_attitude_condition(observation, indices, parameters, statistic, threshold):
    """Eq. (21)'s two sides on one observation, for j = 1, 2: ``‖ē_cj‖`` against
    ``a_j ‖S̄_j‖ + γ_j``; the rule transmits when either error reaches its threshold.

    ``indices`` holds ``ec1_*, ec2_*`` (entries 0-5) then ``s1_*, s2_*`` (6-11);
    ``parameters`` holds a1, a2, γ1, γ2.
    """
    for j in range(2):
        error = 0.0
        surface = 0.0
        for axis in range(3):
            component = float(observation[indices[3 * j + axis]])
            error += component * component
            component = float(observation[indices[6 + 3 * j + axis]])
            surface += component * component
        statistic[j] = np.sqrt(error)
        threshold[j] = parameters[j] * np.sqrt(surface) + parameters[2 + j]


class OrbitAttitudeTrigger(RuleTrigger):
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
        self.a = np.array([_positive("a1", a1), _positive("a2", a2)])
        self.gamma = np.array([_positive("gamma1", gamma1), _positive("gamma2", gamma2)])
        names = [f"{prefix}_{axis}" for prefix in ("ec1", "ec2", "s1", "s2") for axis in "xyz"]
        super().__init__(
            observation_space,
            action_space,
            indices=[observation_names.index(name) for name in names],
            parameters=np.concatenate([self.a, self.gamma]),
            keywords={"a1": a1, "a2": a2, "gamma1": gamma1, "gamma2": gamma2},
        )

    condition = staticmethod(orbit_attitude_condition)
    conditions_per_channel = 2
    threshold_groups: ClassVar[dict[str, tuple[str, ...]]] = {
        "gamma1": ("gamma1",),
        "gamma2": ("gamma2",),
        "a1": ("a1",),
        "a2": ("a2",),
    }
    factor_bounds: ClassVar[dict[str, tuple[float, float]]] = {
        "a1": (0.0, THEOREM_2_K2[0] / PAPER_A[0]),
        "a2": (0.0, THEOREM_2_K2[1] / PAPER_A[1]),
    }

    @classmethod
    def paper_thresholds(cls) -> dict[str, float]:
        return {
            "gamma1": PAPER_GAMMA[0],
            "gamma2": PAPER_GAMMA[1],
            "a1": PAPER_A[0],
            "a2": PAPER_A[1],
        }
