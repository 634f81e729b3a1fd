"""``python -m agents.sweep`` on a local Ray: a three-trial front of a few thousand steps
(two that train, one that crashes), interrupted after its first trial and resumed; and the
one-line refusals of bad input."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
import yaml

pytest.importorskip("stable_baselines3")
pytest.importorskip(
    "ray.tune", reason="Ray Tune: the sweep extra is not installed (pip install -e '.[sweep]')"
)

from agents.sweep.runner import main
from agents.train.kept_checkpoint import kept_evaluation
from tests.child_process import interruptible
from tests.sweep_fixtures import retrained_differences, tiny_sweep

ROOT = Path(__file__).resolve().parents[1]
FIRST, SECOND, CRASHING = (
    "transmission_penalty=30",
    "transmission_penalty=100",
    "transmission_penalty=-1",
)
START_TIMEOUT_S = 600.0
"""Longest wait for the first trial's model (Ray's start and the imports on a busy machine)."""


def sweep_command(config: Path, *options: str) -> list[str]:
    return [sys.executable, "-m", "agents.sweep", "--config", str(config), *options]


def sweep_environment() -> dict[str, str]:
    """The test's environment without a Ray address, so the sweep starts its own Ray."""
    return {key: value for key, value in os.environ.items() if key != "RAY_ADDRESS"}


def modification_times(folder: Path) -> dict[str, int]:
    return {path.name: path.stat().st_mtime_ns for path in folder.iterdir() if path.is_file()}


@pytest.fixture(scope="module")
def interrupted_sweep(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Run the tiny front with a third, crashing penalty (-1: the env refuses it), one trial
    at a time; interrupt it (SIGINT, as Ctrl+C) once the first trial saved its model, then
    resume it. Returns the folders, the summary after the interruption and the first
    trial's file times at the interruption."""
    tmp_path = tmp_path_factory.mktemp("sweep")
    grid = {"env_kwargs.transmission_penalty": [30.0, 100.0, -1.0]}
    config = tiny_sweep(tmp_path, grid=grid)
    results_dir = tmp_path / "sweep"
    first_model = results_dir / "trials" / FIRST / "model.zip"
    log = (tmp_path / "interrupted.log").open("w")
    process = subprocess.Popen(
        sweep_command(config),
        cwd=ROOT,
        env=sweep_environment(),
        stdout=log,
        stderr=log,
        # a test run started in the background inherits SIGINT ignored; the sweep must not
        preexec_fn=interruptible,
    )
    deadline = time.monotonic() + START_TIMEOUT_S
    while not first_model.is_file() and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    if process.poll() is not None or not first_model.is_file():
        process.kill()
        pytest.fail(f"the sweep ended or hung before its first trial finished, rc {process.poll()}")
    process.send_signal(signal.SIGINT)
    interrupted_rc = process.wait(timeout=300)
    interrupted = json.loads((results_dir / "sweep_summary.json").read_text(encoding="utf-8"))
    first_times = modification_times(results_dir / "trials" / FIRST)
    resumed = subprocess.run(
        sweep_command(config, "--resume"),
        cwd=ROOT,
        env=sweep_environment(),
        capture_output=True,
        text=True,
        timeout=900,
    )
    return {
        "config": config,
        "results_dir": results_dir,
        "interrupted_rc": interrupted_rc,
        "interrupted": interrupted,
        "first_times": first_times,
        "resumed": resumed,
    }


def statuses(summary: dict[str, Any]) -> dict[str, str]:
    return {trial["name"]: trial["status"] for trial in summary["trials"]}


def test_an_interrupted_front_is_incomplete_and_says_so(interrupted_sweep) -> None:
    assert interrupted_sweep["interrupted_rc"] == 1, "an incomplete front exits with 1"
    found = statuses(interrupted_sweep["interrupted"])
    assert found[FIRST] == "finished"
    assert found[SECOND] == "incomplete" and found[CRASHING] == "incomplete"


def test_resuming_runs_the_rest_and_not_the_finished_trial(interrupted_sweep) -> None:
    results_dir = interrupted_sweep["results_dir"]
    assert modification_times(results_dir / "trials" / FIRST) == interrupted_sweep["first_times"]
    summary = json.loads((results_dir / "sweep_summary.json").read_text(encoding="utf-8"))
    assert statuses(summary) == {FIRST: "finished", SECOND: "finished", CRASHING: "failed"}
    assert summary["counts"] == {"finished": 2, "failed": 1, "incomplete": 0}
    resumed = interrupted_sweep["resumed"]
    assert resumed.returncode == 1, "a failed trial makes the sweep exit with 1"
    assert f"failed     {CRASHING}  ValueError: config key 'env_kwargs'" in resumed.stdout


def test_both_trials_leave_a_model_its_statistics_and_evaluations(interrupted_sweep) -> None:
    results_dir = interrupted_sweep["results_dir"]
    summary = json.loads((results_dir / "sweep_summary.json").read_text(encoding="utf-8"))
    assert summary["env_id"] == "etsc/AttitudeTracking-v0" and summary["kind"] == "front"
    by_name = {trial["name"]: trial for trial in summary["trials"]}
    for name, penalty in ((FIRST, 30.0), (SECOND, 100.0)):
        folder = results_dir / by_name[name]["folder"]
        assert folder == results_dir / "trials" / name
        for file in ("model.zip", "model_vecnormalize.npz", "config.yaml", "train_summary.json"):
            assert (folder / file).stat().st_size > 0, f"{name}: {file}"
        config = yaml.safe_load((folder / "config.yaml").read_text(encoding="utf-8"))
        assert config["env_kwargs"]["transmission_penalty"] == penalty
        assert config["total_timesteps"] == 2048
        evaluations = json.loads((folder / "evaluations.json").read_text(encoding="utf-8"))
        assert [entry["timesteps"] for entry in evaluations] == [1024, 2048]
        scores = by_name[name]["scores"]
        assert scores["timesteps"] == 2048
        assert scores["learned_transmissions"] == evaluations[-1]["learned"]["transmissions"]
        assert scores["paper_transmissions"] == evaluations[-1]["paper"]["transmissions"] > 0
        assert by_name[name]["values"] == {"env_kwargs.transmission_penalty": penalty}
    crashed = by_name[CRASHING]
    assert (
        crashed["error"].startswith("ValueError: ") and "transmission_penalty" in crashed["error"]
    )
    assert "\n" not in crashed["error"] and crashed["scores"] is None


@pytest.mark.parametrize("name", [FIRST, SECOND])
def test_a_trial_is_the_run_agents_train_makes_from_its_config(
    interrupted_sweep, name: str, tmp_path: Path
) -> None:
    """The first trial as Ray ran it, and the second as it ran again on resuming."""
    folder = interrupted_sweep["results_dir"] / "trials" / name
    assert retrained_differences(folder, tmp_path / "again") == []


def test_a_finished_sweep_is_not_started_again_without_resume(interrupted_sweep, capsys) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["--config", str(interrupted_sweep["config"])])
    assert exit_info.value.code == 2
    assert "already holds a sweep: continue it with --resume" in capsys.readouterr().err


def closed_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--address", "127.0.0.1:{port}"], "--address: no Ray cluster answers at '127.0.0.1:"),
        (["--address", "ray://127.0.0.1:{port}"], "--address: no Ray cluster answers at"),
        (["--address", "nohost"], "--address must be HOST:PORT or ray://HOST:PORT"),
        (["--resume"], "--resume: no saved sweep in"),
    ],
)
def test_bad_command_lines_exit_with_one_line(
    tmp_path: Path, capsys, options: list[str], message: str
) -> None:
    config = tiny_sweep(tmp_path)
    port = closed_port()
    with pytest.raises(SystemExit) as exit_info:
        main(["--config", str(config), *(option.format(port=port) for option in options)])
    assert exit_info.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert message in error


def test_a_bad_sweep_config_exits_with_one_line(tmp_path: Path, capsys) -> None:
    config = tiny_sweep(tmp_path, grid={"env_kwargs.transmission_penalty": []})
    with pytest.raises(SystemExit) as exit_info:
        main(["--config", str(config)])
    assert exit_info.value.code == 2
    assert (
        "'grid.env_kwargs.transmission_penalty' must be a non-empty list" in capsys.readouterr().err
    )


def test_a_search_runs_under_asha_and_optuna_to_saved_models(tmp_path: Path) -> None:
    pytest.importorskip(
        "optuna", reason="Optuna: the sweep extra is not installed (pip install -e '.[sweep]')"
    )
    search = {
        "hyperparameters.learning_rate": {"loguniform": [1.0e-4, 3.0e-3]},
        "env_kwargs.transmission_penalty": {"choice": [30.0, 100.0]},
    }
    objective = {"scheduler": "asha", "search_algorithm": "optuna", "metric": "cost_ratio"}
    keys = {"kind": "search", "grid": {}, "search": search, "num_samples": 2, **objective}
    config = tiny_sweep(tmp_path, **keys, mode="min", grace_timesteps=1024)
    assert main(["--config", str(config)]) == 0
    summary = json.loads((tmp_path / "sweep" / "sweep_summary.json").read_text(encoding="utf-8"))
    assert summary["kind"] == "search" and summary["counts"]["finished"] == 2
    for trial in summary["trials"]:
        assert set(trial["values"]) == set(search)
        assert 1.0e-4 <= trial["values"]["hyperparameters.learning_rate"] <= 3.0e-3
        assert trial["name"].startswith("learning_rate=") and ",trial=" in trial["name"]
        assert (tmp_path / "sweep" / trial["folder"] / "model.zip").is_file()
    base = yaml.safe_load((ROOT / "configs/train/attitude_tracking_ppo.yaml").read_text())
    start = {
        "hyperparameters.learning_rate": base["hyperparameters"]["learning_rate"],
        "env_kwargs.transmission_penalty": base["env_kwargs"]["transmission_penalty"],
    }
    drawn = [trial["values"] for trial in summary["trials"]]
    assert start in drawn, "Optuna evaluates the start (the base with the overrides)"


def test_a_search_trial_of_several_seeds_reports_their_mean(tmp_path: Path) -> None:
    """With ``trial_seeds`` every drawn value trains once per seed, each run in its own folder,
    and the trial's score is the mean over the seeds of their kept checkpoints' validation
    returns."""
    pytest.importorskip(
        "optuna", reason="Optuna: the sweep extra is not installed (pip install -e '.[sweep]')"
    )
    search = {"hyperparameters.learning_rate": {"loguniform": [1.0e-4, 3.0e-3]}}
    objective = {"search_algorithm": "optuna", "metric": "best_validation_return", "mode": "max"}
    keys = {"kind": "search", "grid": {}, "search": search, "num_samples": 1, **objective}
    config = tiny_sweep(tmp_path, **keys, trial_seeds=[0, 1])
    assert main(["--config", str(config)]) == 0
    summary = json.loads((tmp_path / "sweep" / "sweep_summary.json").read_text(encoding="utf-8"))
    (trial,) = summary["trials"]
    assert trial["status"] == "finished"
    folder = tmp_path / "sweep" / trial["folder"]
    returns = []
    for seed in (0, 1):
        run = folder / f"seed={seed}"
        assert (run / "model.zip").is_file()
        assert yaml.safe_load((run / "config.yaml").read_text())["seed"] == seed
        evaluations = json.loads((run / "evaluations.json").read_text(encoding="utf-8"))
        kept = kept_evaluation(evaluations)
        assert kept is not None and kept["trained"]
        returns.append(kept["learned"]["return"])
    assert returns[0] != returns[1], "the seeds train differently"
    assert trial["scores"]["best_validation_return"] == pytest.approx(sum(returns) / 2)


def test_the_last_rollout_is_left_to_the_final_report(monkeypatch, tmp_path: Path) -> None:
    """A scheduler stops a trial that reports its full length: that report must come after
    the model is saved, not from the training loop."""
    import agents.sweep.trial as sweep_trial

    reports: list[dict[str, Any]] = []
    monkeypatch.setattr(sweep_trial.tune, "report", reports.append)
    callback = sweep_trial.TuneReportCallback(tmp_path, total_timesteps=2048)
    callback.model = SimpleNamespace(ep_info_buffer=[{"r": -2.0}, {"r": -4.0}])
    for timesteps in (1024, 2048):
        callback.num_timesteps = timesteps
        callback.on_rollout_end()
    assert reports == [{"timesteps": 1024, "training_reward": -3.0}]
    reports.clear()
    waiting = sweep_trial.TuneReportCallback(tmp_path, total_timesteps=4096, metric="cost_ratio")
    waiting.model = callback.model
    waiting.num_timesteps = 1024
    waiting.on_rollout_end()
    assert reports == [], "no report before the first evaluation gives the objective"
    evaluation = {"mean_cost": 2.0, "transmissions": 10, "return": -30.0, "failure": None}
    paper = {"mean_cost": 1.0, "transmissions": 20, "failure": None}
    entry = {"timesteps": 2048, "learned": evaluation, "paper": paper}
    (tmp_path / "evaluations.json").write_text(json.dumps([entry]), encoding="utf-8")
    waiting.num_timesteps = 2048
    waiting.on_rollout_end()
    assert reports[0]["cost_ratio"] == 2.0 and reports[0]["transmission_ratio"] == 0.5
    assert reports[0]["best_validation_return"] == -30.0


def test_a_summary_names_the_grid_points_that_never_started(tmp_path: Path) -> None:
    from agents.sweep.config import load_sweep_config
    from agents.sweep.runner import summarize

    config = load_sweep_config(tiny_sweep(tmp_path))
    wrapped = RuntimeError("task failed\nTraceback ...")
    wrapped.cause = ValueError("transmission_penalty must be >= 0\n  in the env")
    started = tmp_path / "tune" / "transmission_penalty=30"  # crashed before it reported
    started.mkdir(parents=True)
    (started / "params.json").write_text('{"env_kwargs.transmission_penalty": 30.0}', "utf-8")
    results = [SimpleNamespace(path=str(started), config=None, error=wrapped)]
    trials = summarize(config, results)
    assert [(trial.name, trial.status) for trial in trials] == [
        ("transmission_penalty=30", "failed"),
        ("transmission_penalty=100", "incomplete"),
    ]
    assert trials[0].error == "ValueError: transmission_penalty must be >= 0"
    assert trials[0].values == {"env_kwargs.transmission_penalty": 30.0}
    assert trials[1].values == {"env_kwargs.transmission_penalty": 100.0}


def test_resuming_with_changed_settings_is_refused(interrupted_sweep, tmp_path: Path, capsys):
    raw = yaml.safe_load(interrupted_sweep["config"].read_text(encoding="utf-8"))
    raw["overrides"]["total_timesteps"] = 4096
    changed = tmp_path / "changed.yaml"
    changed.write_text(yaml.safe_dump(raw, sort_keys=False), encoding="utf-8")
    with pytest.raises(SystemExit) as exit_info:
        main(["--config", str(changed), "--resume"])
    assert exit_info.value.code == 2
    assert "--resume: the sweep's ['base'] changed since it started" in capsys.readouterr().err
