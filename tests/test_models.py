"""The trained triggers shipped in ``models/`` and the rows of ``docs/results.md``."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

import etsc_envs
from baselines.evaluate import evaluate
from etsc_envs.sb3_models import NormalizedModel, load_sb3, normalization_path

ROOT = Path(__file__).parents[1]
MODELS = sorted((ROOT / "models").glob("*-v0_*.zip"))
"""``models/<id>_<method>.zip``: per-instant PPO (``_ppo``), self-triggered PPO
(``_self_triggered``) and self-triggered DQN (``_self_triggered_dqn``)."""
RESULTS = ROOT / "docs" / "results"
CROSS_MACHINE_SPREAD = {"etsc/OrbitAttitudeTracking-v0": 5e-3}
"""Relative spread of a recorded paper-scenario row between machines, by id: 000's closed loop
is chaotic at the level of its steady chattering, and rounding that differs between processors
and library versions moves its 300-s episode by 0.03-0.2 % (``docs/results.md``, "Paper 000:
eq. (21) gating a clock"); the per-instant PPO row, 300 000 decisions on those states, moved by
0.21 % in cost and 0.04 % in transmissions between the machine that recorded it and this
project's 2-core machine (deterministic on each). Every other id's rows are reproduced to the
last digit."""


SHIPPED_FROM_FRONTS = {
    "AttitudeTracking-v0_ppo": ("AttitudeTracking-v0_ppo/transmission_penalty=300", 0),
    "AttitudeTracking-v0_self_triggered": (
        "AttitudeTracking-v0_self_triggered_tuned/transmission_penalty=300",
        0,
    ),
    "AttitudeTracking-v0_self_triggered_dqn": (
        "AttitudeTracking-v0_self_triggered_dqn_tuned/transmission_penalty=300",
        2,
    ),
    "AsteroidOrbitKeeping-v0_ppo": ("AsteroidOrbitKeeping-v0_ppo/transmission_penalty=1", 3),
    "AsteroidOrbitKeeping-v0_self_triggered": (
        "AsteroidOrbitKeeping-v0_self_triggered_tuned/transmission_penalty=0.3",
        0,
    ),
    "AsteroidOrbitKeeping-v0_self_triggered_dqn": (
        "AsteroidOrbitKeeping-v0_self_triggered_dqn_tuned/transmission_penalty=0.3",
        3,
    ),
    "ClusterContainment-v0_ppo": ("ClusterContainment-v0_ppo/transmission_penalty=10", 1),
    "ClusterContainmentCentral-v0_ppo": (
        "ClusterContainmentCentral-v0_ppo/transmission_penalty=10",
        2,
    ),
    "ClusterContainment-v0_self_triggered": (
        "ClusterContainment-v0_self_triggered_tuned/transmission_penalty=10",
        3,
    ),
    "ClusterContainmentCentral-v0_self_triggered": (
        "ClusterContainmentCentral-v0_self_triggered_tuned/transmission_penalty=10",
        0,
    ),
    "ClusterContainment-v0_self_triggered_dqn": (
        "ClusterContainment-v0_self_triggered_dqn_tuned/transmission_penalty=10",
        0,
    ),
    "ClusterContainmentCentral-v0_self_triggered_dqn": (
        "ClusterContainmentCentral-v0_self_triggered_dqn_tuned/transmission_penalty=1",
        0,
    ),
    "OrbitAttitudeTracking-v0_ppo": ("OrbitAttitudeTracking-v0_ppo/transmission_penalty=1", 3),
    "OrbitAttitudeTracking-v0_self_triggered": (
        "OrbitAttitudeTracking-v0_self_triggered_tuned/transmission_penalty=1",
        0,
    ),
    "OrbitAttitudeTracking-v0_self_triggered_dqn": (
        "OrbitAttitudeTracking-v0_self_triggered_dqn_tuned/transmission_penalty=1",
        2,
    ),
    "InnerFormation-v0_ppo": ("InnerFormation-v0_ppo/transmission_penalty=5", 1),
    "InnerFormation-v0_self_triggered": (
        "InnerFormation-v0_self_triggered_scratch/transmission_penalty=5",
        4,
    ),
    "InnerFormation-v0_self_triggered_dqn": (
        "InnerFormation-v0_self_triggered_dqn/transmission_penalty=5",
        1,
    ),
}
"""Each model shipped from a protocol front (``agents.results --sweep``): the record of the
chosen penalty's seeds, and which seed the model is (the best on validation); every other
model's record is ``docs/results/<model>/``."""


def recorded_paper_row(model: Path) -> tuple[dict, dict]:
    """The judged record of a shipped model and its row on the paper scenario."""
    folder, seed = SHIPPED_FROM_FRONTS.get(model.stem, (model.stem, None))
    recorded = json.loads((RESULTS / folder / "results.json").read_text(encoding="utf-8"))
    rows = recorded["sets"]["paper"]["models"]
    if seed is None:
        return recorded, rows[0]
    (row,) = [row for row in rows if f"seed={seed}/" in row["model"]]
    return recorded, row


def env_id_of(model: Path) -> str:
    return "etsc/" + model.name.partition("_")[0]


def short_episode(env_id: str) -> dict[str, float]:
    return {"horizon_s": 60.0} if "Asteroid" in env_id else {"horizon_s": 0.05}


def test_models_are_shipped_for_registered_ids() -> None:
    assert MODELS, "models/ holds the trained triggers of docs/results.md"
    known = set(etsc_envs.ENV_IDS) | set(etsc_envs.PETTINGZOO_ENV_IDS)
    for model in MODELS:
        assert env_id_of(model) in known, model.name
        assert normalization_path(model).is_file(), f"statistics beside {model.name}"


@pytest.mark.parametrize("model", MODELS, ids=lambda path: path.stem)
def test_no_shipped_model_is_an_untrained_network(model: Path) -> None:
    """A shipped model is a learned policy: its optimiser updated it at least once (training
    never keeps an untrained checkpoint, agents/train/kept_checkpoint.py)."""
    with zipfile.ZipFile(model) as saved:
        assert json.loads(saved.read("data"))["_n_updates"] > 0


@pytest.mark.parametrize("model", MODELS, ids=lambda path: path.stem)
def test_every_model_loads_with_its_statistics_and_runs(model: Path) -> None:
    assert isinstance(load_sb3(model), NormalizedModel)
    env_id = env_id_of(model)
    result = evaluate(env_id, f"sb3:{model}", env_args=short_episode(env_id))
    assert result["episodes"][0]["steps"] > 0


@pytest.mark.slow
@pytest.mark.parametrize("model", MODELS, ids=lambda path: path.stem)
def test_evaluate_reproduces_the_learned_row_of_the_results(model: Path) -> None:
    env_id = env_id_of(model)
    recorded, paper_row = recorded_paper_row(model)
    row = paper_row["learned"]["mean"]
    result = evaluate(env_id, f"sb3:{model}", env_args=recorded["env_args"], scenarios="paper")
    spread = CROSS_MACHINE_SPREAD.get(env_id, 0.0)
    assert result["mean"]["transmissions"] == pytest.approx(row["transmissions"], rel=spread)
    assert result["mean"]["mean_cost"] == pytest.approx(row["mean_cost"], rel=max(spread, 1e-9))
