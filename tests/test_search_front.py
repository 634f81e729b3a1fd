"""``agents.sweep`` with ``learner: search``: a front of CMA-ES searches over penalty x seed in
one command. Its trials equal stand-alone ``agents.search`` runs, a resumed sweep runs no
finished trial again, ``--sweep`` readers find the learned triggers, and the config is
checked before any trial starts."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml

from agents.search.cma_es import Evaluator, config_from_dict, run_search
from agents.sweep.config import sweep_config_from_dict
from agents.sweep.results import sweep_models
from tests.sweep_fixtures import sweep_without_ray

pytest.importorskip("stable_baselines3")

SEARCH = {
    "env_id": "etsc/AttitudeTracking-v0",
    "penalty": 100.0,
    "start": {"factors": {"psi": 8.0}, "heartbeat_instants": 384, "first_instant": True},
    "search": ["factors", "heartbeat", "exponent"],
    "generations": 2,
    "population": 3,
    "scenarios": 1,
    "horizon_s": 0.5,
    "sigma": 0.5,
    "validate_every": 1,
    "validation_size": 1,
}
PENALTIES = (30.0, 300.0)


def _sweep(tmp_path: Path, **changes: Any) -> Path:
    base = tmp_path / "search.yaml"
    base.write_text(yaml.safe_dump(SEARCH))
    sweep = {
        "base": str(base),
        "results_dir": str(tmp_path / "front"),
        "kind": "front",
        "learner": "search",
        "grid": {"penalty": list(PENALTIES), "seed": [0]},
        **changes,
    }
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(sweep))
    return path


def _generations(folder: Path) -> list[dict[str, Any]]:
    records = [
        json.loads(line) for line in (folder / "generations.jsonl").read_text().split("\n") if line
    ]
    for record in records:
        record.pop("wall_s")
    return records


@pytest.fixture(scope="module")
def front(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp_path = tmp_path_factory.mktemp("search_front")
    config = _sweep(tmp_path)
    first = sweep_without_ray("--config", str(config), "--processes", "2")
    results_dir = tmp_path / "front"
    times = {
        folder.name: (folder / "learned.json").stat().st_mtime_ns
        for folder in (results_dir / "trials").iterdir()
    }
    resumed = sweep_without_ray("--config", str(config), "--processes", "1", "--resume")
    return {"tmp": tmp_path, "results_dir": results_dir, "first": first, "times": times,
            "resumed": resumed}  # fmt: skip


def test_every_trial_is_the_stand_alone_search_at_its_penalty(front) -> None:
    assert front["first"].returncode == 0, front["first"].stderr
    summary = json.loads((front["results_dir"] / "sweep_summary.json").read_text())
    assert [trial["status"] for trial in summary["trials"]] == ["finished"] * len(PENALTIES)
    for trial in summary["trials"]:
        folder = front["results_dir"] / trial["folder"]
        penalty = trial["values"]["penalty"]
        alone = front["tmp"] / f"alone_{penalty:g}"
        evaluator = Evaluator(0, None)
        run_search(config_from_dict({**SEARCH, "penalty": penalty}), alone, evaluator,
                   progress=lambda line: None)  # fmt: skip
        assert _generations(folder) == _generations(alone)
        learned = json.loads((folder / "learned.json").read_text())
        assert learned == json.loads((alone / "learned.json").read_text()) | {
            "search": learned["search"]  # the wall time differs
        }
        assert learned["search"]["penalty"] == penalty
        assert trial["scores"]["validation_return"] == learned["search"]["validation_return"]
        assert yaml.safe_load((folder / "config.yaml").read_text())["penalty"] == penalty


def test_a_resumed_front_runs_no_finished_search_again(front) -> None:
    assert front["resumed"].returncode == 0, front["resumed"].stderr
    for name, mtime in front["times"].items():
        assert (front["results_dir"] / "trials" / name / "learned.json").stat().st_mtime_ns == mtime


def test_readers_of_a_sweep_find_its_learned_triggers(front) -> None:
    models = sweep_models([front["results_dir"]], "etsc/AttitudeTracking-v0")
    assert len(models) == len(PENALTIES)
    assert all(Path(model).name == "learned.json" for model in models)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"kind": "search", "search": {"penalty": {"uniform": [1, 2]}}}, "must be 'front' with"),
        ({"grid": {"penalty": [1.0], "total_timesteps": [5]}}, "unknown search-config key"),
        ({"grid": {"penalty": [-1.0]}}, "penalty"),
        ({"learner": "evolve"}, "learner"),
    ],
)
def test_a_bad_search_front_is_refused_before_any_trial(tmp_path: Path, changes, message) -> None:
    raw = yaml.safe_load(_sweep(tmp_path, **changes).read_text())
    with pytest.raises(ValueError, match=message):
        sweep_config_from_dict(raw, "sweep.yaml")


def test_a_grown_front_runs_only_its_new_points(tmp_path: Path) -> None:
    first = _sweep(tmp_path, grid={"penalty": [30.0], "seed": [0]})
    assert sweep_without_ray("--config", str(first), "--processes", "1").returncode == 0
    trials = tmp_path / "front" / "trials"
    before = {
        folder.name: (folder / "learned.json").stat().st_mtime_ns for folder in trials.iterdir()
    }
    grown = _sweep(tmp_path, grid={"penalty": [30.0], "seed": [0, 1]})
    resumed = sweep_without_ray("--config", str(grown), "--processes", "1", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    summary = json.loads((tmp_path / "front" / "sweep_summary.json").read_text())
    assert [trial["values"] for trial in summary["trials"]] == [
        {"penalty": 30.0, "seed": 0},
        {"penalty": 30.0, "seed": 1},
    ]
    assert [trial["status"] for trial in summary["trials"]] == ["finished"] * 2
    for name, mtime in before.items():  # the seed-0 search did not run again
        assert (trials / name / "learned.json").stat().st_mtime_ns == mtime
    settings = json.loads((tmp_path / "front" / "sweep_settings.json").read_text())
    assert settings["grid"]["seed"] == [0, 1]


def test_a_grid_that_lost_a_value_is_refused(tmp_path: Path) -> None:
    started = sweep_config_from_dict(yaml.safe_load(_sweep(tmp_path).read_text()), "sweep.yaml")
    started.start_or_continue(resume=False, started=False)
    changed = sweep_config_from_dict(
        yaml.safe_load(_sweep(tmp_path, grid={"penalty": [30.0], "seed": [0]}).read_text()),
        "sweep.yaml",
    )
    with pytest.raises(ValueError, match=r"the sweep's \['grid'\] changed"):
        changed.start_or_continue(resume=True, started=True, grid_may_grow=True)


def test_tune_does_not_continue_a_grown_grid(tmp_path: Path) -> None:
    started = sweep_config_from_dict(yaml.safe_load(_sweep(tmp_path).read_text()), "sweep.yaml")
    started.start_or_continue(resume=False, started=False)
    grown = sweep_config_from_dict(
        yaml.safe_load(
            _sweep(tmp_path, grid={"penalty": list(PENALTIES), "seed": [0, 1]}).read_text()
        ),
        "sweep.yaml",
    )
    with pytest.raises(ValueError, match="continue a grown grid with --processes N"):
        grown.start_or_continue(resume=True, started=True)
