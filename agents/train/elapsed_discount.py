"""Discounting by elapsed time for Stable-Baselines3's on-policy algorithms.

Between two self-triggered decisions ``n`` sampling instants apart
(:class:`etsc_envs.decisions.SelfTriggeredWrapper`, ``info["elapsed_steps"] = n``) the return
should be discounted by ``gamma ** n``, ``gamma`` being the per-instant discount, so that it
means what the per-instant return means; SB3 discounts every transition by one ``gamma``. The
rollout buffers here discount transition ``t`` by ``gamma ** n_t`` in the returns and in GAE
(``gae_lambda`` stays per decision), and :class:`ElapsedStepsCallback` records ``n_t`` from the
step's infos (a transition without ``elapsed_steps`` counts one instant)::

    model = MaskablePPO("MlpPolicy", wrapped_env, gamma=0.999,
                        rollout_buffer_class=MaskableElapsedRolloutBuffer)
    model.learn(100_000, callback=ElapsedStepsCallback())

Where an episode is cut by its horizon, SB3 adds ``gamma`` times the value of the cut state to
the last reward, one instant's discount rather than ``gamma ** n``.
"""

from __future__ import annotations

import numpy as np
import torch
from sb3_contrib.common.maskable.buffers import MaskableRolloutBuffer
from stable_baselines3.common.buffers import RolloutBuffer
from stable_baselines3.common.callbacks import BaseCallback


class ElapsedDiscountMixin:
    """A rollout buffer whose transition ``t`` is discounted by ``gamma ** elapsed[t]``."""

    buffer_size: int
    n_envs: int
    pos: int
    gamma: float
    gae_lambda: float
    rewards: np.ndarray
    values: np.ndarray
    episode_starts: np.ndarray
    advantages: np.ndarray
    returns: np.ndarray

    def reset(self) -> None:
        super().reset()  # type: ignore[misc]
        self.elapsed = np.ones((self.buffer_size, self.n_envs), dtype=np.float32)

    def record_elapsed(self, elapsed: np.ndarray) -> None:
        """The sampling instants of the transitions about to be added (one per env)."""
        self.elapsed[self.pos] = elapsed

    def compute_returns_and_advantage(self, last_values: torch.Tensor, dones: np.ndarray) -> None:
        """GAE(λ) and the λ-returns of SB3's ``RolloutBuffer``, discounting each transition by
        ``gamma ** elapsed``."""
        last_values = last_values.clone().cpu().numpy().flatten()
        last_advantage = np.zeros(self.n_envs, dtype=np.float32)
        for step in reversed(range(self.buffer_size)):
            if step == self.buffer_size - 1:
                next_non_terminal = 1.0 - dones.astype(np.float32)
                next_values = last_values
            else:
                next_non_terminal = 1.0 - self.episode_starts[step + 1]
                next_values = self.values[step + 1]
            discount = self.gamma ** self.elapsed[step]
            delta = (
                self.rewards[step] + discount * next_values * next_non_terminal - self.values[step]
            )
            last_advantage = delta + discount * self.gae_lambda * next_non_terminal * last_advantage
            self.advantages[step] = last_advantage
        self.returns = self.advantages + self.values


class ElapsedRolloutBuffer(ElapsedDiscountMixin, RolloutBuffer):
    """SB3's ``RolloutBuffer`` (PPO, A2C) discounting by elapsed instants."""


class MaskableElapsedRolloutBuffer(ElapsedDiscountMixin, MaskableRolloutBuffer):
    """sb3-contrib's ``MaskableRolloutBuffer`` (``MaskablePPO``) discounting by elapsed
    instants."""


class ElapsedStepsCallback(BaseCallback):
    """Passes each step's ``info["elapsed_steps"]`` to the model's rollout buffer (which must
    be an :class:`ElapsedDiscountMixin` buffer; ``ValueError`` at the start otherwise)."""

    def _on_training_start(self) -> None:
        if not isinstance(self.model.rollout_buffer, ElapsedDiscountMixin):
            raise ValueError(
                "rollout_buffer_class must be ElapsedRolloutBuffer or "
                "MaskableElapsedRolloutBuffer for ElapsedStepsCallback"
            )

    def _on_step(self) -> bool:
        infos = self.locals["infos"]
        elapsed = np.array([info.get("elapsed_steps", 1) for info in infos], dtype=np.float32)
        self.model.rollout_buffer.record_elapsed(elapsed)
        return True
