"""The Stable-Baselines3 adapter over a native vector environment."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from numpy.testing import assert_array_equal
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import VecMonitor

import etsc_envs
from agents.train.vector_adapter import (
    SB3VecEnvAdapter,
    make_sb3_vec_env,
    make_shared_policy_vec_env,
    unbatch_info,
)

ENV_ID = "etsc/AttitudeTracking-v0"
SHORT = {"horizon_s": 0.01, "randomize": True}


def test_adapter_reports_sb3_terminal_observations_and_time_limits():
    adapter = make_sb3_vec_env(ENV_ID, 3, **SHORT)
    adapter.seed(4)
    observations = adapter.reset()
    single = gym.make(ENV_ID, **SHORT)
    assert_array_equal(observations[1], single.reset(seed=5)[0])
    last = None
    for _ in range(10):
        single_step = single.step(1)
        last = single_step[0]
        observations, rewards, dones, infos = adapter.step(np.ones(3, dtype=np.int64))
        assert rewards.dtype == np.float32
    assert dones.all(), "a 10-step horizon ends every episode at the 10th step"
    for info in infos:
        assert info["TimeLimit.truncated"] is True
        assert "episode_metrics" in info and info["episode_metrics"]["steps"] == 10
    assert_array_equal(infos[1]["terminal_observation"], last)
    assert not np.array_equal(observations[1], last), "the returned observation is the reset's"


def test_adapter_refuses_a_vector_env_that_resets_at_the_next_step():
    vector = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point")
    with pytest.raises(ValueError, match="same_step"):
        SB3VecEnvAdapter(vector)


def test_attribute_access_reaches_the_sub_environments():
    adapter = make_sb3_vec_env(ENV_ID, 2, **SHORT)
    assert adapter.get_attr("n_steps") == [10, 10]
    adapter.set_attr("transmission_penalty", 0.5, indices=[1])
    assert adapter.get_attr("transmission_penalty") == [0.1, 0.5]
    assert adapter.env_method("observation_index", "time_since_transmission_s") == [13, 13]
    assert adapter.env_is_wrapped(gym.Wrapper) == [False, False]


def test_unbatch_info_keeps_only_the_entries_of_one_sub_environment():
    infos = {
        "cost": np.array([1.0, 2.0]),
        "_cost": np.array([True, True]),
        "failure": np.array([None, "diverged"], dtype=object),
        "_failure": np.array([False, True]),
        "episode_metrics": {"steps": np.array([0, 7]), "_steps": np.array([False, True])},
        "_episode_metrics": np.array([False, True]),
    }
    assert unbatch_info(infos, 0) == {"cost": 1.0}
    assert unbatch_info(infos, 1) == {
        "cost": 2.0,
        "failure": "diverged",
        "episode_metrics": {"steps": 7},
    }


def test_ppo_trains_through_the_adapter_on_a_native_vector_env():
    env = VecMonitor(make_sb3_vec_env(ENV_ID, 4, **SHORT))
    model = PPO("MlpPolicy", env, n_steps=32, batch_size=64, n_epochs=1, seed=0, device="cpu")
    model.learn(256)
    assert model.num_timesteps >= 256
    assert len(model.ep_info_buffer) > 0, "VecMonitor saw finished episodes through the adapter"
    env.close()


CLUSTER_ID = "etsc/ClusterContainment-v0"
CLUSTER_SHORT = {"horizon_s": 0.05, "randomize": True}


def test_shared_policy_env_presents_each_agent_as_its_parallel_env_does():
    rows = 2
    shared = make_shared_policy_vec_env(CLUSTER_ID, rows, **CLUSTER_SHORT)
    shared.seed(3)
    observations = shared.reset()
    parallel = [etsc_envs.make_parallel(CLUSTER_ID, **CLUSTER_SHORT) for _ in range(rows)]
    agents = parallel[0].possible_agents
    n_agents = len(agents)
    assert shared.num_envs == rows * n_agents
    assert shared.observation_space == parallel[0].observation_space(agents[0])
    references = [env.reset(seed=3 + row)[0] for row, env in enumerate(parallel)]
    rng = np.random.default_rng(0)
    for _ in range(5):
        for row in range(rows):
            for agent_index, agent in enumerate(agents):
                assert_array_equal(
                    observations[row * n_agents + agent_index], references[row][agent]
                )
        bits = rng.integers(0, 2, size=shared.num_envs)
        observations, rewards, dones, infos = shared.step(bits)
        for row, env in enumerate(parallel):
            actions = {agent: int(bits[row * n_agents + i]) for i, agent in enumerate(agents)}
            references[row], agent_rewards, *_ = env.step(actions)
            expected = [agent_rewards[agent] for agent in agents]
            assert_array_equal(rewards[row * n_agents : (row + 1) * n_agents], np.float32(expected))
    assert dones.all(), "a 5-step horizon ends every row at the 5th step, all agents together"
    assert "episode_metrics" in infos[0] and "episode_metrics" not in infos[1]
    for row in range(rows):
        for agent_index, agent in enumerate(agents):
            info = infos[row * n_agents + agent_index]
            assert info["TimeLimit.truncated"] is True
            assert_array_equal(info["terminal_observation"], references[row][agent])


def test_shared_policy_env_needs_a_pettingzoo_id():
    with pytest.raises(ValueError, match="not a PettingZoo id"):
        make_shared_policy_vec_env(ENV_ID, 2)


def test_ppo_trains_one_policy_for_every_agent():
    shared = VecMonitor(make_shared_policy_vec_env(CLUSTER_ID, 2, **CLUSTER_SHORT))
    model = PPO("MlpPolicy", shared, n_steps=16, batch_size=48, n_epochs=1, device="cpu", seed=0)
    model.learn(total_timesteps=2 * 12 * 16)
    assert model.num_timesteps == 2 * 6 * 32
