"""``python -m agents.sweep --processes N``: the tiny front in worker processes with Ray made
unimportable (two trials that train, one that crashes), continued with ``--resume``; and its
refusals of what it cannot run."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest
import yaml

from tests.sweep_fixtures import (
    ROOT,
    TINY,
    command_without_ray,
    retrained_differences,
    sweep_without_ray,
    tiny_sweep,
)

pytest.importorskip("stable_baselines3")

from agents.train.training import LOCK_FILE

FINISHING = ("transmission_penalty=30", "transmission_penalty=100")
CRASHING = "transmission_penalty=-1"


@pytest.fixture(scope="module")
def process_sweep(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp_path = tmp_path_factory.mktemp("process_sweep")
    config = tiny_sweep(tmp_path, grid={"env_kwargs.transmission_penalty": [30.0, 100.0, -1.0]})
    first = sweep_without_ray("--config", str(config), "--processes", "2")
    results_dir = tmp_path / "sweep"
    summary = json.loads((results_dir / "sweep_summary.json").read_text(encoding="utf-8"))
    times = {
        name: (results_dir / "trials" / name / "model.zip").stat().st_mtime_ns for name in FINISHING
    }
    resumed = sweep_without_ray("--config", str(config), "--processes", "1", "--resume")
    return {
        "config": config,
        "results_dir": results_dir,
        "first": first,
        "summary": summary,
        "times": times,
        "resumed": resumed,
    }


def test_the_grid_trains_without_ray_and_records_the_crashing_trial(process_sweep) -> None:
    first = process_sweep["first"]
    assert first.returncode == 1, first.stderr
    statuses = {trial["name"]: trial["status"] for trial in process_sweep["summary"]["trials"]}
    assert statuses == {FINISHING[0]: "finished", FINISHING[1]: "finished", CRASHING: "failed"}
    crashed = next(t for t in process_sweep["summary"]["trials"] if t["name"] == CRASHING)
    assert "transmission_penalty must be a number in [0, 1e+12]" in crashed["error"]
    for name in FINISHING:
        folder = process_sweep["results_dir"] / "trials" / name
        assert (folder / "model_vecnormalize.npz").is_file()
        assert json.loads((folder / "evaluations.json").read_text(encoding="utf-8"))
    assert not (process_sweep["results_dir"] / "tune").exists()


def test_resuming_trains_only_the_unfinished_trials(process_sweep) -> None:
    resumed = process_sweep["resumed"]
    assert resumed.returncode == 1, resumed.stderr
    for name in FINISHING:
        model = process_sweep["results_dir"] / "trials" / name / "model.zip"
        assert model.stat().st_mtime_ns == process_sweep["times"][name]
        assert f"finished   {name}" in resumed.stdout


def test_the_results_tools_read_the_process_sweep(process_sweep) -> None:
    from agents.sweep.results import read_sweep

    trials = read_sweep(process_sweep["results_dir"])
    assert sorted(t.name for t in trials if t.status == "finished") == sorted(FINISHING)


def test_starting_again_over_a_sweep_is_refused(process_sweep) -> None:
    again = sweep_without_ray("--config", str(process_sweep["config"]), "--processes", "1")
    assert again.returncode == 2
    assert "already holds a sweep: continue it with --resume" in again.stderr


@pytest.mark.parametrize(
    ("keys", "options", "message"),
    [
        (
            {"kind": "search", "grid": {}, "search": {"seed": {"choice": [0, 1]}}},
            ("--processes", "1"),
            "--processes runs grid sweeps only",
        ),
        ({}, ("--processes", "0"), "--processes must be an integer >= 1, got 0"),
        ({}, ("--processes", "1", "--address", "auto"), "--processes runs without Ray"),
        ({}, ("--processes", "1", "--resume"), "--resume: no sweep in"),
    ],
)
def test_what_processes_cannot_run_is_refused_in_one_line(
    tmp_path: Path, keys: dict[str, Any], options: tuple[str, ...], message: str
) -> None:
    config = tiny_sweep(tmp_path, **keys)
    run = sweep_without_ray("--config", str(config), *options)
    assert run.returncode == 2
    assert message in run.stderr.strip().splitlines()[-1]
    assert not (tmp_path / "sweep" / "trials").exists()


def test_a_trial_is_the_run_agents_train_makes_from_its_config(process_sweep, tmp_path) -> None:
    folder = process_sweep["results_dir"] / "trials" / FINISHING[1]
    assert retrained_differences(folder, tmp_path / "again") == []


def _children(pid: int) -> set[int]:
    """The processes ``pid`` started (Linux: ``/proc``)."""
    found = set()
    for task in Path(f"/proc/{pid}/task").iterdir():
        found |= {int(child) for child in (task / "children").read_text().split()}
    return found


def _alive(pid: int) -> bool:
    try:
        status = Path(f"/proc/{pid}/stat").read_text().split()[2]
    except FileNotFoundError:
        return False
    return status != "Z"


@pytest.mark.skipif(
    not Path(f"/proc/self/task/{os.getpid()}/children").is_file(),
    reason="reads a process's children from /proc (Linux)",
)
def test_sigterm_stops_the_sweep_and_its_workers(tmp_path: Path) -> None:
    """``kill PID`` on a sweep started in the background (which ignores Ctrl-C's SIGINT)
    stops it as Ctrl-C does, and takes its running trial's worker with it."""
    config = tiny_sweep(
        tmp_path,
        grid={"env_kwargs.transmission_penalty": [30.0]},
        overrides={
            **yaml.safe_load(TINY.read_text(encoding="utf-8"))["overrides"],
            "total_timesteps": 10_000_000,
        },
    )
    sweep = subprocess.Popen(
        command_without_ray("--config", str(config), "--processes", "1", sigint_ignored=True),
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    started = tmp_path / "sweep" / "trials" / "transmission_penalty=30" / LOCK_FILE
    deadline = time.monotonic() + 300
    while not started.is_file() and sweep.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    workers = _children(sweep.pid) if sweep.poll() is None else set()
    assert workers, f"the sweep ended or hung before its trial started: rc {sweep.poll()}"
    sweep.send_signal(signal.SIGTERM)
    _, stderr = sweep.communicate(timeout=120)
    assert sweep.returncode == 130, stderr
    assert "interrupted; finished trials are kept" in stderr
    deadline = time.monotonic() + 30
    while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(_alive(pid) for pid in workers), "a worker trains on after the sweep ended"
