"""agents.search: CMA-ES over a trigger family converges on a toy objective, chooses on
validation, resumes to the same θ, refuses bad configs, and its process and Ray evaluators
score alike."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import pytest

from agents.search.cma_es import (
    EXPONENT_RANGE,
    Evaluator,
    SearchSpace,
    config_from_dict,
    load_config,
    run_search,
    training_seeds,
)
from etsc_envs.protocol import RESERVED_SEEDS
from etsc_envs.triggers.family import FamilyPoint, LearnedTrigger

TARGET = {"psi": 4.0, "floor": 3.0, "heartbeat": 200.0, "exponent": 0.5}


def toy_return(point: FamilyPoint) -> float:
    """A smooth objective with its maximum 0 at :data:`TARGET` (in the search's log2 units)."""
    return -(
        (math.log2(point.factors["psi"]) - math.log2(TARGET["psi"])) ** 2
        + (math.log2(max(point.floor_instants, 0.5)) - math.log2(TARGET["floor"])) ** 2
        + (math.log2(point.heartbeat_instants) - math.log2(TARGET["heartbeat"])) ** 2
        + (point.exponent - TARGET["exponent"]) ** 2
    )


class ToyEvaluator:
    """Scores each call's learned trigger by :func:`toy_return` instead of running the env."""

    description = "toy"

    def __init__(self) -> None:
        self.calls = 0

    def map(self, calls: list[tuple]) -> list[dict[str, float]]:
        self.calls += len(calls)
        results = []
        for _, _, learned, seeds in calls:
            value = toy_return(LearnedTrigger.from_json(learned).point)
            results.append(
                {"return": value, "mean_cost": -value, "transmissions": 1.0, "failures": 0}
                | {"steps": len(seeds)}
            )
        return results

    def close(self) -> None:
        pass


def _config(**changes) -> object:
    raw = {
        "env_id": "etsc/AttitudeTracking-v0",
        "penalty": 1.0,
        "start": {"factors": {"psi": 1.0}, "heartbeat_instants": 50},
        "search": ["factors", "floor", "heartbeat", "exponent"],
        "generations": 40,
        "population": 8,
        "scenarios": 2,
        "sigma": 1.0,
        "validate_every": 4,
        "validation_size": 2,
        "horizon_s": 1.0,
    }
    return config_from_dict({**raw, **changes})


def test_search_converges_on_a_toy_objective(tmp_path: Path) -> None:
    config = _config()
    learned = run_search(config, tmp_path, ToyEvaluator(), progress=lambda line: None)
    start = toy_return(config.start)
    assert toy_return(learned.point) > -0.05 > start
    point = learned.point
    assert point.factors["psi"] == pytest.approx(TARGET["psi"], rel=0.15)
    assert point.exponent == pytest.approx(TARGET["exponent"], abs=0.15)
    curve = json.loads((tmp_path / "curve.json").read_text())
    validated = [row["validation_return"] for row in curve["curve"] if "validation_return" in row]
    assert validated[-1] > validated[0]
    assert learned.search["validation_return"] == max(validated)
    assert (tmp_path / "curve.png").stat().st_size > 0


def test_resumed_search_gives_the_uninterrupted_theta(tmp_path: Path) -> None:
    config = _config(generations=9)
    whole = run_search(config, tmp_path / "whole", ToyEvaluator(), progress=lambda line: None)
    interrupted = tmp_path / "resumed"
    run_search(replace(config, generations=4), interrupted, ToyEvaluator(), progress=print)
    evaluator = ToyEvaluator()
    resumed = run_search(config, interrupted, evaluator, progress=lambda line: None)
    assert resumed.point.to_json() == whole.point.to_json()
    assert evaluator.calls == 5 * 8 + 2  # only the five missing generations ran
    other_seed = replace(config, seed=1)
    with pytest.raises(ValueError, match="--resume"):
        run_search(other_seed, interrupted, ToyEvaluator(), progress=lambda line: None)


def test_same_seed_same_search_other_seed_other_draws(tmp_path: Path) -> None:
    config = _config(generations=3)
    first = run_search(config, tmp_path / "a", ToyEvaluator(), progress=lambda line: None)
    again = run_search(config, tmp_path / "b", ToyEvaluator(), progress=lambda line: None)
    assert first.point.to_json() == again.point.to_json()
    log_a = (tmp_path / "a" / "generations.jsonl").read_text().splitlines()
    other = run_search(
        replace(config, seed=7), tmp_path / "c", ToyEvaluator(), progress=lambda line: None
    )
    log_c = (tmp_path / "c" / "generations.jsonl").read_text().splitlines()
    assert json.loads(log_a[0])["candidates"] != json.loads(log_c[0])["candidates"]
    assert other is not None


def test_encoding_round_trips_and_respects_the_papers_bounds() -> None:
    config = _config(
        env_id="etsc/OrbitAttitudeTracking-v0",
        start={"factors": {"a1": 5.0, "gamma1": 4.0}, "floor_instants": 64},
    )
    space = SearchSpace(config, n_steps=300_000, modulation=None)
    point = space.decode(space.encode(config.start))
    assert point.factors["a1"] == pytest.approx(5.0)
    assert point.floor_instants == pytest.approx(64.0)
    assert math.isinf(space.decode(space.upper).heartbeat_instants)
    assert space.decode(space.upper).factors["a1"] < 3.2 / 0.6  # Theorem 2: a1 < K21
    assert space.decode(space.lower).floor_instants == 0.0


def test_the_exponent_box_is_the_configs() -> None:
    """``exponent_range`` widens p's box for one config and leaves every other search's
    decoding as it was (the default box)."""
    default = SearchSpace(_config(search=["exponent"]), n_steps=50_000, modulation=None)
    assert (default.lower[0], default.upper[0]) == EXPONENT_RANGE
    config = _config(search=["exponent"], exponent_range=[-1.0, 4.0], start={"exponent": 3.0})
    wide = SearchSpace(config, n_steps=50_000, modulation=None)
    assert (wide.lower[0], wide.upper[0]) == (-1.0, 4.0)
    assert wide.decode(wide.encode(config.start)).exponent == 3.0
    assert wide.decode([10.0]).exponent == 4.0


def test_a_coupled_search_encodes_weights_and_strength() -> None:
    """Searching ``coupling`` adds log2 of each condition's weight and κ to x; every candidate
    keeps the start's refresh_all."""
    start = {
        "factors": {"pi": 6.0},
        "exponent": 1.0,
        "coupling": {"weights": [1.0, 0.5, 2.0], "strength": 0.25, "refresh_all": False},
    }
    config = _config(env_id="etsc/InnerFormation-v0", start=start, search=["factors", "coupling"])
    space = SearchSpace(config, n_steps=40_000, modulation=None)
    assert space.encode(config.start).tolist() == pytest.approx(
        [math.log2(6.0), 0.0, -1.0, 1.0, 0.25]
    )
    point = space.decode([1.0, 2.0, 0.0, -3.0, 0.9])
    assert point.coupling.weights == (4.0, 1.0, 0.125) and point.coupling.strength == 0.9
    assert point.coupling.refresh_all is False
    assert space.decode([1.0, 2.0, 0.0, -3.0, 7.0]).coupling.strength == 1.0  # κ's box
    with pytest.raises(ValueError, match=r"search.start.coupling' gives the coupling"):
        _config(env_id="etsc/InnerFormation-v0", start={}, search=["coupling"])


def test_training_seeds_avoid_the_protocols_sets() -> None:
    config = _config(scenarios=64)
    for generation in (0, 1, 10_000):
        seeds = training_seeds(replace(config, seed=3), generation)
        for reserved in RESERVED_SEEDS.values():
            assert not set(seeds) & set(reserved)
    assert training_seeds(config, 1)[0] == training_seeds(config, 0)[-1] + 1


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"env_id": "etsc/Nope-v0"}, "env_id"),
        ({"search": ["factors", "wings"]}, "search"),
        ({"generations": 0}, "generations"),
        ({"population": 1}, "population"),
        ({"penalty": -1.0}, "penalty"),
        ({"penalty": float("inf")}, "penalty"),
        ({"horizon_s": 0}, "horizon_s"),
        ({"search": ["modulation"]}, "inputs"),
        (
            {
                "env_id": "etsc/ClusterContainment-v0",
                "start": {},
                "search": ["modulation"],
                "inputs": ["s_norm"],
            },
            r"inputs\[0\]': 's_norm' must read each agent's own observation",
        ),
        (
            {
                "env_id": "etsc/ClusterContainment-v0",
                "start": {},
                "search": ["modulation"],
                "inputs": ["s_norm_{channel}"],
            },
            r"\['s_norm_'\] are not observations of etsc/ClusterContainment-v0",
        ),
        (
            {
                "env_id": "etsc/ClusterContainmentCentral-v0",
                "start": {},
                "search": ["modulation"],
                "inputs": ["s_norm{channel}", "speed{channel}"],
            },
            r"inputs\[1\]': \['speed_0', .* are not observations",
        ),
        ({"colour": "red"}, "unknown keys"),
        ({"start": {"factors": {"psi": 0.0}}}, "factors.psi"),
        ({"exponent_range": [2.0, 1.0]}, r"search.exponent_range' must be \[low, high\]"),
        ({"exponent_range": [-1.0, 5.0]}, "exponent_range"),
        ({"exponent_range": [0.0]}, "exponent_range"),
        ({"start": {"exponent": 3.0}}, r"start.exponent' must lie in exponent_range \[-1.0, 2.0\]"),
    ],
)
def test_bad_configs_are_refused_naming_the_key(changes, message) -> None:
    with pytest.raises(ValueError, match=message):
        _config(**changes)


def test_shipped_search_configs_start_where_they_say() -> None:
    """Every shipped config loads, and its start point survives the search's encoding (a
    factor the config leaves out is 1), so generation 0 validates the menu rule it names."""
    for path in sorted(Path("configs/search").glob("*.yaml")):
        config = load_config(path)
        space = SearchSpace(config, n_steps=300_000, modulation=None)
        start = space.decode(space.encode(config.start))
        for name, factor in start.factors.items():
            assert factor == pytest.approx(config.start.factors.get(name, 1.0), rel=1e-12), path
        for key in ("floor_instants", "heartbeat_instants", "exponent", "first_instant"):
            assert getattr(start, key) == getattr(config.start, key), (path, key)


def test_process_and_ray_evaluators_score_alike(tmp_path: Path) -> None:
    """One tiny real search (002, 0.2-s training episodes) gives the same records through
    worker processes and through a local Ray."""
    pytest.importorskip(
        "ray", reason="Ray: the sweep extra is not installed (pip install -e '.[sweep]')"
    )
    config = _config(generations=2, population=2, scenarios=1, horizon_s=0.2, validate_every=1)
    logs = []
    for name, evaluator in (("processes", Evaluator(1, None)), ("ray", Evaluator(None, None))):
        try:
            run_search(config, tmp_path / name, evaluator, progress=lambda line: None)
        finally:
            evaluator.close()
        records = [
            json.loads(line)
            for line in (tmp_path / name / "generations.jsonl").read_text().splitlines()
        ]
        for record in records:
            record.pop("wall_s")
        logs.append(records)
    assert logs[0] == logs[1]
    assert logs[0][0]["transmissions"][0] > 0


def test_search_benchmark_counts_every_env_step_it_times() -> None:
    """``agents.bench.search`` divides the search's recorded env steps, training episodes of
    every candidate and the validation of the mean alike, by the times it measured."""
    from agents.bench.search import time_search

    config = _config(generations=1, population=2, scenarios=3, horizon_s=0.2, validation_size=2)
    steps, cpu, wall = time_search(config)
    training = 2 * 3 * 200  # 0.2 s at 1 ms
    validation = 2 * 50_000  # the paper's 50 s at 1 ms
    assert steps == training + validation
    assert cpu > 0.0 and wall > 0.0


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--config", "no/such.yaml"], "--config no/such.yaml: not a readable YAML file"),
        (["--generations", "0"], "--generations must be an integer >= 1, got 0"),
        (["--repeats", "-2"], "--repeats must be an integer >= 1, got -2"),
    ],
)
def test_search_benchmark_refuses_bad_arguments_in_one_line(capsys, argv, message) -> None:
    from agents.bench.search import main

    with pytest.raises(SystemExit):
        main(argv)
    assert message in capsys.readouterr().err.strip().splitlines()[-1]
