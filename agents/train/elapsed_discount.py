"""Discounting by elapsed time for Stable-Baselines3's algorithms.

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

DQN's target is the semi-Markov one, ``r + gamma ** n * max_a Q'(s', a)``, with
:class:`ElapsedReplayBuffer`, which reads ``n`` from the infos it is given with each transition
and returns ``gamma ** n`` as the samples' ``discounts`` (SB3's DQN uses them in place of
``gamma``; a cut episode's bootstrap is discounted by its ``n`` too)::

    model = DQN("MlpPolicy", wrapped_env, gamma=0.999,
                replay_buffer_class=ElapsedReplayBuffer, replay_buffer_kwargs={"gamma": 0.999})
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from sb3_contrib.common.maskable.buffers import MaskableRolloutBuffer
from stable_baselines3.common.buffers import ReplayBuffer, RolloutBuffer
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.type_aliases import ReplayBufferSamples
from stable_baselines3.common.vec_env import VecNormalize


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
        self.model.rollout_buffer.record_elapsed(elapsed_steps(self.locals["infos"]))
        return True


def elapsed_steps(infos: list[dict[str, Any]]) -> np.ndarray:
    """Each info's ``elapsed_steps`` (one instant where a transition has none)."""
    return np.array([info.get("elapsed_steps", 1) for info in infos], dtype=np.float32)


class ElapsedReplayBuffer(ReplayBuffer):
    """SB3's ``ReplayBuffer`` whose samples discount transition ``t`` by ``gamma ** n_t``
    (``discounts``), ``n_t`` read from ``info["elapsed_steps"]`` when the transition is added.

    Args:
        gamma: the per-instant discount (the algorithm's ``gamma``).
        *args, **kwargs: ``ReplayBuffer``'s; ``optimize_memory_usage`` is refused.
    """

    def __init__(self, *args: Any, gamma: float = 0.99, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if self.optimize_memory_usage:
            raise ValueError("ElapsedReplayBuffer: optimize_memory_usage is not supported")
        self.gamma = float(gamma)
        self.elapsed = np.ones((self.buffer_size, self.n_envs), dtype=np.float32)

    def add(
        self,
        obs: np.ndarray,
        next_obs: np.ndarray,
        action: np.ndarray,
        reward: np.ndarray,
        done: np.ndarray,
        infos: list[dict[str, Any]],
    ) -> None:
        self.elapsed[self.pos] = elapsed_steps(infos)
        super().add(obs, next_obs, action, reward, done, infos)

    def _get_samples(
        self, batch_inds: np.ndarray, env: VecNormalize | None = None
    ) -> ReplayBufferSamples:
        """``ReplayBuffer``'s samples with their ``discounts``. Its one draw is the env index
        of each sample, from NumPy's global generator; the draw is repeated from the same
        generator state to find them, and the generator left as that draw left it."""
        before = np.random.get_state()
        samples = super()._get_samples(batch_inds, env)
        after = np.random.get_state()
        np.random.set_state(before)
        env_indices = np.random.randint(0, high=self.n_envs, size=(len(batch_inds),))
        np.random.set_state(after)
        discounts = self.gamma ** self.elapsed[batch_inds, env_indices].reshape(-1, 1)
        return samples._replace(discounts=self.to_torch(discounts))
