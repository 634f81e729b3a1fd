"""``python -m agents.results``: the learned trigger against the paper's and periodic sampling."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from stable_baselines3 import PPO

from agents.judge.results import (
    clock_verdict,
    equal_rate_period,
    main,
    markdown,
    model_kind,
    verdict_text,
)
from agents.train.vector_adapter import make_sb3_vec_env
from etsc_envs.decisions import DecisionSet, Hold
from etsc_envs.evaluation.statistics import paired_ratio

ENV_ID = "etsc/AttitudeTracking-v0"
SHORT = {"horizon_s": 0.05}


def test_equal_rate_period_matches_the_transmission_count() -> None:
    assert equal_rate_period(50_000, 500, 1) == 100
    assert equal_rate_period(200_000, 6_000, 3) == 100  # three channels each every 100
    assert equal_rate_period(1_000, 0, 1) == 1_000
    assert equal_rate_period(10, 100, 1) == 1


def tiny_model(path: Path, seed: int) -> Path:
    env = make_sb3_vec_env(ENV_ID, 2, **SHORT)
    model = PPO("MlpPolicy", env, n_steps=16, batch_size=32, n_epochs=1, device="cpu", seed=seed)
    model.learn(total_timesteps=32)
    model.save(path)
    return path


def test_results_judges_models_on_the_paper_scenario_and_the_test_set(tmp_path: Path) -> None:
    models = [tiny_model(tmp_path / f"model_{seed}.zip", seed) for seed in range(3)]
    out_dir = tmp_path / "results"
    argv = [ENV_ID, "--set-size", "4", "--out", str(out_dir), "--env-arg", "horizon_s=0.05"]
    for model in models:
        argv += ["--model", str(model)]
    assert main(argv) == 0
    result = json.loads((out_dir / "results.json").read_text(encoding="utf-8"))
    assert set(result["sets"]) == {"paper", "test"}
    test = result["sets"]["test"]
    assert test["scenarios"]["size"] == 4 and len(test["paper"]["episodes"]) == 4
    assert test["paper"]["aggregates"]["mean_cost"]["n"] == 4
    first = test["models"][0]
    every = first["periodic_every"]
    assert first["periodic"]["mean"]["transmissions"] == -(-50 // every)
    ratio = first["vs_paper"]["mean_cost"]
    assert ratio["iqm_ci95"][0] <= ratio["iqm"] <= ratio["iqm_ci95"][1]
    assert set(first["goal"]) == {"outcome", "met", "axes", "reasons", "failures"}
    method = test["method"]
    assert method["claim"] and method["seeds"] == 3
    assert len(method["vs_paper"]["mean_cost"]["per_run"]) == 3
    paper = result["sets"]["paper"]
    assert paper["scenarios"]["size"] == 1 and paper["paper"]["env_args"]["randomize"] is False
    assert [row["kind"] for row in test["models"]] == ["PPO"] * 3
    text = markdown(result)
    assert "**Test set (4 scenarios)**" in text and "| paper |" in text
    assert "| PPO #3 |" in text and "learned #" not in text
    assert "method over 3 seeds" in text


def test_a_model_is_named_by_what_it_is(tmp_path: Path) -> None:
    """A PPO model is a PPO model: only a search's point is a "learned trigger"."""
    models = Path(__file__).resolve().parents[1] / "models"
    assert model_kind(str(models / "AttitudeTracking-v0_learned.json")) == "learned trigger"
    assert model_kind(f"learned:{models / 'AttitudeTracking-v0_hand.json'}") == "hand point"
    model = tiny_model(tmp_path / "model.zip", 0)
    assert model_kind(str(model)) == "PPO"
    DecisionSet(ENV_ID, [Hold(1), Hold(2)]).save(model)
    assert model_kind(f"sb3:{model}") == "self-triggered PPO"


def test_one_model_makes_no_claim(tmp_path: Path) -> None:
    model = tiny_model(tmp_path / "model.zip", 0)
    out_dir = tmp_path / "results"
    argv = [ENV_ID, "--model", str(model), "--scenarios", "paper", "--out", str(out_dir)]
    assert main([*argv, "--env-arg", "horizon_s=0.05"]) == 0
    result = json.loads((out_dir / "results.json").read_text(encoding="utf-8"))
    assert not result["sets"]["paper"]["method"]["claim"]
    assert "no claim: 1 training seed(s)" in markdown(result)


def fake_result(costs: list[float], transmissions: list[int]) -> dict:
    """An evaluation result with one record per scenario (what ``clock_verdict`` reads)."""
    return {
        "episodes": [
            {"mean_cost": cost, "transmissions": sent, "failure": None}
            for cost, sent in zip(costs, transmissions, strict=True)
        ]
    }


@pytest.mark.parametrize(
    ("periodic_costs", "outcome", "text"),
    [
        ([1.0, 2.0, 3.0, 4.0], "ties", "ties (cost ratio interval [1, 1] reaches 1)"),
        ([1.1, 2.2, 3.3, 4.4], "beats", "**beats**"),
        ([0.9, 1.8, 2.7, 3.6], "loses", "loses (cost ratio interval"),
    ],
)
def test_a_learned_trigger_that_is_the_clock_ties(periodic_costs, outcome, text) -> None:
    learned = fake_result([1.0, 2.0, 3.0, 4.0], [10, 10, 10, 10])
    periodic = fake_result(periodic_costs, [10, 10, 10, 10])
    costs = [[record["mean_cost"] for record in r["episodes"]] for r in (learned, periodic)]
    result = clock_verdict(paired_ratio(*map(np.array, costs)), 0, 0).to_json()
    assert result["outcome"] == outcome
    assert verdict_text(result).startswith(text)


def test_a_failed_trigger_beats_no_clock_that_failed_too() -> None:
    """The report's bug: a trigger that failed the paper scenario, beside a clock that failed
    it too, was printed "beats periodic **met**" (its cut-short cost was lower)."""
    ratio = paired_ratio(np.array([0.5]), np.array([1.0]))
    both = clock_verdict(ratio, 1, 1)
    assert both.outcome == "both fail" and not both.met
    assert "**" not in verdict_text(both.to_json())
    assert clock_verdict(ratio, 1, 0).outcome == "loses"
    assert clock_verdict(ratio, 0, 1).outcome == "beats"


def test_seeds_at_one_rate_share_one_run_of_the_clock(tmp_path: Path, monkeypatch) -> None:
    """The clock at a period runs once per set (its episodes depend on the period alone): two
    copies of one model, one clock run per set, and each row keeps the clock's records."""
    import agents.judge.results as results

    calls = []
    evaluate = results.evaluate

    def counted(env_id, spec, **kwargs):
        calls.append((spec, kwargs["scenarios"]))
        return evaluate(env_id, spec, **kwargs)

    monkeypatch.setattr(results, "evaluate", counted)
    model = tiny_model(tmp_path / "model.zip", 0)
    out_dir = tmp_path / "results"
    argv = [ENV_ID, "--set-size", "4", "--out", str(out_dir), "--env-arg", "horizon_s=0.05"]
    assert main([*argv, "--model", str(model), "--model", str(model)]) == 0
    assert sorted(calls).count(("periodic", "test")) == 1
    assert sorted(calls).count(("periodic", "paper")) == 1
    test = json.loads((out_dir / "results.json").read_text(encoding="utf-8"))["sets"]["test"]
    first, second = test["models"]
    assert first["periodic_every"] == second["periodic_every"]
    assert first["periodic"]["episodes"] == second["periodic"]["episodes"]
