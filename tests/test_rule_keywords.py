"""Thresholds of the rule's trigger that a rule action's "x f" leaves alone (for 000, eq.
(21)'s relative thresholds a1, a2), set by the action's point through factors of their own.
They reach the floored rule, a saved set and a training config, and bad ones are refused by
name."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import etsc_envs  # noqa: F401  (registers the ids)
from agents.train.config import config_from_dict
from etsc_envs.decisions import DecisionSet
from etsc_envs.evaluation.episodes import run_episode
from etsc_envs.evaluation.policy_specs import make_policy
from etsc_envs.triggers import OrbitAttitudeTrigger
from etsc_envs.triggers.family import scaled_thresholds
from tests.rule_sets import BASE_CONFIG, rule_block, rule_set, rule_wrapper
from tests.test_decisions import RecordedActions
from tests.test_rule_floor import (
    GAMMAS,
    HORIZON_S,
    ORBIT,
    ObservationLog,
    floored,
)

RELATIVE = {"a1": 2.4, "a2": 3.2}
"""Eq. (21)'s a1, a2 at four times the paper's (Theorem 2 needs a1 < 3.2, a2 < 3.6)."""


def floor_decision_actions(floor: int = 48, **decision_keywords) -> np.ndarray:
    """The transmit/hold actions of always choosing "paper x4, floor ``floor``"."""
    base = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    wrapper = rule_wrapper(base, max_exponent=8, factors=(4.0,), floor=floor, **decision_keywords)
    action = wrapper.decisions.action(f"paper x4, floor {floor}")
    wrapper.reset(seed=2)
    done = False
    while not done:
        _, _, terminated, truncated, _ = wrapper.step(action)
        done = terminated or truncated
    return np.array(base.actions)


def test_the_command_lines_floored_rule_with_a_heartbeat_is_the_floor_decision():
    """``--policy paper --policy-arg floor=80 --policy-arg heartbeat=128`` with a1, a2 and the
    thresholds x4 takes exactly the actions of always choosing "paper x4, floor 80" with those
    ``thresholds`` in a set whose rule interval cap is 128 — the floor and the cap each end
    some of its intervals: the command reproduces a floor decision without a model."""
    decided = floor_decision_actions(80, thresholds=RELATIVE, cap=128)
    reference = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    arguments = {**GAMMAS, **RELATIVE, "floor": 80, "heartbeat": 128}
    run_episode(reference, make_policy("paper", reference, arguments, ORBIT), seed=2)
    np.testing.assert_array_equal(decided, np.array(reference.actions))
    intervals = np.diff(np.flatnonzero(decided))
    assert intervals.min() == 80 and intervals.max() == 128 and len(set(intervals)) > 2


def test_the_keywords_reach_the_floored_rule_and_change_its_transmissions():
    """Always choosing "paper x4, floor 48" with a1, a2 given transmits exactly where the
    stand-alone floored rule with those a1, a2 does (sending at the first instant, as a
    decision instant does), and not where the set without them does."""
    with_keywords = floor_decision_actions(thresholds=RELATIVE)
    reference = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    trigger = floored(reference, 48, **GAMMAS, **RELATIVE)
    run_episode(reference, ObservationLog(trigger, [], first=True), 2)
    np.testing.assert_array_equal(with_keywords, np.array(reference.actions))
    without = floor_decision_actions()
    assert with_keywords.sum() != without.sum()


def test_keywords_survive_a_save_and_a_load(tmp_path):
    decisions = rule_set(
        ORBIT,
        factors=(4.0,),
        floor=64,
        thresholds={"a1": 2, "a2": 3.2},
    )
    action = decisions.actions[decisions.trigger_indices[0]]
    thresholds = scaled_thresholds(OrbitAttitudeTrigger, action.point.factors)
    assert (thresholds["a1"], thresholds["a2"]) == (2.0, 3.2)
    decisions.save(tmp_path / "model.zip")
    assert DecisionSet.load(tmp_path / "model.zip") == decisions


def test_a_threshold_outside_the_triggers_range_names_its_factor():
    block = {"actions": [{"kind": "trigger", "point": {"factors": {"a1": -1.0}}}]}
    with pytest.raises(
        ValueError, match=r"actions\[0\]: key 'point\.factors\.a1' must be a finite number > 0"
    ):
        DecisionSet.from_json(block, ORBIT)
    with pytest.raises(ValueError, match=r"factors\.a1 must be"):
        rule_wrapper(gym.make(ORBIT, horizon_s=0.05), factors=(4.0,), thresholds={"a1": -1.0})


def test_a_training_config_takes_the_keywords(tmp_path):
    """(Bad keywords in a config: ``tests/test_decisions.py``.)"""
    decisions = rule_block(ORBIT, factors=[4.0], floor=8, thresholds=RELATIVE)
    config = {**BASE_CONFIG, "env_id": ORBIT, "env_kwargs": {"horizon_s": 0.05}}
    config.update(out_dir=str(tmp_path / "run"), decisions=decisions)
    decisions = DecisionSet.from_json(config_from_dict(config).decisions)
    action = decisions.actions[decisions.trigger_indices[0]]
    thresholds = scaled_thresholds(OrbitAttitudeTrigger, action.point.factors)
    assert {name: thresholds[name] for name in RELATIVE} == RELATIVE
