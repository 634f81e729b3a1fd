"""A sweep's results folder read back: the reported scores, the summary, and
``agents.judge.pareto`` / ``agents.results`` on a sweep (``--sweep``). No Ray needed: the folder
is built here."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from stable_baselines3 import PPO

from agents.judge import pareto, results
from agents.sweep.results import (
    SweepTrial,
    final_scores,
    finished_trials,
    read_sweep,
    scores,
    trial_scores,
    trial_status,
    write_summary,
)
from agents.train.vector_adapter import make_sb3_vec_env

ENV_ID = "etsc/AttitudeTracking-v0"


def evaluation(
    learned_cost: float, learned_sent: int, paper_cost: float, paper_sent: int, learned_return=-1.0
):
    return {
        "timesteps": 1024,
        "learned": {
            "mean_cost": learned_cost,
            "transmissions": learned_sent,
            "return": learned_return,
            "failure": None,
        },
        "paper": {"mean_cost": paper_cost, "transmissions": paper_sent, "failure": None},
    }


def test_scores_compare_the_last_evaluation_with_the_paper_trigger() -> None:
    reported = scores(2048, -3.5, [evaluation(9.0, 99, 1.0, 120), evaluation(1.1, 30, 1.0, 120)])
    assert reported["timesteps"] == 2048 and reported["training_reward"] == -3.5
    assert reported["cost_ratio"] == pytest.approx(1.1)
    assert reported["transmission_ratio"] == pytest.approx(0.25)
    assert reported["paper_transmissions"] == 120
    no_paper_cost = scores(2048, None, [evaluation(0.5, 30, 0.0, 120)])
    assert "cost_ratio" not in no_paper_cost and "training_reward" not in no_paper_cost
    assert scores(10, None, []) == {"timesteps": 10}


def test_the_best_validation_return_is_the_kept_checkpoints_not_the_last() -> None:
    history = [evaluation(1.0, 30, 1.0, 120, learned_return=r) for r in (-9.0, -2.0, -5.0)]
    assert scores(3072, None, history)["best_validation_return"] == -2.0
    assert scores(1024, None, history[:1])["best_validation_return"] == -9.0


def test_an_untrained_policys_validation_is_not_the_score_of_the_kept_checkpoint() -> None:
    """A tuning scores a run by the checkpoint it keeps, which is never a policy no gradient
    step had touched (``"trained": false``, e.g. DQN before ``learning_starts``); before the
    first trained validation there is no such score."""
    untrained = evaluation(1.0, 30, 1.0, 120, learned_return=-1.0) | {"trained": False}
    trained = [
        evaluation(1.0, 30, 1.0, 120, learned_return=r) | {"trained": True} for r in (-6.0, -4.0)
    ]
    assert scores(4096, None, [untrained, *trained])["best_validation_return"] == -4.0
    assert "best_validation_return" not in scores(4096, None, [untrained])


def test_a_trial_of_several_seeds_scores_their_mean_once_all_finished(tmp_path: Path) -> None:
    runs = [tmp_path / "seed=0", tmp_path / "seed=1"]
    for run, best in zip(runs, (-4.0, -2.0), strict=True):
        run.mkdir()
        history = [evaluation(1.0, 30, 1.0, 120, learned_return=r) for r in (-9.0, best)]
        (run / "evaluations.json").write_text(json.dumps(history), encoding="utf-8")
    summary = {"timesteps": 2048, "recent_episodes": [{"return": -1.0}]}
    (runs[0] / "train_summary.json").write_text(json.dumps(summary), encoding="utf-8")
    assert trial_scores(runs) is None, "seed 1 has not finished"
    (runs[1] / "train_summary.json").write_text(json.dumps(summary), encoding="utf-8")
    both = trial_scores(runs)
    assert both is not None and both["best_validation_return"] == -3.0
    assert trial_scores(runs[:1]) == final_scores(runs[0])


def make_sweep(results_dir: Path) -> None:
    """A sweep folder of two trials: one finished with a small model, one failed."""
    finished = results_dir / "trials" / "transmission_penalty=30"
    failed = results_dir / "trials" / "transmission_penalty=-1"
    finished.mkdir(parents=True)
    env = make_sb3_vec_env(ENV_ID, 2, horizon_s=0.05)
    model = PPO("MlpPolicy", env, n_steps=16, batch_size=32, n_epochs=1, device="cpu", seed=0)
    model.learn(total_timesteps=32)
    model.save(finished / "model.zip")
    summary = {"timesteps": 32, "recent_episodes": [{"return": -1.0}, {"return": -3.0}]}
    (finished / "train_summary.json").write_text(json.dumps(summary), encoding="utf-8")
    failed.mkdir(parents=True)
    error = "ValueError: transmission_penalty must be >= 0, got -1.0"
    trials = [
        SweepTrial(
            "transmission_penalty=30",
            {"env_kwargs.transmission_penalty": 30.0},
            trial_status([finished], None),
            None,
            finished,
            final_scores(finished),
        ),
        SweepTrial(
            "transmission_penalty=-1",
            {"env_kwargs.transmission_penalty": -1.0},
            trial_status([failed], error),
            error,
            failed,
            None,
        ),
    ]
    write_summary(results_dir, {"env_id": ENV_ID, "kind": "front"}, trials)


def test_the_summary_reads_back_and_only_finished_trials_count(tmp_path: Path) -> None:
    make_sweep(tmp_path / "sweep")
    summary = json.loads((tmp_path / "sweep" / "sweep_summary.json").read_text("utf-8"))
    assert summary["counts"] == {"finished": 1, "failed": 1, "incomplete": 0}
    assert summary["trials"][0]["scores"] == {"timesteps": 32, "training_reward": -2.0}
    assert trial_status([tmp_path / "sweep" / "trials"], None) == "incomplete"
    trials = read_sweep(tmp_path / "sweep")
    assert [trial.status for trial in trials] == ["finished", "failed"]
    assert trials[1].error.startswith("ValueError: transmission_penalty")
    (finished,) = finished_trials(tmp_path / "sweep", ENV_ID)
    folder = tmp_path / "sweep" / "trials" / "transmission_penalty=30"
    assert finished.model == folder / "model.zip"
    (folder / "best_model.zip").write_bytes(b"")  # a run that validated: its best checkpoint
    (finished,) = finished_trials(tmp_path / "sweep", ENV_ID)
    assert finished.model == folder / "best_model.zip"
    with pytest.raises(ValueError, match="trained 'etsc/AttitudeTracking-v0', not"):
        finished_trials(tmp_path / "sweep", "etsc/InnerFormation-v0")
    with pytest.raises(ValueError, match=r"holds no sweep_summary\.json"):
        read_sweep(tmp_path)


def test_pareto_and_results_read_a_sweep_folder(tmp_path: Path) -> None:
    sweep = tmp_path / "sweep"
    make_sweep(sweep)
    model = str(sweep / "trials" / "transmission_penalty=30" / "model.zip")
    short = ["--env-arg", "horizon_s=0.05", "--set-size", "2"]
    assert pareto.main([ENV_ID, "--sweep", str(sweep), *short, "--out", str(tmp_path / "p")]) == 0
    front = json.loads((tmp_path / "p" / "pareto.json").read_text("utf-8"))
    assert [point["policy"] for point in front["curves"]["learned"]] == [f"sb3:{model}"]
    argv = [ENV_ID, "--sweep", str(sweep), "--scenarios", "paper", *short]
    assert results.main([*argv, "--out", str(tmp_path / "r")]) == 0
    written = sorted(path.parent.name for path in (tmp_path / "r").rglob("results.json"))
    assert written == ["transmission_penalty=30"]
    result = json.loads(
        (tmp_path / "r" / "transmission_penalty=30" / "results.json").read_text("utf-8")
    )
    assert result["models"] == [model]
    with pytest.raises(SystemExit):
        results.main([ENV_ID, "--sweep", str(tmp_path), *short])


def test_each_group_of_a_sweep_is_written_as_soon_as_it_is_judged(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A judgement that stops at its second group keeps the first group's results.json."""
    trials = [
        SweepTrial(f"transmission_penalty={value},seed=0", {}, "finished", None, tmp_path, None)
        for value in (1, 3)
    ]
    monkeypatch.setattr(results, "finished_trials", lambda folder, env_id: trials)
    judged: list[list[str]] = []

    def compare(env_id: str, models: list[str], *arguments: object, **keywords: object) -> dict:
        judged.append(models)
        if len(judged) == 2:
            raise ValueError("--model: the second group's model does not load")
        return {"env": env_id, "models": models}

    monkeypatch.setattr(results, "compare", compare)
    monkeypatch.setattr(results, "markdown", lambda result: "")
    out = tmp_path / "judged"
    with pytest.raises(SystemExit):
        results.main([ENV_ID, "--sweep", str(tmp_path), "--out", str(out)])
    assert len(judged) == 2
    first = json.loads((out / "transmission_penalty=1" / "results.json").read_text("utf-8"))
    assert first["models"] == judged[0]
    assert not (out / "transmission_penalty=3").exists()
