"""``python -m agents.results``: the learned trigger against the paper's and periodic sampling."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from stable_baselines3 import PPO

from agents.results import equal_rate_period, main, markdown, meets_goal
from agents.vector_adapter import make_sb3_vec_env

ENV_ID = "etsc/AttitudeTracking-v0"
SHORT = {"horizon_s": 0.05}


def row(mean_cost: float, transmissions: int, failures: int = 0) -> dict[str, float]:
    return {"mean_cost": mean_cost, "transmissions": transmissions, "failures": failures}


@pytest.mark.parametrize(
    ("learned", "paper", "met"),
    [
        (row(1.04, 70), row(1.0, 100), True),
        (row(1.06, 70), row(1.0, 100), False),  # 6 % less accurate
        (row(1.0, 71), row(1.0, 100), False),  # 29 % saving
        (row(1.0, 50, failures=1), row(1.0, 100), False),
        (row(0.0, 50), row(0.0, 100), True),  # a paper cost of 0 must be matched exactly
        (row(1e-9, 50), row(0.0, 100), False),
    ],
)
def test_the_goal_needs_both_axes_and_no_failure(learned, paper, met) -> None:
    assert meets_goal(learned, paper)["met"] is met


def test_equal_rate_period_matches_the_transmission_count() -> None:
    assert equal_rate_period(50_000, 500, 1) == 100
    assert equal_rate_period(200_000, 6_000, 3) == 100  # three channels each every 100
    assert equal_rate_period(1_000, 0, 1) == 1_000
    assert equal_rate_period(10, 100, 1) == 1


def test_results_compares_a_model_on_the_paper_and_randomized_scenarios(tmp_path: Path) -> None:
    env = make_sb3_vec_env(ENV_ID, 2, **SHORT)
    model = PPO("MlpPolicy", env, n_steps=16, batch_size=32, n_epochs=1, device="cpu", seed=0)
    model.learn(total_timesteps=32)
    model_path = tmp_path / "model.zip"
    model.save(model_path)
    out_dir = tmp_path / "results"
    argv = [ENV_ID, "--model", str(model_path), "--randomized-episodes", "2", "--out"]
    assert main([*argv, str(out_dir), "--env-arg", "horizon_s=0.05"]) == 0
    result = json.loads((out_dir / "results.json").read_text(encoding="utf-8"))
    rows = result["paper_scenario"]
    periodic = next(name for name in rows if name.startswith("periodic every "))
    assert {"paper", "learned", "goal"} <= set(rows)
    assert rows["paper"]["transmissions"] > 0 and "mean_input_norm" in rows["paper"]
    every = int(periodic.split()[-1])
    assert rows[periodic]["transmissions"] == -(-50 // every)
    assert result["randomized"]["episodes"] == 2
    assert result["randomized"]["paper"]["mean_cost"] != rows["paper"]["mean_cost"]
    text = markdown(result)
    assert "| paper |" in text and "Randomized scenarios (2 episodes, mean)" in text
