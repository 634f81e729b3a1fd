"""The test protocol: scenario sets, reserved seeds, statistics with intervals, verdicts."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from agents.judge.results import goal_verdict
from etsc_envs.evaluation.statistics import (
    aggregate_records,
    paired_ratio,
    proportion_summary,
    seeds_ratio,
    seeds_summary,
    summarize,
)
from etsc_envs.evaluation.verdict import Axis
from etsc_envs.protocol import (
    DEFAULT_SET_SIZE,
    TEST_SEEDS,
    VALIDATION_SEEDS,
    require_training_seeds,
    scenario_set,
)


def test_the_sets_are_fixed_disjoint_and_randomized() -> None:
    test, validation, paper = (
        scenario_set("test"),
        scenario_set("validation"),
        scenario_set("paper"),
    )
    assert test.size == validation.size == DEFAULT_SET_SIZE
    assert test.seeds == tuple(range(TEST_SEEDS.start, TEST_SEEDS.start + DEFAULT_SET_SIZE))
    assert not set(test.seeds) & set(validation.seeds)
    assert test.env_args == validation.env_args == {"randomize": True}
    assert paper.env_args == {"randomize": False} and paper.size == 1
    assert scenario_set("test", 8).seeds == test.seeds[:8]


@pytest.mark.parametrize(
    ("name", "size", "message"),
    [
        ("train", 4, "scenarios must be one of"),
        ("test", 0, "size of a scenario set"),
        ("validation", -3, "size of a scenario set"),
        ("test", 2.5, "size of a scenario set"),
        ("test", len(TEST_SEEDS) + 1, "size of a scenario set"),
    ],
)
def test_a_bad_set_request_names_the_argument(name: str, size: object, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        scenario_set(name, size)


def test_a_set_refuses_a_contradicting_randomize() -> None:
    with pytest.raises(ValueError, match="contradicts the 'test' scenario set"):
        scenario_set("test").env_kwargs({"randomize": False})
    assert scenario_set("test").env_kwargs({"horizon_s": 1.0}) == {
        "horizon_s": 1.0,
        "randomize": True,
    }


@pytest.mark.parametrize(
    ("first", "count"),
    [
        (VALIDATION_SEEDS.start, 1),
        (VALIDATION_SEEDS.start - 4, 5),
        (TEST_SEEDS.stop - 1, 1),
        (TEST_SEEDS.start + 10, 16),
    ],
)
def test_training_refuses_the_reserved_seeds(first: int, count: int) -> None:
    with pytest.raises(ValueError, match="training never uses"):
        require_training_seeds(first, count)


def test_training_accepts_seeds_outside_the_reserved_ranges() -> None:
    assert require_training_seeds(0, 64) == 0
    assert require_training_seeds(VALIDATION_SEEDS.start - 16, 16) == VALIDATION_SEEDS.start - 16
    assert require_training_seeds(TEST_SEEDS.stop, 8) == TEST_SEEDS.stop


def test_a_training_config_seeded_inside_the_test_set_is_refused() -> None:
    pytest.importorskip("stable_baselines3")
    from agents.train.config import config_from_dict

    raw = {
        "env_id": "etsc/AttitudeTracking-v0",
        "algorithm": "PPO",
        "policy": "MlpPolicy",
        "total_timesteps": 64,
        "out_dir": "runs/never",
        "tensorboard": False,
        "n_envs": 4,
    }
    assert config_from_dict({**raw, "seed": 7}).seed == 7
    with pytest.raises(ValueError, match="config key 'seed'=2000000 with 4"):
        config_from_dict({**raw, "seed": TEST_SEEDS.start})


def test_summaries_hold_the_mean_and_its_interval() -> None:
    rng = np.random.default_rng(3)
    values = rng.lognormal(size=64)
    summary = summarize(values)
    assert summary["mean_ci95"][0] < summary["mean"] < summary["mean_ci95"][1]
    assert summary["iqm_ci95"][0] < summary["iqm"] < summary["iqm_ci95"][1]
    assert summary["median"] == pytest.approx(np.median(values))
    assert summarize(values) == summary, "intervals are reproducible"
    constant = summarize([2.0] * 5)
    assert constant["mean_ci95"] == [2.0, 2.0]
    with pytest.raises(ValueError, match="finite numbers"):
        summarize([1.0, float("nan")])


def test_a_rate_interval_is_the_exact_binomial_one() -> None:
    none = proportion_summary([False] * 64)
    assert none["count"] == 0 and none["rate_ci95"][0] == 0.0
    assert none["rate_ci95"][1] == pytest.approx(1 - 0.025 ** (1 / 64))
    half = proportion_summary([True, False] * 32)
    assert half["rate_ci95"][0] < 0.5 < half["rate_ci95"][1]


def test_paired_ratios_and_probability_of_improvement() -> None:
    rng = np.random.default_rng(4)
    reference = rng.uniform(1.0, 2.0, 64)
    same = paired_ratio(reference, reference)
    assert same["iqm"] == 1.0 and same["iqm_ci95"] == [1.0, 1.0]
    assert same["probability_of_improvement"] == 0.5
    better = paired_ratio(0.8 * reference * rng.uniform(0.95, 1.05, 64), reference)
    assert better["iqm_ci95"][1] < 1.0
    assert better["probability_of_improvement"] == 1.0
    assert better["ratio_of_means_ci95"][0] < better["ratio_of_means"] < 1.0


def test_several_seeds_aggregate_with_the_stratified_bootstrap() -> None:
    pytest.importorskip("rliable")
    rng = np.random.default_rng(5)
    reference = rng.uniform(1.0, 2.0, 32)
    runs = np.vstack([scale * reference for scale in (0.9, 1.0, 1.1)])
    result = seeds_ratio(runs, reference)
    assert result["runs"] == 3 and result["per_run"] == pytest.approx([0.9, 1.0, 1.1])
    assert result["range"] == pytest.approx([0.9, 1.1])
    assert result["iqm_ci95"][0] <= result["iqm"] <= result["iqm_ci95"][1]


def test_seeds_worse_than_a_zero_reference_everywhere_have_no_ratio() -> None:
    """Seeds above a reference that is 0 on every scenario (a method that fails the paper
    scenario its rule keeps at cost 0) get no ratio and count as worse there, as one seed does
    with :func:`paired_ratio`, instead of stopping the judgement."""
    pytest.importorskip("rliable")
    runs = np.array([[2.0], [3.0], [0.5]])
    result = seeds_ratio(runs, np.zeros(1))
    single = paired_ratio(runs[0], np.zeros(1))
    assert result["iqm"] is None is single["iqm"] and result["iqm_ci95"] is None
    assert result["range"] is None and result["per_run"] == [None, None, None]
    assert result["worse_where_reference_zero"] == single["worse_where_reference_zero"] == 1
    assert Axis(result["iqm_ci95"], 1.0, result["worse_where_reference_zero"]).outcome()[0] == (
        "loses"
    )


def test_stratified_intervals_are_the_same_in_every_call() -> None:
    """rliable resamples from NumPy's global generator: the interval must not depend on what
    drew from it before (a record is reproduced digit for digit), and the caller's stream is
    left as it was."""
    pytest.importorskip("rliable")
    rng = np.random.default_rng(3)
    reference = rng.uniform(1.0, 2.0, 16)
    runs = reference * rng.uniform(0.8, 1.2, (3, 16))
    first_ratio, first_mean = seeds_ratio(runs, reference), seeds_summary(runs)
    np.random.seed(123)
    expected_draw = np.random.random()
    np.random.seed(123)
    again_ratio, again_mean = seeds_ratio(runs, reference), seeds_summary(runs)
    assert np.random.random() == expected_draw
    assert again_ratio["iqm_ci95"] == first_ratio["iqm_ci95"]
    assert again_mean["mean_ci95"] == first_mean["mean_ci95"]
    low, high = first_mean["mean_ci95"]
    assert low < runs.mean() < high


def test_seeds_that_learned_one_policy_keep_the_scenarios_spread() -> None:
    """Identical runs leave no run-to-run variation, but the scenarios are a sample of their
    distribution: the method's interval is that of one run's per-scenario ratios, not a point."""
    pytest.importorskip("rliable")
    rng = np.random.default_rng(7)
    reference = rng.uniform(1.0, 2.0, 64)
    one_policy = reference * rng.uniform(0.5, 0.9, 64)
    result = seeds_ratio(np.vstack([one_policy] * 5), reference)
    single = paired_ratio(one_policy, reference)
    assert result["range"][0] == result["range"][1] == pytest.approx(single["iqm"])
    low, high = result["iqm_ci95"]
    assert high - low > 0.5 * (single["iqm_ci95"][1] - single["iqm_ci95"][0]) > 0.0


def test_a_verdict_is_met_only_when_the_interval_supports_it() -> None:
    cost = {"iqm": 1.0, "iqm_ci95": [0.97, 1.04]}
    sent = {"iqm": 0.5, "iqm_ci95": [0.45, 0.69]}

    def goal(cost: dict, sent: dict, failures: int = 0):
        return goal_verdict({"mean_cost": cost, "transmissions": sent}, failures, 0)

    assert goal(cost, sent).met
    result = goal({"iqm": 1.0, "iqm_ci95": [0.9, 1.06]}, sent)
    assert not result.met and "cost ratio interval [0.9, 1.06] reaches 1.05" in result.reasons[0]
    assert not goal(cost, {"iqm": 0.6, "iqm_ci95": [0.5, 0.71]}).met
    assert not goal(cost, sent, failures=1).met


def test_aggregates_cover_cost_transmissions_failures_and_settling() -> None:
    records = [
        {
            "mean_cost": cost,
            "transmissions": 10 + index,
            "transmission_rate": 0.1,
            "return": -cost,
            "failure": None if index else "diverged",
            "settled": bool(index),
        }
        for index, cost in enumerate([1.0, 2.0, 3.0, 4.0])
    ]
    aggregates = aggregate_records(records)
    assert aggregates["mean_cost"]["mean"] == 2.5
    assert aggregates["failure"]["count"] == 1 and aggregates["settled"]["count"] == 3


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "baselines.evaluate", *args],
        capture_output=True,
        text=True,
        check=False,
    )


def test_evaluate_runs_a_scenario_set_and_prints_the_aggregates_as_json() -> None:
    done = run_cli(
        "etsc/AttitudeTracking-v0",
        "--policy",
        "paper",
        "--scenarios",
        "test",
        "--set-size",
        "3",
        "--env-arg",
        "horizon_s=0.5",
        "--json",
        "-",
    )
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["scenarios"]["name"] == "test" and result["scenarios"]["size"] == 3
    assert [record["seed"] for record in result["episodes"]] == list(TEST_SEEDS[:3])
    assert result["env_args"]["randomize"] is True
    cost = result["aggregates"]["mean_cost"]
    assert cost["mean_ci95"][0] <= cost["mean"] <= cost["mean_ci95"][1]
    assert "aggregates (95 % intervals)" in done.stderr


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--scenarios", "train"), "invalid choice: 'train'"),
        (("--scenarios", "test", "--set-size", "0"), "argument --set-size: takes an integer >= 1"),
        (("--scenarios", "test", "--env-arg", "randomize=false"), "contradicts"),
    ],
)
def test_evaluate_refuses_a_bad_scenario_request(args: tuple[str, ...], message: str) -> None:
    done = run_cli("etsc/AttitudeTracking-v0", "--policy", "paper", *args)
    assert done.returncode == 2 and message in done.stderr
    assert "Traceback" not in done.stderr


def test_evaluate_refuses_a_folder_as_json_path_before_the_work(tmp_path) -> None:
    done = run_cli("etsc/AttitudeTracking-v0", "--policy", "paper", "--json", str(tmp_path))
    assert done.returncode == 2 and "--json must name a file" in done.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_cost_where_the_reference_has_none_fails_the_verdict() -> None:
    reference = np.array([0.0, 0.0, 1.0, 2.0])
    tied = paired_ratio(np.array([0.0, 0.0, 1.0, 2.0]), reference)
    assert tied["worse_where_reference_zero"] == 0 and tied["iqm"] == 1.0
    sent = {"iqm": 0.5, "iqm_ci95": [0.45, 0.6]}
    assert goal_verdict({"mean_cost": tied, "transmissions": sent}, 0, 0).met
    worse = paired_ratio(np.array([0.1, 0.0, 1.0, 2.0]), reference)
    assert worse["worse_where_reference_zero"] == 1
    result = goal_verdict({"mean_cost": worse, "transmissions": sent}, 0, 0)
    assert not result.met and "where the reference is 0" in result.reasons[0]
