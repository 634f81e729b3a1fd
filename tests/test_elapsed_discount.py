"""Discounting by elapsed instants: SB3's returns when every transition is one instant, the
γ^n recursion otherwise, the elapsed steps reaching the buffer during training, and DQN's
replay samples discounted by their own transitions' instants."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch
from sb3_contrib import MaskablePPO
from stable_baselines3 import DQN
from stable_baselines3.common.buffers import ReplayBuffer, RolloutBuffer

import etsc_envs  # noqa: F401  (registers the ids)
from agents.train.elapsed_discount import (
    ElapsedReplayBuffer,
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


def replay(buffer_class: type, **kwargs) -> ReplayBuffer:
    """A replay buffer of 3 envs holding 10 transitions each, transition (t, e) lasting
    ``1 + (t + 3 e) % 7`` instants with that number as its reward."""
    space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
    buffer = buffer_class(30, space, gym.spaces.Discrete(3), device="cpu", n_envs=3, **kwargs)
    for step in range(10):
        elapsed = 1 + (step + 3 * np.arange(3)) % 7
        observations = np.full((3, 2), step, dtype=np.float32)
        infos = [{"elapsed_steps": int(n)} for n in elapsed]
        buffer.add(observations, observations, np.zeros(3), elapsed, np.zeros(3), infos)
    return buffer


def test_replay_samples_discount_by_their_own_instants():
    """Each sample's discount is γ to its own transition's instants (its reward here), the
    samples are SB3's, and the global generator ends where SB3's sampling leaves it."""
    ours, theirs = replay(ElapsedReplayBuffer, gamma=GAMMA), replay(ReplayBuffer)
    np.random.seed(3)
    samples = ours.sample(64)
    after = np.random.get_state()[1].copy()
    np.random.seed(3)
    plain = theirs.sample(64)
    np.testing.assert_array_equal(np.random.get_state()[1], after)
    np.testing.assert_array_equal(samples.rewards.numpy(), plain.rewards.numpy())
    assert plain.discounts is None and len(set(samples.rewards.flatten().tolist())) > 3
    np.testing.assert_allclose(
        samples.discounts.numpy(), GAMMA ** samples.rewards.numpy(), rtol=1e-6
    )


def test_dqn_learns_from_elapsed_discounts():
    """DQN on self-triggered decisions stores each decision's instants and trains on them."""
    env = rule_wrapper(gym.make("etsc/InnerFormation-v0", horizon_s=0.1), max_exponent=3)
    model = DQN(
        "MlpPolicy",
        env,
        gamma=0.999,
        learning_starts=8,
        train_freq=4,
        batch_size=8,
        replay_buffer_class=ElapsedReplayBuffer,
        replay_buffer_kwargs={"gamma": 0.999},
        device="cpu",
        seed=0,
    )
    model.learn(total_timesteps=32)
    stored = model.replay_buffer.elapsed[: model.replay_buffer.pos]
    assert stored.max() > 1
    assert model.replay_buffer.sample(8).discounts.max() <= 0.999
