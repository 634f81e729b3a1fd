"""A decision set's own hold lengths: holds of any length, such as the clocks every 5, 10 and
20 instants of a periodic sweep, in place of 1, 2, 4, ..., 2^k. Each hold is its clock, the
longest hold caps the rule's intervals, and the lengths survive a save, a load and a training
config."""

from __future__ import annotations

import numpy as np
import pytest

from agents.train.config import config_from_dict
from etsc_envs.decisions import DecisionSet
from etsc_envs.triggers import PeriodicPolicy
from tests.rule_sets import BASE_CONFIG, rule_set
from tests.test_decisions import (
    ATTITUDE,
    ScriptedModel,
    assert_same,
    policy_actions,
    recorded,
    wrapper_actions,
)

HOLDS = (2, 5, 10, 20)


def test_the_holds_are_the_actions_and_the_rule_comes_after_them():
    decisions = rule_set(ATTITUDE, factors=(1.0, 4.0), holds=list(HOLDS))
    assert tuple(decisions.actions[i].instants for i in decisions.hold_indices) == HOLDS
    assert len(decisions.hold_indices) == 4 and decisions.action_space.n == 6
    labels = [decisions.label(action) for action in range(6)]
    assert labels == ["hold 2", "hold 5", "hold 10", "hold 20", "paper x1", "paper x4"]
    assert tuple(decisions.actions[i].cap for i in decisions.trigger_indices) == (20, 20)


@pytest.mark.parametrize("hold", [5, 10])
def test_a_hold_of_any_length_is_its_clock(hold):
    env = recorded(ATTITUDE)
    clock = PeriodicPolicy(env.observation_space, env.action_space, every=hold)
    action = HOLDS.index(hold)
    actions, infos = wrapper_actions(ATTITUDE, ScriptedModel(0, fixed=action), holds=HOLDS)
    assert_same(actions, policy_actions(ATTITUDE, clock))
    assert {info["elapsed_steps"] for info in infos[:-1]} == {hold}
    assert np.array(actions).sum() > 5


def test_the_holds_survive_a_save_a_load_and_a_config(tmp_path):
    decisions = rule_set(ATTITUDE, factors=(1.0,), holds=HOLDS)
    decisions.save(tmp_path / "model.zip")
    assert DecisionSet.load(tmp_path / "model.zip") == decisions
    config = {**BASE_CONFIG, "out_dir": str(tmp_path / "run")}
    holds = [{"kind": "hold", "instants": instants} for instants in HOLDS]
    config["decisions"] = {"actions": [*holds, {"kind": "trigger", "cap": HOLDS[-1]}]}
    config = config_from_dict(config)
    assert [action["instants"] for action in config.decisions["actions"][:4]] == list(HOLDS)
