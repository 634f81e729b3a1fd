"""The deterministic actions of ``greedy_actor`` are those of SB3's ``predict``, bit for bit.

Each covered kind of model (PPO over ``Discrete`` and ``MultiBinary`` actions, MaskablePPO with
and without masks, DQN) gets random weights large enough that its actions vary, then both
paths answer the same observations: batches drawn by hypothesis, a single observation, and
near-ties of the logits. A model outside the covered kinds gets ``None`` (SB3 answers it).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from etsc_envs.sb3_models import NormalizedModel, ObservationStatistics, greedy_actor

torch = pytest.importorskip("torch")
sb3 = pytest.importorskip("stable_baselines3")
sb3_contrib = pytest.importorskip("sb3_contrib")

OBSERVATION_SIZE = 7


class SpacesEnv(gym.Env):
    """An env of these spaces, to build models on (never stepped)."""

    def __init__(self, action_space: gym.Space) -> None:
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (OBSERVATION_SIZE,), np.float32)
        self.action_space = action_space

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> Any:
        return np.zeros(OBSERVATION_SIZE, dtype=np.float32), {}

    def step(self, action: Any) -> Any:
        return np.zeros(OBSERVATION_SIZE, dtype=np.float32), 0.0, False, False, {}

    def action_masks(self) -> np.ndarray:
        return np.ones(int(self.action_space.n), dtype=bool)


def scrambled(model: Any, seed: int) -> Any:
    """``model`` with random weights of unit scale, so that its actions vary."""
    generator = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for parameter in model.policy.parameters():
            parameter.copy_(torch.randn(parameter.shape, generator=generator))
    return model


def make_models() -> dict[str, Any]:
    discrete, binary = gym.spaces.Discrete(9), gym.spaces.MultiBinary(6)
    return {
        "PPO Discrete": sb3.PPO("MlpPolicy", SpacesEnv(discrete), device="cpu", seed=0),
        "PPO MultiBinary": sb3.PPO("MlpPolicy", SpacesEnv(binary), device="cpu", seed=0),
        "MaskablePPO": sb3_contrib.MaskablePPO(
            "MlpPolicy", SpacesEnv(discrete), device="cpu", seed=0
        ),
        "DQN": sb3.DQN("MlpPolicy", SpacesEnv(discrete), device="cpu", seed=0),
    }


MODELS = {name: scrambled(model, seed) for seed, (name, model) in enumerate(make_models().items())}

observations = arrays(
    np.float32,
    st.tuples(st.integers(1, 12), st.just(OBSERVATION_SIZE)),
    elements=st.floats(-3, 3, width=32),
)


def predicted(model: Any, obs: np.ndarray, masks: np.ndarray | None = None) -> np.ndarray:
    extra = {} if masks is None else {"action_masks": masks}
    return model.predict(obs, deterministic=True, **extra)[0]


@pytest.mark.parametrize("name", sorted(MODELS))
@settings(max_examples=40, deadline=None)
@given(obs=observations)
def test_greedy_actions_are_predicts_actions(name: str, obs: np.ndarray) -> None:
    model = MODELS[name]
    greedy = greedy_actor(model)
    assert greedy is not None
    expected = predicted(model, obs)
    actions = greedy(obs, None)
    assert actions.dtype == expected.dtype and actions.shape == expected.shape
    np.testing.assert_array_equal(actions, expected)
    single = greedy(obs[0], None)
    np.testing.assert_array_equal(single, predicted(model, obs[0]))
    assert single.shape == expected.shape[1:]


@settings(max_examples=40, deadline=None)
@given(obs=observations, seed=st.integers(0, 2**16))
def test_masked_greedy_actions_are_predicts_actions(obs: np.ndarray, seed: int) -> None:
    model = MODELS["MaskablePPO"]
    masks = np.random.default_rng(seed).random((len(obs), 9)) < 0.4
    masks[np.arange(len(obs)), np.random.default_rng(seed).integers(0, 9, len(obs))] = True
    actions = greedy_actor(model)(obs, masks)
    np.testing.assert_array_equal(actions, predicted(model, obs, masks))
    assert masks[np.arange(len(obs)), actions].all()


def test_near_ties_are_broken_as_predict_breaks_them() -> None:
    """Logits equal to a few ulps (a zero last layer plus tiny biases): the argmax of the
    normalised probabilities, as the distribution takes it, not of the raw logits."""
    model = make_models()["PPO Discrete"]
    with torch.no_grad():
        model.policy.action_net.weight.zero_()
        bias = torch.full((9,), 0.5)
        bias[3] = torch.nextafter(bias[0], torch.tensor(1.0))
        bias[7] = torch.nextafter(bias[3], torch.tensor(1.0))
        model.policy.action_net.bias.copy_(bias)
    obs = np.random.default_rng(0).normal(size=(5, OBSERVATION_SIZE)).astype(np.float32)
    np.testing.assert_array_equal(greedy_actor(model)(obs, None), predicted(model, obs))


def test_a_normalized_model_answers_with_its_greedy_actor() -> None:
    model = MODELS["PPO Discrete"]
    statistics = ObservationStatistics(
        observation_mean=np.linspace(-1, 1, OBSERVATION_SIZE),
        observation_var=np.linspace(0.5, 2, OBSERVATION_SIZE),
        observation_count=100.0,
        return_mean=0.0,
        return_var=1.0,
        return_count=100.0,
        clip_obs=10.0,
        clip_reward=10.0,
        gamma=0.99,
        epsilon=1e-8,
        norm_obs=True,
        norm_reward=False,
    )
    normalized = NormalizedModel(model, statistics)
    assert normalized.greedy is not None
    obs = np.random.default_rng(1).normal(size=(8, OBSERVATION_SIZE)).astype(np.float32)
    expected = predicted(model, statistics.normalize_obs(obs))
    np.testing.assert_array_equal(normalized.predict(obs)[0], expected)
    stochastic, _ = normalized.predict(obs, deterministic=False)
    assert stochastic.shape == expected.shape


def test_models_it_does_not_cover_get_none() -> None:
    box = gym.spaces.Box(-1, 1, (2,), np.float32)
    assert greedy_actor(sb3.PPO("MlpPolicy", SpacesEnv(box), device="cpu")) is None
    recurrent = sb3_contrib.RecurrentPPO(
        "MlpLstmPolicy", SpacesEnv(gym.spaces.Discrete(3)), device="cpu"
    )
    assert greedy_actor(recurrent) is None
    assert greedy_actor(object()) is None
