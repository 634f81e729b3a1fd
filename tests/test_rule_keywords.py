"""A decision set's ``rule_keywords``: keywords of the rule's trigger that every rule action
shares and the factors leave alone (for 000, eq. (21)'s relative thresholds a1, a2). They reach
every rule action, the stand-alone form of a plain rule action and a saved set, and bad ones
are refused by name."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import etsc_envs  # noqa: F401  (registers the ids)
from agents.train.config import config_from_dict
from agents.train.decision_selection import stand_alone_spec
from etsc_envs.decisions import DecisionSet, decision_set_v1, read_decision_set
from etsc_envs.evaluation.episodes import run_episode
from etsc_envs.evaluation.policy_specs import make_policy
from etsc_envs.triggers import OrbitAttitudeTrigger
from etsc_envs.triggers.family import scaled_thresholds
from tests.test_decision_selection import BASE_CONFIG
from tests.test_decisions import RecordedActions
from tests.test_rule_floor import (
    GAMMAS,
    HORIZON_S,
    ORBIT,
    SAMPLING_PERIOD_S,
    ObservationLog,
    floored,
)
from tests.v1_decisions import v1_block, v1_wrapper

RELATIVE = {"a1": 2.4, "a2": 3.2}
"""Eq. (21)'s a1, a2 at four times the paper's (Theorem 2 needs a1 < 3.2, a2 < 3.6)."""


def floor_decision_actions(floor: int = 48, **decision_keywords) -> np.ndarray:
    """The transmit/hold actions of always choosing "paper x4, floor ``floor``"."""
    base = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    wrapper = v1_wrapper(
        base, max_exponent=8, factors=(4.0,), rule_floor=floor, **decision_keywords
    )
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
    ``rule_keywords`` in a set whose rule interval cap is 128 — the floor and the cap each end
    some of its intervals: the command reproduces a floor decision without a model."""
    decided = floor_decision_actions(80, rule_keywords=RELATIVE, rule_cap=128)
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
    with_keywords = floor_decision_actions(rule_keywords=RELATIVE)
    reference = RecordedActions(gym.make(ORBIT, horizon_s=HORIZON_S, randomize=True))
    trigger = floored(reference, 48, **GAMMAS, **RELATIVE)
    run_episode(reference, ObservationLog(trigger, [], first=True), 2)
    np.testing.assert_array_equal(with_keywords, np.array(reference.actions))
    without = floor_decision_actions()
    assert with_keywords.sum() != without.sum()


def test_a_plain_rule_actions_stand_alone_form_carries_the_keywords():
    decisions = decision_set_v1(ORBIT, max_exponent=3, factors=(2.0,), rule_keywords=RELATIVE)
    spec = stand_alone_spec(decisions, decisions.action("paper x2"))
    assert spec == ("paper", {"gamma1": 0.002, "gamma2": 0.006, **RELATIVE})


def test_keywords_survive_a_save_and_a_load(tmp_path):
    decisions = decision_set_v1(
        ORBIT,
        factors=(4.0,),
        rule_floor=64,
        sampling_period_s=SAMPLING_PERIOD_S,
        rule_keywords={"a1": 2, "a2": 3.2},
    )
    action = decisions.actions[decisions.trigger_indices[0]]
    thresholds = scaled_thresholds(OrbitAttitudeTrigger, action.point.factors)
    assert (thresholds["a1"], thresholds["a2"]) == (2.0, 3.2)
    decisions.save(tmp_path / "model.zip")
    assert DecisionSet.load(tmp_path / "model.zip") == decisions


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        ({"b1": 1.0}, r"rule_keywords: \['b1'\] are not keywords .* allowed: \['a1', 'a2'\]"),
        ({"gamma1": 0.01}, r"rule_keywords: \['gamma1'\] are not keywords"),
        ({"a1": float("nan")}, "rule_keywords: a1 must be a finite number"),
        ({"a1": "big"}, "rule_keywords: a1 must be a finite number"),
        ({"a1": True}, "rule_keywords: a1 must be a finite number"),
        ([2.4, 3.2], "rule_keywords must map keyword names to numbers"),
    ],
)
def test_a_decision_set_refuses_bad_keywords(keywords, message):
    with pytest.raises(ValueError, match=message):
        decision_set_v1(ORBIT, factors=(4.0,), rule_keywords=keywords)


def test_a_keyword_outside_the_triggers_range_names_the_keywords():
    env = gym.make(ORBIT, horizon_s=0.05)
    with pytest.raises(ValueError, match=r"rule_keywords \{'a1': -1.0\}: a1 must be"):
        v1_wrapper(env, factors=(4.0,), rule_keywords={"a1": -1.0})


def test_a_training_config_takes_the_keywords(tmp_path):
    """(Bad keywords in a config: ``tests/test_decisions.py``.)"""
    decisions = v1_block(ORBIT, factors=[4.0], rule_floor=8, rule_keywords=RELATIVE)
    config = {**BASE_CONFIG, "env_id": ORBIT, "env_kwargs": {"horizon_s": 0.05}}
    config.update(out_dir=str(tmp_path / "run"), decisions=decisions)
    decisions = read_decision_set(config_from_dict(config).decisions)
    action = decisions.actions[decisions.trigger_indices[0]]
    thresholds = scaled_thresholds(OrbitAttitudeTrigger, action.point.factors)
    assert {name: thresholds[name] for name in RELATIVE} == RELATIVE
