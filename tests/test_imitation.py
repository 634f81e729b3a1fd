"""Cloning the paper's trigger into an SB3 policy before reinforcement (agents.train.imitation)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import VecNormalize

from agents.train.imitation import clone, collect_demonstrations, paper_trigger
from agents.train.vector_adapter import make_sb3_vec_env

ENV_ID = "etsc/AttitudeTracking-v0"
SHORT = {"randomize": True, "horizon_s": 0.5}


def test_a_cloned_policy_decides_like_the_paper_trigger_on_new_states() -> None:
    env = VecNormalize(make_sb3_vec_env(ENV_ID, 8, **SHORT), norm_reward=False)
    env.seed(0)
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=256, device="cpu", seed=0)
    rule = paper_trigger(ENV_ID, SHORT)
    observations, actions, returns = collect_demonstrations(env, rule, 16_000, gamma=0.99)
    assert observations.shape == (16_000, 14) and returns.shape == (16_000,)
    assert 0.05 < actions.mean() < 0.95, "both decisions are demonstrated"
    summary = clone(model, observations, actions, returns, epochs=10, batch_size=256)
    assert summary["agreement"] > 0.8

    env.training = False  # fresh episodes, statistics frozen
    held_out, decisions, _ = collect_demonstrations(env, rule, 8_000, gamma=0.99)
    predicted, _ = model.policy.predict(held_out, deterministic=True)
    transmit = decisions == 1
    recall = np.mean(predicted[transmit] == 1)
    specificity = np.mean(predicted[~transmit] == 0)
    assert (recall + specificity) / 2 > 0.75, (recall, specificity)


def test_discounted_returns_stop_at_episode_ends() -> None:
    env = make_sb3_vec_env(ENV_ID, 1, horizon_s=0.003)  # 3-step episodes

    class Hold:
        def predict(self, observation, state=None, episode_start=None):
            return np.zeros(len(observation), dtype=np.int64), state

    _, _, returns = collect_demonstrations(env, Hold(), 6, gamma=0.5)
    rewards = []
    env.reset()
    for _ in range(6):
        rewards.append(env.step(np.zeros(1, dtype=np.int64))[1][0])
    for start in (0, 3):
        first, second, third = rewards[start : start + 3]
        assert returns[start] == pytest.approx(first + 0.5 * second + 0.25 * third, rel=1e-6)
        assert returns[start + 2] == pytest.approx(third, rel=1e-6)
