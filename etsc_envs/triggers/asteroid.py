"""The barrier-based triggering rule eq. (15) of paper 003 as a trigger policy."""

from __future__ import annotations

from typing import ClassVar

import gymnasium as gym
import numpy as np

from etsc_envs.core.jit import jit
from etsc_envs.core.validation import require_positive
from etsc_envs.triggers.base import RuleTrigger

PAPER_ALPHA = 0.05
"""α of eq. (15) in section 4, m²/s."""


@jit
def asteroid_condition(observation, indices, parameters, statistic, threshold):
    """Eq. (15)'s two sides on one observation: ``-barrier_m2ps`` (``indices[0]``) against α
    (``parameters[0]``), the rule's ``barrier + α <= 0`` as ``-barrier >= α`` (the same
    comparison: a rounded sum keeps its sign); while a burst runs (``burst_active``,
    ``indices[1]``, at least 0.5) the threshold is infinite and nothing fires."""
    statistic[0] = -float(observation[indices[0]])
    threshold[0] = parameters[0] if observation[indices[1]] < 0.5 else np.inf


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

    condition = staticmethod(asteroid_condition)
    threshold_groups: ClassVar[dict[str, tuple[str, ...]]] = {"alpha": ("alpha",)}

    @classmethod
    def paper_thresholds(cls) -> dict[str, float]:
        return {"alpha": PAPER_ALPHA}


PAPER_SHIELD_MULTIPLE = 1.0
"""The fraction of the shell's half-width the shield of :class:`AsteroidShield` lets a hold's
predicted radius error reach (1: the shell [r_min, r_max] itself)."""


class AsteroidShield:
    """Which holds keep the predicted orbital radius inside the shell of section 3.1.

    Section 3.1 calls the motion unsafe when ‖r‖ moves away from r_0 fast enough for the
    highest (or lowest) radius to pass the barrier r_max (r_min) before thrust acts (Case 1.3,
    Case 2.2). A hold of h after a decision instant lets no burst start for h; it is called
    unsafe when the first-order prediction ‖r‖ + (d‖r‖/dt) h leaves r_0 ± m (r_max - r_0)
    (observations ``radius_m`` and ``radial_velocity_mps``). The burst a hold starts at its
    decision instant is ignored, so the prediction errs towards forbidding. A hold of one
    sampling period (a burst as soon as none runs) and the paper's rule (eq. 15 watches the
    same drift at every instant) are always allowed.

    Args:
        observation_names: the environment's ``observation_names``.
        sampling_period_s: the environment's sampling period (s).
        multiple: m > 0.
        reference_radius_m, shell_half_width_m: r_0 and r_max - r_0 (the paper's 200 m and
            5 m by default).
    """

    def __init__(
        self,
        observation_names: tuple[str, ...],
        sampling_period_s: float,
        multiple: float = PAPER_SHIELD_MULTIPLE,
        reference_radius_m: float = 200.0,
        shell_half_width_m: float = 5.0,
    ) -> None:
        self.multiple = require_positive("multiple", multiple)
        self.sampling_period_s = require_positive("sampling_period_s", sampling_period_s)
        self.reference_radius_m = float(reference_radius_m)
        self.allowed_error_m = self.multiple * float(shell_half_width_m)
        self.radius_index = observation_names.index("radius_m")
        self.rate_index = observation_names.index("radial_velocity_mps")

    def allowed_holds(self, obs: np.ndarray, hold_steps: np.ndarray) -> np.ndarray:
        """Whether each hold of ``hold_steps`` sampling periods is safe at the decision instant
        of each observation: booleans of shape ``(batch, n)``."""
        hold_steps = np.asarray(hold_steps)
        hold_s = hold_steps * self.sampling_period_s
        radius = np.asarray(obs[:, self.radius_index], dtype=np.float64)[:, None]
        rate = np.asarray(obs[:, self.rate_index], dtype=np.float64)[:, None]
        predicted_error = np.abs(radius + rate * hold_s[None, :] - self.reference_radius_m)
        return (predicted_error <= self.allowed_error_m) | (hold_steps == 1)[None, :]

    def allowed_factors(self, factors: np.ndarray) -> np.ndarray:
        """The paper's rule is allowed at every threshold factor."""
        return np.ones(np.shape(factors), dtype=bool)
