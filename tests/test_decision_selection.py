"""Choosing the decision a self-triggered run starts from, per transmission penalty
(``start_from.decision: best``, :mod:`agents.train.decision_selection`)."""

from __future__ import annotations

import json

import pytest
import yaml

import etsc_envs  # noqa: F401  (registers the ids)
from agents.train.config import config_from_dict
from agents.train.decision_selection import (
    constant_decision_policy,
    select_decision,
    stand_alone_spec,
)
from agents.train.training import main
from agents.train.validation_callback import deployment, set_summary
from etsc_envs.decisions import FixedDecision, SelfTriggeredPolicy, decision_set_v1
from etsc_envs.evaluation.batch import run_batch
from etsc_envs.evaluation.policy_specs import episode_setup
from etsc_envs.protocol import scenario_set
from etsc_envs.triggers.base import RuleTrigger
from tests.v1_decisions import v1_block

ATTITUDE = "etsc/AttitudeTracking-v0"
CANDIDATES = ["hold 1", "hold 4", "paper x1", "paper x4"]
SHORT = {"horizon_s": 0.3}
SET_SIZE = 2


def selection_at(penalty: float) -> dict:
    decisions = decision_set_v1(ATTITUDE, max_exponent=3, factors=(1.0, 4.0))
    kwargs = {**SHORT, "randomize": True, "transmission_penalty": penalty}
    return select_decision(ATTITUDE, kwargs, decisions, SET_SIZE, CANDIDATES)


def run_stand_alone(spec: str, policy_args: dict, penalty: float) -> dict:
    """The set summary of a stand-alone policy on the same validation scenarios."""
    scenarios = scenario_set("validation", SET_SIZE)
    kwargs = scenarios.env_kwargs({**SHORT, "transmission_penalty": penalty})
    setup = episode_setup(ATTITUDE, kwargs)
    policy = setup.make_policy(spec, policy_args)
    setup.env.close()
    return set_summary(run_batch(ATTITUDE, policy, scenarios.seeds, kwargs))


def test_each_candidate_is_scored_as_its_baseline_and_the_best_return_wins():
    """ "hold 4" always taken is the clock every 4 instants, "paper x1" the paper's rule (after
    the transmission at the episode's start that every hold sends): their summaries are those
    baselines' on the same validation scenarios, and the chosen label has the highest return."""
    penalty = 0.1
    selection = selection_at(penalty)
    summaries = selection["candidates"]
    assert list(summaries) == CANDIDATES
    clock = run_stand_alone("periodic", {"every": 4}, penalty)
    for key in ("mean_cost", "transmissions", "return"):
        assert summaries["hold 4"][key] == pytest.approx(clock[key], rel=1e-12)
    paper = run_stand_alone("paper", {}, penalty)
    assert summaries["paper x1"]["mean_cost"] == pytest.approx(paper["mean_cost"], rel=1e-9)
    assert abs(summaries["paper x1"]["transmissions"] - paper["transmissions"]) <= 1
    returns = {label: summary["return"] for label, summary in summaries.items()}
    assert returns[selection["chosen"]] == max(returns.values())
    assert selection["scenarios"] == scenario_set("validation", SET_SIZE).describe()


def test_the_choice_moves_to_sparser_decisions_as_transmissions_get_dearer():
    """With no price on a transmission the most accurate candidate wins, with a prohibitive
    one the sparsest."""
    free = selection_at(0.0)
    dear = selection_at(1.0e6)
    costs = {label: summary["mean_cost"] for label, summary in free["candidates"].items()}
    sent = {label: summary["transmissions"] for label, summary in dear["candidates"].items()}
    assert free["chosen"] == min(costs, key=costs.get)
    assert dear["chosen"] == min(sent, key=sent.get)
    assert free["chosen"] != dear["chosen"]
    assert dear["transmission_penalty"] == 1.0e6


def test_runs_that_differ_in_lambda_alone_share_the_candidates_runs(tmp_path):
    """The first selection writes the unpriced runs into the cache; a selection at another λ
    reads them (a changed file shows it was read) and prices them at its own λ, which gives
    what running at that λ gives."""
    decisions = decision_set_v1(ATTITUDE, max_exponent=3, factors=(1.0, 4.0))
    cache = tmp_path / "cache"

    def select(penalty: float) -> dict:
        kwargs = {**SHORT, "transmission_penalty": penalty}
        return select_decision(ATTITUDE, kwargs, decisions, SET_SIZE, CANDIDATES, cache)

    first = select(0.1)
    (written,) = cache.iterdir()
    assert first == selection_at(0.1)
    assert select(1.0e6) == selection_at(1.0e6)
    record = json.loads(written.read_text(encoding="utf-8"))
    record["candidates"]["hold 4"]["mean_cost"] = -1.0
    written.write_text(json.dumps(record), encoding="utf-8")
    assert select(3.0)["candidates"]["hold 4"]["mean_cost"] == -1.0
    other = decision_set_v1(ATTITUDE, max_exponent=2, factors=(1.0, 4.0))
    select_decision(ATTITUDE, SHORT, other, SET_SIZE, CANDIDATES, cache)
    assert len(list(cache.iterdir())) == 2  # another decision set: runs of its own


def test_an_unknown_candidate_is_refused_by_name():
    decisions = decision_set_v1(ATTITUDE, max_exponent=3)
    with pytest.raises(ValueError, match=r"start_from\.candidates: 'hold 64'"):
        select_decision(ATTITUDE, SHORT, decisions, SET_SIZE, ["hold 1", "hold 64"])


BASE_CONFIG = {
    "env_id": ATTITUDE,
    "env_kwargs": SHORT,
    "algorithm": "PPO",
    "policy": "MlpPolicy",
    "total_timesteps": 32,
    "decisions": v1_block(ATTITUDE, max_exponent=3, factors=[1.0, 4.0]),
}


@pytest.mark.parametrize(
    ("start_from", "message"),
    [
        (
            {"decision": "hold 1", "candidates": ["hold 1"]},
            "'start_from.candidates' needs 'start_from.decision: best'",
        ),
        (
            {"decision": "best", "candidates": []},
            "'start_from.candidates' must be a non-empty list",
        ),
        (
            {"decision": "best", "candidates": ["hold 64"]},
            "'start_from.candidates': 'hold 64' is not a decision of this set",
        ),
        (
            {"decision": "hold 1", "selection_cache": "cache"},
            "'start_from.selection_cache' needs 'start_from.decision: best'",
        ),
    ],
)
def test_the_config_checks_the_candidates(tmp_path, start_from, message):
    with pytest.raises(ValueError, match=message):
        config_from_dict(
            {
                **BASE_CONFIG,
                "out_dir": str(tmp_path / "run"),
                "start_from": {"steps": 64, **start_from},
            }
        )


def test_a_best_run_starts_from_the_chosen_decision_and_resumes_with_it(tmp_path):
    """``start_from.decision: best`` records the choice beside the model, clones and pins that
    decision, and a resumed run reads it back instead of choosing again."""
    out_dir = tmp_path / "run"
    config = {
        **BASE_CONFIG,
        "env_kwargs": {**SHORT, "transmission_penalty": 1.0e6},
        "hyperparameters": {"n_steps": 16, "batch_size": 16, "n_epochs": 1, "gamma": 0.999},
        "total_timesteps": 32,
        "n_envs": 1,
        "out_dir": str(out_dir),
        "start_from": {
            "decision": "best",
            "steps": 64,
            "epochs": 5,
            "pinned_probability": 0.9,
            "candidates": CANDIDATES,
            "selection_cache": str(tmp_path / "cache"),
        },
        "evaluation_scenarios": SET_SIZE,
        "checkpoint_every": 16,
        "tensorboard": False,
    }
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config), encoding="utf-8")
    assert main(["--config", str(path), "--timesteps", "16"]) == 0
    selection = json.loads((out_dir / "decision_selection.json").read_text(encoding="utf-8"))
    assert selection == json.loads(json.dumps(selection_at(1.0e6)))
    assert len(list((tmp_path / "cache").iterdir())) == 1
    summary = json.loads((out_dir / "train_summary.json").read_text(encoding="utf-8"))
    assert summary["imitation"]["decision"] == f"{selection['chosen']}, pinned at probability 0.9"
    written = yaml.safe_load((out_dir / "config.yaml").read_text())
    assert written["start_from"]["decision"] == "best"
    (out_dir / "decision_selection.json").write_text(json.dumps({"chosen": "hold 1"}))
    assert main(["--config", str(path), "--resume"]) == 0
    resumed = json.loads((out_dir / "train_summary.json").read_text(encoding="utf-8"))
    assert resumed["resumed_from"] is not None and resumed["total_timesteps"] >= 32
    (out_dir / "decision_selection.json").unlink()
    with pytest.raises(SystemExit):
        main(["--config", str(path), "--resume"])


@pytest.mark.parametrize(
    ("env_id", "env_kwargs", "decision_keywords", "labels"),
    [
        (ATTITUDE, SHORT, {"max_exponent": 3, "factors": (2.0,)}, ["hold 4", "paper x2"]),
        (
            "etsc/InnerFormation-v0",
            {"horizon_s": 0.5},
            {"max_exponent": 3, "rule": "error_time", "factors": (2.0,)},
            ["hold 8", "error_time x2"],
        ),
        (
            "etsc/ClusterContainmentCentral-v0",
            {"horizon_s": 20.0},
            {"max_exponent": 5, "factors": (1.5,)},
            ["hold 16", "paper x1.5"],
        ),
        (
            "etsc/ClusterContainment-v0",
            {"horizon_s": 20.0},
            {"max_exponent": 5, "factors": (0.5,)},
            ["hold 32", "paper x0.5"],
        ),
        (
            "etsc/ClusterContainmentCentral-v0",
            {"horizon_s": 20.0},
            {"factors": (1.0,), "rule_channel_heartbeat": 150, "sampling_period_s": 0.01},
            ["paper x1, channel heartbeat 150"],
        ),
        (
            "etsc/ClusterContainment-v0",
            {"horizon_s": 20.0},
            {"factors": (1.0,), "rule_channel_heartbeat": 150, "sampling_period_s": 0.01},
            ["paper x1, channel heartbeat 150"],
        ),
    ],
)
def test_a_stand_alone_trigger_takes_the_constant_decisions_actions(
    env_id, env_kwargs, decision_keywords, labels
):
    """Where a decision always taken is a stand-alone trigger (the clock, the rule at a
    scaled threshold, with a heartbeat per channel), the compiled run of that trigger gives the
    records of the deployed decision policy (run decision by decision, the episode of the
    per-instant deployment: tests/test_batch.py): the same transmissions, cost and failure, and
    the same return up to the order of its sum."""
    decisions = decision_set_v1(env_id, **decision_keywords)
    seeds = scenario_set("validation", SET_SIZE).seeds
    setup = episode_setup(env_id, env_kwargs)
    deployed = deployment(setup, decisions)
    for label in labels:
        action = decisions.action(label)
        assert stand_alone_spec(decisions, action) is not None
        compiled = constant_decision_policy(setup, deployed, decisions, action)
        assert isinstance(compiled, RuleTrigger)
        reference = SelfTriggeredPolicy(FixedDecision(action), *deployed)
        for fast, slow in zip(
            run_batch(env_id, compiled, seeds, env_kwargs),
            run_batch(env_id, reference, seeds, env_kwargs),
            strict=True,
        ):
            assert fast["transmissions"] > 0
            for key in ("transmissions", "mean_cost", "failure"):
                assert fast[key] == slow[key], (label, key)
            assert fast["return"] == pytest.approx(slow["return"], rel=1e-12), label
    setup.env.close()


def test_decisions_with_a_forced_transmission_or_a_shield_run_as_decisions():
    """A heartbeat's or a floor's forced transmission at each decision instant, and a shield
    that may replace a choice, have no stand-alone trigger: those run as decisions."""
    heartbeat = decision_set_v1(ATTITUDE, max_exponent=3, factors=(2.0,), rule_heartbeat=True)
    assert stand_alone_spec(heartbeat, heartbeat.action("paper x2, heartbeat 8")) is None
    assert stand_alone_spec(heartbeat, heartbeat.action("hold 8")) == ("periodic", {"every": 8})
    shielded = decision_set_v1(
        "etsc/InnerFormation-v0", max_exponent=3, shield_multiple=2.0, sampling_period_s=0.01
    )
    assert stand_alone_spec(shielded, shielded.action("hold 1")) is None
