"""Discounting by elapsed instants: SB3's returns when every transition is one instant, the
γ^n recursion otherwise, and the elapsed steps reaching the buffer during training."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch
from sb3_contrib import MaskablePPO
from stable_baselines3.common.buffers import RolloutBuffer

import etsc_envs  # noqa: F401  (registers the ids)
from agents.train.elapsed_discount import (
    ElapsedRolloutBuffer,
    ElapsedStepsCallback,
    MaskableElapsedRolloutBuffer,
)
from tests.rule_sets import rule_wrapper

SIZE, ENVS, GAMMA = 6, 2, 0.9


def filled(buffer_class: type, elapsed: np.ndarray | None, gae_lambda: float) -> RolloutBuffer:
    """A buffer of ``SIZE`` random transitions of ``ENVS`` envs (seeded), returns computed."""
    random = np.random.default_rng(0)
    space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
    buffer = buffer_class(
        SIZE, space, gym.spaces.Discrete(3), gamma=GAMMA, gae_lambda=gae_lambda, n_envs=ENVS
    )
    for step in range(SIZE):
        if elapsed is not None:
            buffer.record_elapsed(elapsed[step])
        buffer.add(
            random.normal(size=(ENVS, 2)).astype(np.float32),
            np.zeros((ENVS, 1)),
            random.normal(size=ENVS),
            np.array([step == 0, step == 3]),
            torch.tensor(random.normal(size=ENVS)),
            torch.zeros(ENVS),
        )
    buffer.compute_returns_and_advantage(torch.tensor([0.5, -0.5]), np.zeros(ENVS))
    return buffer


@pytest.mark.parametrize("gae_lambda", [0.95, 1.0])
def test_one_instant_per_transition_is_sb3(gae_lambda):
    ours = filled(ElapsedRolloutBuffer, None, gae_lambda)
    theirs = filled(RolloutBuffer, None, gae_lambda)
    np.testing.assert_allclose(ours.returns, theirs.returns, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(ours.advantages, theirs.advantages, rtol=1e-5, atol=1e-6)


def test_returns_discount_by_elapsed_instants():
    elapsed = np.arange(1, SIZE * ENVS + 1, dtype=np.float32).reshape(SIZE, ENVS) % 5 + 1
    buffer = filled(ElapsedRolloutBuffer, elapsed, gae_lambda=1.0)
    for env, last_value in enumerate([0.5, -0.5]):
        expected = last_value
        for step in reversed(range(SIZE)):
            if step + 1 < SIZE and buffer.episode_starts[step + 1, env]:
                expected = 0.0
            expected = buffer.rewards[step, env] + GAMMA ** elapsed[step, env] * expected
            assert buffer.returns[step, env] == pytest.approx(expected, rel=1e-5)


def test_training_passes_the_elapsed_steps_to_the_buffer():
    env = rule_wrapper(
        gym.make("etsc/InnerFormation-v0", horizon_s=0.1), max_exponent=3, shield_multiple=2.0
    )
    model = MaskablePPO(
        "MlpPolicy",
        env,
        gamma=0.999,
        n_steps=32,
        batch_size=32,
        n_epochs=1,
        rollout_buffer_class=MaskableElapsedRolloutBuffer,
        device="cpu",
        seed=0,
    )
    model.learn(total_timesteps=32, callback=ElapsedStepsCallback())
    assert model.rollout_buffer.elapsed.max() > 1


def test_callback_needs_an_elapsed_buffer():
    env = rule_wrapper(gym.make("etsc/InnerFormation-v0", horizon_s=0.1), max_exponent=3)
    model = MaskablePPO("MlpPolicy", env, n_steps=32, batch_size=32, device="cpu")
    with pytest.raises(ValueError, match="rollout_buffer_class"):
        model.learn(total_timesteps=32, callback=ElapsedStepsCallback())
