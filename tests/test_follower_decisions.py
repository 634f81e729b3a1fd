"""One follower's self-triggered decisions in the decentralised cluster (paper 001), its
teammates following the shared policy: the training env against the deployed transmit/hold
policy that ``baselines.evaluate`` runs, step for step (short horizons)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import etsc_envs
from etsc_envs.decisions import FollowerDecisionEnv
from etsc_envs.evaluation.episodes import run_parallel_episode
from etsc_envs.papers import paper_of
from etsc_envs.triggers.base import HeartbeatPolicy
from tests.rule_sets import deployed_policy, rule_follower

CLUSTER = "etsc/ClusterContainment-v0"
HORIZON_S = 3.0
DECISIONS = {"max_exponent": 5, "factors": (0.5, 1.0, 1.5)}


class ScriptedSharedModel:
    """A stand-in for a model being trained: a decision that varies with the observation, and
    no observation statistics."""

    def __init__(self, n_actions: int) -> None:
        self.n_actions = n_actions

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        digits = np.abs(np.asarray(observation)).sum(axis=1) * 1e3
        return digits.astype(np.int64) % self.n_actions, None

    def get_vec_normalize_env(self):
        return None


def follower_env(horizon_s: float = HORIZON_S, **kwargs) -> FollowerDecisionEnv:
    return rule_follower(CLUSTER, {"horizon_s": horizon_s}, **{**DECISIONS, **kwargs})


@pytest.mark.parametrize("seed", [0, 5])
def test_training_episode_is_the_deployed_policy_step_for_step(seed):
    """The learner acting as the model its teammates follow: the training episode is the
    evaluation episode of the deployed policy, agent for agent, and the learner is paid exactly
    its own channel's rewards."""
    env = follower_env(gamma=1.0)
    model = ScriptedSharedModel(env.action_space.n)
    env.follow_model(model)
    observation, info = env.reset(seed=seed)
    learner_return, decisions, actions = 0.0, 0, set()
    while True:
        action = int(model.predict(observation[None])[0][0])
        observation, reward, terminated, truncated, info = env.step(action)
        learner_return += reward
        decisions += 1
        actions.add(info["action"])
        if terminated or truncated:
            break
    training = info["episode_metrics"]
    assert len(actions) > 2 and decisions > 10  # the scripted decisions vary

    parallel = etsc_envs.make_parallel(CLUSTER, horizon_s=HORIZON_S)
    deployed = deployed_policy(model, env, parallel)
    record, _ = run_parallel_episode(parallel, deployed, seed=seed)
    for name in parallel.possible_agents:
        assert training["agents"][name]["transmissions"] == record["agents"][name]["transmissions"]
    assert training["mean_cost"] == record["mean_cost"]
    learner = parallel.possible_agents[env.learner]
    assert learner_return == pytest.approx(record["agents"][learner]["return"], rel=1e-12)


def test_every_follower_is_the_learner_under_some_seed():
    env = follower_env()
    learners = {env.reset(seed=seed)[1]["learner"] for seed in range(40)}
    assert learners == set(range(env.n_agents))
    assert env.reset(seed=7)[1]["learner"] == env.reset(seed=7)[1]["learner"]


def episode_info(env: FollowerDecisionEnv, action: int, seed: int) -> dict:
    """The last ``info`` of an episode in which the learner takes ``action`` at every decision."""
    env.reset(seed=seed)
    while True:
        _, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            return info


def rule_alone(horizon_s: float, seed: int, heartbeat: int | None = None, **thresholds) -> dict:
    """The record of eq. (15)'s rule run by every follower alone (with a heartbeat of its own
    with ``heartbeat``)."""
    parallel = etsc_envs.make_parallel(CLUSTER, horizon_s=horizon_s)
    agent = parallel.possible_agents[0]
    rule = paper_of(CLUSTER).trigger(
        parallel.observation_space(agent),
        parallel.action_space(agent),
        parallel.unwrapped.agent_observation_names,
        **thresholds,
    )
    policy = rule if heartbeat is None else HeartbeatPolicy(rule, heartbeat)
    record, _ = run_parallel_episode(parallel, policy, seed=seed)
    return record


def assert_same_updates(info: dict, record: dict) -> None:
    """Every follower updates as often in the decision env's episode as in ``record``."""
    for name, agent in record["agents"].items():
        assert info["episode_metrics"]["agents"][name]["transmissions"] == agent["transmissions"]


def test_teammates_take_the_rule_until_they_follow_a_model():
    """Before ``follow_model`` every teammate takes the rule at its own thresholds (the first
    trigger action at factor 1): with the learner taking it too, each follower updates as eq.
    (15)'s rule at the paper's c does alone (20 s: the rule first fires after a few seconds)."""
    env = follower_env(horizon_s=20.0, factors=(1.5, 1.0))
    assert env.decisions.label(env.teammates.model.action) == "paper x1"
    info = episode_info(env, env.decisions.action("paper x1"), seed=2)
    record = rule_alone(20.0, seed=2, c=0.6)  # the paper's c
    assert record["transmissions"] > 0
    assert_same_updates(info, record)


def test_a_heartbeat_per_factor_is_each_followers_rule_with_its_own_heartbeat():
    """A set pairing each factor with its own heartbeat (``cap`` a list): the teammates'
    default decision is the paper's rule with its heartbeat, and with the learner taking it
    too each follower updates as eq. (15)'s rule with a heartbeat of its own does alone."""
    env = follower_env(horizon_s=20.0, factors=(1.0, 1.5), cap=[256, 1024], send_first=True)
    assert env.decisions.label(env.teammates.model.action) == "paper x1, heartbeat 256"
    info = episode_info(env, env.teammates.model.action, seed=2)
    record = rule_alone(20.0, seed=2, heartbeat=256)
    assert record["transmissions"] > len(record["agents"]) * 2000 // 256
    assert_same_updates(info, record)
    assert info["episode_metrics"]["mean_cost"] == record["mean_cost"]


def test_follower_env_passes_the_gymnasium_and_sb3_env_checkers():
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    check_env(follower_env(), skip_render_check=True)
    sb3_check_env(follower_env())


def test_bad_arguments_name_themselves():
    with pytest.raises(ValueError, match="env_id: 'etsc/ClusterContainmentCentral-v0'"):
        rule_follower("etsc/ClusterContainmentCentral-v0", factors=(1.0,))
    with pytest.raises(ValueError, match="gamma"):
        follower_env(gamma=1.5)
    env = follower_env()
    with pytest.raises(gym.error.ResetNeeded):
        env.step(0)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action must be one integer"):
        env.step(env.action_space.n)
