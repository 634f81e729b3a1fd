"""A rule with a floor (a minimum inter-event time: the rule gating a clock), as a trigger and
as the "paper × f, floor F" decisions of a decision set: it never transmits sooner than the
floor, transmits only where the rule fires, equals the stand-alone floored trigger instant for
instant, and refuses bad arguments."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import etsc_envs  # noqa: F401  (registers the ids)
from etsc_envs.decisions import DecisionSet
from etsc_envs.evaluation.episodes import run_episode
from etsc_envs.evaluation.policy_specs import make_policy
from etsc_envs.triggers import OrbitAttitudeTrigger
from etsc_envs.triggers.base import floored_trigger_class, instants_seconds
from tests.rule_sets import rule_set, rule_wrapper
from tests.test_decisions import RecordedActions

ORBIT = "etsc/OrbitAttitudeTracking-v0"
FORMATION = "etsc/InnerFormation-v0"
SAMPLING_PERIOD_S = 1e-3
HORIZON_S = 1.5
GAMMAS = {"gamma1": 0.004, "gamma2": 0.012}
"""Eq. (21) at four times the paper's absolute thresholds."""


def floored(env: gym.Env, floor: int, **keywords) -> OrbitAttitudeTrigger:
    trigger_class = floored_trigger_class(OrbitAttitudeTrigger)
    return trigger_class(
        env.observation_space,
        env.action_space,
        env.unwrapped.observation_names,
        floor_s=instants_seconds(floor, SAMPLING_PERIOD_S),
        **keywords,
    )


def transmission_instants(actions: list[np.ndarray]) -> np.ndarray:
    return np.flatnonzero(np.array(actions).reshape(len(actions), -1).any(axis=1))


@pytest.mark.parametrize("floor", [16, 64])
def test_a_floored_rule_waits_the_floor_and_fires_only_with_the_rule(floor):
    """Consecutive transmissions are at least ``floor`` instants apart, and at each one (past
    the floor) the rule alone would fire on that observation."""
    env = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    trigger = floored(env, floor, **GAMMAS)
    rule = OrbitAttitudeTrigger(
        env.observation_space, env.action_space, env.unwrapped.observation_names, **GAMMAS
    )
    observations = []
    policy = ObservationLog(trigger, observations)
    run_episode(env, policy, seed=2)
    instants = transmission_instants(env.actions)
    assert len(instants) > 5
    assert np.diff(instants).min() >= floor
    fired, _ = rule.predict(np.array(observations)[instants])
    assert fired.all()
    held = np.setdiff1d(np.arange(len(observations)), instants)
    early = held[held < instants[0]]
    assert early.size >= floor - 1


def test_a_floored_rule_is_the_clock_where_the_rule_always_fires():
    """With thresholds so small that eq. (21) fires at every instant the floor is a clock."""
    env = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    run_episode(env, floored(env, 32, gamma1=1e-12, gamma2=1e-12, a1=1e-9, a2=1e-9), seed=2)
    instants = transmission_instants(env.actions)
    np.testing.assert_array_equal(np.diff(instants), 32)


@pytest.mark.parametrize("floor", [48, [16, 48], (48, 16)])
def test_the_floor_decision_is_the_floored_rule_sending_at_its_decisions(floor):
    """Always choosing "paper x4, floor 48" (the set's one floor, or the floor paired with x4)
    transmits at the decision instant and then exactly where the stand-alone floored rule does
    (through compiled intervals)."""
    kwargs = {"max_exponent": 8, "factors": (1.0, 4.0), "floor": floor}
    base = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    wrapper = rule_wrapper(base, **kwargs)
    label = "paper x4, floor 48"
    if floor == (48, 16):
        with pytest.raises(ValueError, match=label):
            wrapper.decisions.action(label)
        return
    action = wrapper.decisions.action(label)
    wrapper.reset(seed=2)
    lengths, done = [], False
    while not done:
        _, _, terminated, truncated, info = wrapper.step(action)
        lengths.append(info["elapsed_steps"])
        done = terminated or truncated
    reference = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    run_episode(reference, ObservationLog(floored(reference, 48, **GAMMAS), [], first=True), 2)
    np.testing.assert_array_equal(np.array(base.actions), np.array(reference.actions))
    assert min(lengths[:-1]) >= 48 and len(set(lengths)) > 1


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"floor": 0}, "floor must be an integer >= 1"),
        ({"floor": 2.5}, "floor must be an integer >= 1"),
        ({"floor": 8, "channel_heartbeat": 64}, "channel_heartbeat or floor, not both"),
    ],
)
def test_the_command_line_refuses_a_bad_floor(arguments, message):
    env = gym.make(ORBIT, horizon_s=0.05)
    with pytest.raises(ValueError, match=message):
        make_policy("paper", env, arguments, ORBIT)


@pytest.mark.parametrize(
    ("action", "message"),
    [
        ({"point": {"floor_instants": -1.0}}, "floor_instants' must be a finite number >= 0"),
    ],
)
def test_a_decision_set_refuses_a_bad_floor(action, message):
    block = {"actions": [{"kind": "hold", "instants": 1}, {"kind": "trigger", **action}]}
    with pytest.raises(ValueError, match=rf"actions\[1\]: .*{message}"):
        DecisionSet.from_json(block, ORBIT)


def test_a_shielded_set_refuses_a_floored_action():
    with pytest.raises(ValueError, match="shield_multiple: the shield bounds"):
        rule_set(FORMATION, factors=(1.0,), floor=8, shield_multiple=2.0)


def test_the_floor_names_its_actions_and_bad_floors_name_themselves():
    decisions = rule_set(ORBIT, factors=(4.0,), floor=64)
    assert decisions.label(len(decisions.hold_indices)) == "paper x4, floor 64"
    paired = rule_set(ORBIT, factors=(0.3, 1.0), floor=[2, 8])
    labels = [paired.label(len(paired.hold_indices) + index) for index in range(2)]
    assert labels == ["paper x0.3, floor 2", "paper x1, floor 8"]
    env = gym.make(ORBIT, horizon_s=0.05)
    with pytest.raises(ValueError, match="floor_s"):
        floored_trigger_class(OrbitAttitudeTrigger)(
            env.observation_space, env.action_space, env.unwrapped.observation_names, floor_s=0.0
        )


class ObservationLog:
    """A policy that keeps every observation it is asked about; with ``first`` it transmits at
    the episode's first instant too (as a decision instant does)."""

    def __init__(self, trigger, observations: list, first: bool = False) -> None:
        self.trigger = trigger
        self.observations = observations
        self.first = first

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        self.observations.append(np.asarray(observation).copy())
        action, state = self.trigger.predict(observation, state, episode_start, deterministic)
        if self.first and len(self.observations) == 1:
            action = np.ones_like(action)
        return action, state


def test_floors_per_factor_survive_a_save_and_a_load(tmp_path):
    decisions = rule_set(ORBIT, factors=(0.3, 1.0), floor=[2, 8])
    decisions.save(tmp_path / "model.zip")
    loaded = DecisionSet.load(tmp_path / "model.zip")
    floors = [loaded.actions[i].point.floor_instants for i in loaded.trigger_indices]
    assert loaded == decisions and floors == [2, 8]
