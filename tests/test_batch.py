"""The batch path (every scenario in one native vector env) equals the single-env path,
scenario for scenario, for every id and every kind of policy."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from agents.train.validation_callback import deployment
from etsc_envs.decisions import SelfTriggeredPolicy
from etsc_envs.evaluation.batch import run_batch, run_batch_in_processes
from etsc_envs.evaluation.policy_specs import episode_setup
from tests.rule_sets import rule_set, rule_wrapper

SHORT_HORIZONS = {
    "etsc/AttitudeTracking-v0": 2.0,
    "etsc/InnerFormation-v0": 2.0,
    "etsc/OrbitAttitudeTracking-v0": 1.0,
    "etsc/AsteroidOrbitKeeping-v0": 500.0,
    "etsc/ClusterContainmentCentral-v0": 20.0,
    "etsc/ClusterContainment-v0": 20.0,
}
"""About 2000 sampling instants of each id: long enough for every trigger to fire."""

SEEDS = (2_000_000, 2_000_001, 2_000_002)
MODEL = Path(__file__).resolve().parents[1] / "models" / "AttitudeTracking-v0_ppo.zip"


def single_records(
    env_id: str, spec: str, policy_args: dict[str, Any], env_args: dict[str, Any]
) -> list[dict[str, Any]]:
    setup = episode_setup(env_id, env_args)
    policy = setup.make_policy(spec, policy_args)
    records = [setup.run(setup.env, policy, seed)[0] for seed in SEEDS]
    setup.env.close()
    return records


def batch_records(
    env_id: str,
    spec: str,
    policy_args: dict[str, Any],
    env_args: dict[str, Any],
    seeds: tuple[int, ...] = SEEDS,
) -> list[dict[str, Any]]:
    setup = episode_setup(env_id, env_args)
    policy = setup.make_policy(spec, policy_args)
    setup.env.close()
    return run_batch(env_id, policy, seeds, env_args)


def distinct(record: dict[str, Any]) -> str:
    """The record without its seed and wall time, as text (equal for equal episodes)."""
    kept = {key: value for key, value in record.items() if key not in ("seed", "wall_time_s")}
    return json.dumps(kept, sort_keys=True)


def assert_same_record(single: Any, batch: Any, where: str = "record") -> None:
    """Equal key for key and bit for bit (NaN equals NaN), ``wall_time_s`` aside."""
    if isinstance(single, dict):
        assert set(single) == set(batch), where
        for key in single:
            if key != "wall_time_s":
                assert_same_record(single[key], batch[key], f"{where}[{key!r}]")
    elif isinstance(single, list | tuple):
        assert len(single) == len(batch), where
        for index, (a, b) in enumerate(zip(single, batch, strict=True)):
            assert_same_record(a, b, f"{where}[{index}]")
    elif isinstance(single, float) and math.isnan(single):
        assert isinstance(batch, float) and math.isnan(batch), where
    else:
        assert single == batch, f"{where}: {single!r} != {batch!r}"


@pytest.mark.parametrize("env_id", sorted(SHORT_HORIZONS))
def test_batch_equals_single_env_for_the_paper_trigger(env_id: str) -> None:
    env_args = {"randomize": True, "horizon_s": SHORT_HORIZONS[env_id]}
    single = single_records(env_id, "paper", {}, env_args)
    batch = batch_records(env_id, "paper", {}, env_args)
    assert [record["seed"] for record in batch] == list(SEEDS)
    assert len({distinct(record) for record in single}) == len(SEEDS), "scenarios must differ"
    for one, other in zip(single, batch, strict=True):
        assert_same_record(one, other)


@pytest.mark.parametrize(
    ("env_id", "spec", "policy_args"),
    [
        ("etsc/InnerFormation-v0", "periodic", {"every": 7}),
        ("etsc/ClusterContainment-v0", "periodic", {"every": 13}),
        ("etsc/AsteroidOrbitKeeping-v0", "always", {}),
        ("etsc/AttitudeTracking-v0", f"sb3:{MODEL}", {}),
    ],
)
def test_batch_equals_single_env_for_clocks_and_learned_triggers(
    env_id: str, spec: str, policy_args: dict[str, Any]
) -> None:
    if spec.startswith("sb3:"):
        pytest.importorskip("stable_baselines3")
    env_args = {"randomize": True, "horizon_s": SHORT_HORIZONS[env_id]}
    single = single_records(env_id, spec, policy_args, env_args)
    batch = batch_records(env_id, spec, policy_args, env_args)
    for one, other in zip(single, batch, strict=True):
        assert_same_record(one, other)


def test_a_scenario_that_fails_early_keeps_its_own_record() -> None:
    """A sub-environment that fails is recorded at its failure while the others run on (and
    its autoreset episode is ignored)."""
    env_id = "etsc/AttitudeTracking-v0"
    env_args = {"randomize": True, "horizon_s": 2.0, "max_rate_rad_s": 0.4}
    single = single_records(env_id, "periodic", {"every": 400}, env_args)
    batch = batch_records(env_id, "periodic", {"every": 400}, env_args)
    assert all(record["failure"] is not None for record in single)
    assert len({record["steps"] for record in single}) == len(SEEDS), "they fail apart"
    for one, other in zip(single, batch, strict=True):
        assert_same_record(one, other)


@pytest.mark.parametrize(
    ("env_id", "spec"),
    [
        ("etsc/OrbitAttitudeTracking-v0", "paper"),
        ("etsc/ClusterContainment-v0", "paper"),
        ("etsc/AttitudeTracking-v0", f"sb3:{MODEL}"),
    ],
)
def test_worker_processes_give_the_records_of_one_process(env_id: str, spec: str) -> None:
    if spec.startswith("sb3:"):
        pytest.importorskip("stable_baselines3")
    env_args = {"randomize": True, "horizon_s": SHORT_HORIZONS[env_id]}
    seeds = (*SEEDS, 2_000_003, 2_000_004)
    together = batch_records(env_id, spec, {}, env_args, seeds)
    apart = run_batch_in_processes(env_id, spec, {}, seeds, env_args, processes=2)
    assert [record["seed"] for record in apart] == list(seeds)
    for one, other in zip(together, apart, strict=True):
        assert_same_record(one, other)


@pytest.mark.parametrize("processes", [0, -1, 1.5, True])
def test_a_bad_process_count_names_itself(processes: Any) -> None:
    with pytest.raises(ValueError, match="processes"):
        run_batch_in_processes("etsc/AttitudeTracking-v0", "paper", {}, SEEDS, processes=processes)


class ScriptedDecisions:
    """A stand-in for a self-triggered model: an action that varies with the observation;
    with ``mostly`` that action three times in four."""

    def __init__(self, n_actions: int, mostly: int | None = None) -> None:
        self.n_actions = n_actions
        self.mostly = mostly

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        digits = (np.abs(np.asarray(observation)).sum(axis=1) * 1e4).astype(np.int64)
        actions = digits % self.n_actions
        if self.mostly is not None:
            actions = np.where(digits % 4 == 0, actions, self.mostly)
        return actions, None


def assert_same_episode(single: dict[str, Any], batch: dict[str, Any]) -> None:
    """Equal records but the return, which the decision path sums interval by interval."""
    assert batch["return"] == pytest.approx(single["return"], rel=1e-12)
    assert_same_record({**single, "return": 0.0}, {**batch, "return": 0.0})


@pytest.mark.parametrize(
    ("env_id", "decision_keywords"),
    [
        ("etsc/AttitudeTracking-v0", {"max_exponent": 6, "cap": 48, "send_first": True}),
        ("etsc/InnerFormation-v0", {"max_exponent": 6, "shield_multiple": 2.0}),
        ("etsc/InnerFormation-v0", {"max_exponent": 5, "rule": "error_time"}),
        ("etsc/OrbitAttitudeTracking-v0", {"max_exponent": 6, "floor": 8}),
        ("etsc/AsteroidOrbitKeeping-v0", {"max_exponent": 6, "shield_multiple": 1.0}),
        ("etsc/ClusterContainmentCentral-v0", {"max_exponent": 8, "factors": (0.5, 1.0, 1.5)}),
    ],
)
def test_self_triggered_decisions_run_decision_by_decision_as_instant_by_instant(
    env_id: str, decision_keywords: dict[str, Any]
) -> None:
    """run_batch runs a self-triggered policy's intervals in compiled calls, one choice per
    decision: the episodes of the per-instant deployment, every action of the set taken."""
    env_args = {"randomize": True, "horizon_s": SHORT_HORIZONS[env_id]}
    setup = episode_setup(env_id, env_args)
    decisions = rule_set(env_id, **decision_keywords)
    policy = SelfTriggeredPolicy(
        ScriptedDecisions(decisions.action_space.n), *deployment(setup, decisions)
    )
    single = [setup.run(setup.env, policy, seed)[0] for seed in SEEDS]
    setup.env.close()
    batch = run_batch(env_id, policy, SEEDS, env_args)
    assert len({distinct(record) for record in single}) == len(SEEDS), "scenarios must differ"
    for one, other in zip(single, batch, strict=True):
        assert_same_episode(one, other)


@pytest.mark.parametrize("env_id", ["etsc/AttitudeTracking-v0", "etsc/InnerFormation-v0"])
def test_rows_holding_one_instant_step_together_as_instant_by_instant(env_id: str) -> None:
    """A policy that mostly holds one instant (the rows that chose it step together in the
    vector env, the others run their intervals alone): the per-instant episodes."""
    env_args = {"randomize": True, "horizon_s": SHORT_HORIZONS[env_id]}
    setup = episode_setup(env_id, env_args)
    decisions = rule_set(env_id, max_exponent=4)
    one_instant = decisions.action("hold 1")
    model = ScriptedDecisions(decisions.action_space.n, mostly=one_instant)
    policy = SelfTriggeredPolicy(model, *deployment(setup, decisions))
    single = [setup.run(setup.env, policy, seed)[0] for seed in SEEDS]
    setup.env.close()
    batch = run_batch(env_id, policy, SEEDS, env_args)
    steps = single[0]["steps"]
    assert single[0]["transmissions"] > steps / 4, "many instants must be one-instant holds"
    for one, other in zip(single, batch, strict=True):
        assert_same_episode(one, other)


def test_a_saved_self_triggered_model_runs_decision_by_decision(tmp_path: Path) -> None:
    """An SB3 model of self-triggered decisions saved with its set (``sb3:``) runs the same
    episodes in the batch as one by one."""
    stable_baselines3 = pytest.importorskip("stable_baselines3")
    env_id = "etsc/AttitudeTracking-v0"
    wrapper = rule_wrapper(gym.make(env_id), max_exponent=6)
    model = stable_baselines3.PPO("MlpPolicy", wrapper, device="cpu", seed=0)
    model.save(tmp_path / "model.zip")
    wrapper.decisions.save(tmp_path / "model.zip")
    spec = f"sb3:{tmp_path / 'model.zip'}"
    env_args = {"randomize": True, "horizon_s": SHORT_HORIZONS[env_id]}
    single = single_records(env_id, spec, {}, env_args)
    batch = batch_records(env_id, spec, {}, env_args)
    for one, other in zip(single, batch, strict=True):
        assert_same_episode(one, other)
