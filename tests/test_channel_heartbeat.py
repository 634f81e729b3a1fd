"""A rule with a heartbeat per channel (a maximum inter-event time per channel), as a trigger
and as the "paper × f, channel heartbeat H" decisions of a decision set, on the central form
of paper 001: each follower updates when eq. (15) fires for it or H instants after its own last
update, alone; the compiled intervals, the deployed policy and a reference that counts each
follower's instants itself take the same actions; bad arguments are named."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import etsc_envs  # noqa: F401  (registers the ids)
from etsc_envs.decisions import DecisionSet
from etsc_envs.evaluation.episodes import run_episode
from etsc_envs.evaluation.policy_specs import episode_setup
from etsc_envs.triggers import ClusterContainmentTrigger
from etsc_envs.triggers.base import (
    channel_heartbeat_trigger_class,
    instants_seconds,
    timed_rule_class,
)
from tests.rule_sets import deployed_policy, rule_set, rule_wrapper
from tests.test_decisions import RecordedActions, ScriptedModel

CENTRAL = "etsc/ClusterContainmentCentral-v0"
HORIZON_S = 20.0
HEARTBEAT = 150
"""Instants: shorter than eq. (15)'s first silences, so heartbeats and events interleave."""


class CountedHeartbeat:
    """The reference: eq. (15) per follower, and a follower that has gone ``heartbeat``
    instants without an update (counted here, from the episode's first instant) updates."""

    def __init__(self, env: gym.Env, heartbeat: int) -> None:
        self.rule = ClusterContainmentTrigger(
            env.observation_space, env.action_space, env.unwrapped.observation_names
        )
        self.heartbeat = heartbeat
        self.silent: np.ndarray | None = None

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        fires, _ = self.rule.predict(observation)
        if self.silent is None:
            self.silent = np.zeros(len(fires), dtype=np.int64)
        sent = np.asarray(fires, dtype=bool) | (self.silent >= self.heartbeat)
        self.silent = np.where(sent, 1, self.silent + 1)
        return sent.astype(np.int64), state


def central_env() -> RecordedActions:
    return RecordedActions(gym.make(CENTRAL, horizon_s=HORIZON_S, randomize=True))


def reference_actions(seed: int) -> np.ndarray:
    env = central_env()
    run_episode(env, CountedHeartbeat(env, HEARTBEAT), seed=seed)
    return np.array(env.actions)


def test_the_trigger_is_the_rule_with_each_followers_own_heartbeat():
    """Against the reference: every follower waits at most H instants between updates, a
    heartbeat sends its follower alone (some instants update some followers, not all), and the
    trigger updates where the reference does, instant for instant."""
    env = central_env()
    trigger = channel_heartbeat_trigger_class(ClusterContainmentTrigger)(
        env.observation_space,
        env.action_space,
        env.unwrapped.observation_names,
        heartbeat_s=instants_seconds(HEARTBEAT, env.unwrapped.params.sampling_period_s),
    )
    run_episode(env, trigger, seed=3)
    actions = np.array(env.actions)
    np.testing.assert_array_equal(actions, reference_actions(3))
    for follower in actions.T:
        updates = np.flatnonzero(follower)
        assert np.diff(np.concatenate([[0], updates])).max() <= HEARTBEAT
    partial = actions.any(axis=1) & ~actions.all(axis=1)
    assert partial.sum() > 5
    plain = central_env()
    run_episode(plain, ClusterContainmentTrigger(*spaces(plain)), seed=3)
    assert np.array(plain.actions).sum() < actions.sum()


def spaces(env: gym.Env) -> tuple:
    return env.observation_space, env.action_space, env.unwrapped.observation_names


def test_the_decision_runs_the_trigger_in_compiled_intervals_and_deployed():
    """Always choosing "paper x1, channel heartbeat 150" (with a plain rule action beside it)
    updates as the reference does, stepped through compiled intervals and deployed as a
    transmit/hold policy one instant at a time."""
    kwargs = {"max_exponent": 6, "factors": (0.5, 1.0), "channel_heartbeat": [None, 150]}
    base = central_env()
    wrapper = rule_wrapper(base, **kwargs)
    labels = [wrapper.decisions.label(len(wrapper.decisions.hold_indices) + i) for i in range(2)]
    assert labels == ["paper x0.5", "paper x1, channel heartbeat 150"]
    action = wrapper.decisions.action(labels[1])
    wrapper.reset(seed=5)
    done, intervals = False, 0
    while not done:
        _, _, terminated, truncated, _ = wrapper.step(action)
        done, intervals = terminated or truncated, intervals + 1
    reference = reference_actions(5)
    np.testing.assert_array_equal(np.array(base.actions), reference)
    assert intervals > 50
    deployed_env = central_env()
    policy = deployed_policy(
        ScriptedModel(wrapper.decisions.action_space.n, fixed=action), wrapper, deployed_env
    )
    run_episode(deployed_env, policy, seed=5)
    np.testing.assert_array_equal(np.array(deployed_env.actions), reference)


@pytest.mark.parametrize(
    ("heartbeat", "message"),
    [
        (0.0, "heartbeat_instants' must be a finite number >= 1"),
        (-1.0, "heartbeat_instants' must be a finite number >= 1"),
    ],
)
def test_a_decision_set_refuses_a_bad_channel_heartbeat(heartbeat, message):
    action = {"kind": "trigger", "point": {"heartbeat_instants": heartbeat}}
    with pytest.raises(ValueError, match=rf"actions\[0\]: .*{message}"):
        DecisionSet.from_json({"actions": [action]}, CENTRAL)


def test_a_channel_heartbeat_trigger_names_its_bad_arguments():
    env = central_env()
    heartbeat_class = channel_heartbeat_trigger_class(ClusterContainmentTrigger)
    with pytest.raises(ValueError, match="heartbeat_s must be a finite number > 0"):
        heartbeat_class(*spaces(env), heartbeat_s=0.0)
    with pytest.raises(TypeError, match="heartbeat_s"):
        heartbeat_class(*spaces(env))
    with pytest.raises(ValueError, match="floor_s and heartbeat_s"):
        timed_rule_class(ClusterContainmentTrigger, floor_s=0.1, heartbeat_s=0.1)


def test_channel_heartbeats_survive_a_save_and_a_load(tmp_path):
    decisions = rule_set(CENTRAL, factors=(0.5, 1.0), channel_heartbeat=[None, 256])
    decisions.save(tmp_path / "model.zip")
    loaded = DecisionSet.load(tmp_path / "model.zip")
    beats = [loaded.actions[i].point.heartbeat_instants for i in loaded.trigger_indices]
    assert loaded == decisions and beats == [math.inf, 256]


@pytest.mark.parametrize("heartbeat", [0, 2.5, True])
def test_the_stand_alone_policy_names_a_bad_channel_heartbeat(heartbeat):
    setup = episode_setup(CENTRAL, {"horizon_s": 1.0})
    with pytest.raises(ValueError, match="--policy-arg channel_heartbeat must be an integer"):
        setup.make_policy("paper", {"channel_heartbeat": heartbeat})
    setup.env.close()
