"""Decision sets as data (:mod:`etsc_envs.decisions.actions`): the sets of the self-triggered
models of earlier rounds (``decision_sets_expected.json``) read with their labels, round-trip
through the JSON form, and each action takes the decisions it took before the sets became data
(transmissions and mean cost of always taking it, recorded by the code of that time); a
learned trigger's point is a trigger action; bad actions name their field."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import etsc_envs
from etsc_envs.decisions import (
    DecisionSet,
    FixedDecision,
    Hold,
    SelfTriggeredPolicy,
    TriggerAction,
)
from etsc_envs.evaluation.batch import run_batch
from etsc_envs.triggers.family import LearnedTrigger

ROOT = Path(__file__).resolve().parent.parent
EXPECTED = json.loads((Path(__file__).parent / "decision_sets_expected.json").read_text())
"""Per earlier model: its decision set, and label → [transmissions, mean cost] of always
taking the action, seed 11, randomized, over :data:`HORIZON_S` (the records of the code that
trained it)."""

HORIZON_S = {
    "etsc/AttitudeTracking-v0": 1.0,
    "etsc/InnerFormation-v0": 1.0,
    "etsc/OrbitAttitudeTracking-v0": 1.0,
    "etsc/ClusterContainmentCentral-v0": 20.0,
    "etsc/ClusterContainment-v0": 20.0,
    "etsc/AsteroidOrbitKeeping-v0": 1000.0,
}


def _read(name: str) -> DecisionSet:
    return DecisionSet.from_json(EXPECTED[name]["decisions"])


def _records(decisions: DecisionSet, actions: list[int]) -> dict[str, list]:
    env_id = decisions.env_id
    env_args = {"horizon_s": HORIZON_S[env_id], "randomize": True}
    if env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        env = etsc_envs.make_parallel(env_id)
    else:
        env = gym.make(env_id)
    out = {}
    for action in actions:
        policy = SelfTriggeredPolicy.for_env(FixedDecision(action), decisions, env)
        record = run_batch(env_id, policy, [11], env_args)[0]
        out[decisions.label(action)] = [int(record["transmissions"]), float(record["mean_cost"])]
    return out


def _assert_same_decisions(records: dict[str, list], expected: dict[str, list]) -> None:
    """The same transmissions, and the same mean cost to 1e-12 relative. The compiled loop and
    NumPy's float64 kernels are chosen for the host CPU's instruction set, so 003's costs
    differ in the last bits between machines (seen: 9.506865225599297 against ...304); a
    changed decision moves the count, and a changed law moves the cost far past 1e-12."""
    assert list(records) == list(expected)
    for label, (sent, cost) in expected.items():
        assert records[label][0] == sent, label
        assert records[label][1] == pytest.approx(cost, rel=1e-12, abs=0.0), label


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_a_set_reads_with_its_labels_and_round_trips(name, tmp_path):
    decisions = _read(name)
    assert decisions.labels == list(EXPECTED[name]["records"])
    data = json.loads(json.dumps(decisions.to_json()))
    assert data["format"] == "etsc-envs/decision-set" and data["version"] == 2
    assert DecisionSet.from_json(data) == decisions
    decisions.save(tmp_path / "model.zip")
    assert DecisionSet.load(tmp_path / "model.zip") == decisions


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_a_shipped_sets_last_trigger_and_longest_hold_take_the_old_decisions(name):
    decisions = _read(name)
    chosen = [decisions.hold_indices[-1], decisions.trigger_indices[-1]]
    expected = {decisions.label(a): EXPECTED[name]["records"][decisions.label(a)] for a in chosen}
    _assert_same_decisions(_records(decisions, chosen), expected)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_every_action_of_a_shipped_set_takes_the_old_decisions(name):
    decisions = _read(name)
    records = _records(decisions, list(range(decisions.n_actions)))
    _assert_same_decisions(records, EXPECTED[name]["records"])


def test_a_learned_triggers_point_is_a_trigger_action():
    """Always choosing the action at the point of ``models/AttitudeTracking-v0_learned.json``
    (not sent first, no cap) transmits where the learned trigger alone does."""
    learned = LearnedTrigger.load(ROOT / "models" / "AttitudeTracking-v0_learned.json")
    assert not learned.keywords
    action = TriggerAction(learned.point)
    decisions = DecisionSet(learned.env_id, (Hold(1), action))
    assert DecisionSet.from_json(json.loads(json.dumps(decisions.to_json()))) == decisions
    env = gym.make(learned.env_id, horizon_s=2.0, randomize=True)
    alone = learned.policy_for(env)
    deployed = SelfTriggeredPolicy.for_env(FixedDecision(1), decisions, env)
    obs, _ = env.reset(seed=4)
    state, sent, done = None, 0, False
    while not done:
        action_bit, state = deployed.predict(obs, state)
        assert np.array_equal(action_bit, alone.predict(obs)[0])
        sent += int(np.sum(action_bit))
        obs, _, terminated, truncated, _ = env.step(action_bit)
        done = terminated or truncated
    assert sent > 0


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"kind": "hold", "instants": 0}, "hold instants must be an integer in 1"),
        ({"kind": "hold"}, "missing"),
        ({"kind": "sometimes"}, "kind must be one of"),
        ({"kind": "trigger", "cap": 2.5}, "cap must be an integer"),
        ({"kind": "trigger", "send_first": "yes"}, "send_first must be true or false"),
        ({"kind": "trigger", "rule": "clock"}, "rule must be one of"),
        ({"kind": "trigger", "point": {"factors": {"pi": 2.0}}}, "allowed"),
        ({"kind": "trigger", "keywords": {"psi": 1.0}}, r"got unknown \['keywords'\]"),
    ],
)
def test_a_bad_action_names_its_field(data, message):
    block = {"actions": [{"kind": "hold", "instants": 1}, data]}
    with pytest.raises(ValueError, match=message):
        DecisionSet.from_json(block, "etsc/AttitudeTracking-v0")


def test_a_file_without_the_format_names_its_keys():
    """A decision file of the keyword form that preceded the actions (``max_exponent``,
    ``factors``, ...) is refused by its keys, not read as another set."""
    data = {"env_id": "etsc/AttitudeTracking-v0", "max_exponent": 8, "factors": [2.0]}
    with pytest.raises(ValueError, match=r"unknown keys \['factors', 'max_exponent'\]"):
        DecisionSet.from_json(data)


def test_a_set_refuses_a_shield_where_there_is_none():
    with pytest.raises(ValueError, match="shield_multiple: no shield"):
        DecisionSet("etsc/AttitudeTracking-v0", (Hold(1),), shield_multiple=2.0)
