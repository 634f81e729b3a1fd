"""A sweep's results folder: the scores a trial reports, the sweep summary, and reading the
finished trials back (for ``agents.judge.pareto`` and ``agents.judge.results``). No Ray here.

Layout of a sweep's ``results_dir`` (see :mod:`agents.sweep.config`)::

    sweep_summary.json          every trial: name, swept values, status, error, final scores
    sweep_settings.json         the validated sweep config it started with (``--resume``
                                refuses changed settings)
    trials/<name>/              one ``agents.train`` run: model.zip, model_vecnormalize.npz,
                                config.yaml, evaluations.json, train_summary.json, ...
    tune/                       Ray Tune's experiment state (what ``--resume`` restores)

A trial's status is ``finished`` (its model was saved), ``failed`` (it raised; ``error`` says
what) or ``incomplete`` (neither: interrupted, or stopped early by a search's scheduler).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from agents.train.kept_checkpoint import kept_evaluation
from etsc_envs.core.files import atomic_write_text

SUMMARY_FILE = "sweep_summary.json"
SETTINGS_FILE = "sweep_settings.json"
TRIALS_DIR = "trials"
MODEL_FILE = "model.zip"
BEST_MODEL_FILE = "best_model.zip"
EVALUATIONS_FILE = "evaluations.json"
TRAIN_SUMMARY_FILE = "train_summary.json"
CONFIG_FILE = "config.yaml"
LEARNED_FILE = "learned.json"
"""A search trial's learned trigger (``agents.search``), written last."""
SEARCH_CURVE_FILE = "curve.json"
ORACLE_FILE = "oracle.json"
"""A clairvoyant-schedule trial's record (``agents.oracle``), written last."""
STATUSES = ("finished", "failed", "incomplete")

METRICS = (
    "timesteps",
    "training_reward",
    "learned_mean_cost",
    "learned_transmissions",
    "paper_mean_cost",
    "paper_transmissions",
    "cost_ratio",
    "transmission_ratio",
    "best_validation_return",
)
"""What a trial reports to Tune (all but the first two once the training callback has
evaluated): training steps, the mean return of the last training episodes, the last
evaluation's ``mean_cost`` and transmissions of the learned policy and of the paper trigger,
their ratios learned / paper (absent where the paper's value is 0), and the highest mean
validation return of the trained policies' evaluations so far
(:func:`agents.train.kept_checkpoint.kept_evaluation`) — the score of the checkpoint the run
keeps (``best_model.zip``), which a hyperparameter search maximises."""

EVALUATION_METRICS = METRICS[2:]
"""The metrics that come from the training run's evaluations against the paper trigger."""


def scores(
    timesteps: int, training_reward: float | None, evaluations: list[dict[str, Any]]
) -> dict[str, Any]:
    """The reported metrics (:data:`METRICS`) from the training steps, the mean training
    return (``None`` before an episode ended) and the entries of ``evaluations.json`` so far
    (none before the first evaluation)."""
    result: dict[str, Any] = {"timesteps": int(timesteps)}
    if training_reward is not None:
        result["training_reward"] = float(training_reward)
    if not evaluations:
        return result
    learned, paper = evaluations[-1]["learned"], evaluations[-1]["paper"]
    for name, summary in (("learned", learned), ("paper", paper)):
        result[f"{name}_mean_cost"] = summary["mean_cost"]
        result[f"{name}_transmissions"] = summary["transmissions"]
    for ratio, key in (("cost_ratio", "mean_cost"), ("transmission_ratio", "transmissions")):
        if paper[key]:
            result[ratio] = learned[key] / paper[key]
    kept = kept_evaluation(evaluations)
    if kept is not None:
        result["best_validation_return"] = float(kept["learned"]["return"])
    return result


def evaluations_so_far(folder: str | Path) -> list[dict[str, Any]]:
    """The entries of a training run's ``evaluations.json`` (none if it has not evaluated)."""
    path = Path(folder) / EVALUATIONS_FILE
    if not path.is_file():
        return []
    return json.loads(path.read_text(encoding="utf-8"))


def final_scores(folder: str | Path) -> dict[str, Any] | None:
    """The metrics of a finished training run, from its ``train_summary.json`` (steps and the
    mean return of its last episodes) and ``evaluations.json``, or of a finished search (its
    env steps and the chosen trigger's validation return, from ``curve.json``); ``None`` if it
    did not finish."""
    if (Path(folder) / ORACLE_FILE).is_file():
        oracle = json.loads((Path(folder) / ORACLE_FILE).read_text(encoding="utf-8"))
        return {
            "trigger_transmissions": oracle["trigger"]["transmissions"],
            "fewest_transmissions": oracle["fewest_transmissions"]["transmissions"],
            "trigger_mean_cost": oracle["trigger"]["mean_cost"],
            "least_mean_cost": oracle["least_cost"]["mean_cost"],
        }
    if (Path(folder) / LEARNED_FILE).is_file():
        search = json.loads((Path(folder) / SEARCH_CURVE_FILE).read_text(encoding="utf-8"))
        return {
            "env_steps": search["search"]["env_steps"],
            "validation_return": search["search"]["validation_return"],
        }
    summary_path = Path(folder) / TRAIN_SUMMARY_FILE
    if not summary_path.is_file():
        return None
    summary = json.loads(summary_path.read_text(encoding="utf-8"))
    returns = [episode["return"] for episode in summary.get("recent_episodes", [])]
    reward = float(np.mean(returns)) if returns else None
    return scores(summary["timesteps"], reward, evaluations_so_far(folder))


def trial_scores(runs: Sequence[Path]) -> dict[str, Any] | None:
    """The scores of a trial made of the training ``runs`` (folders,
    :meth:`~agents.sweep.config.SweepConfig.trial_runs`): one run's :func:`final_scores`, or for
    a trial of several seeds the mean over the seeds of each score every one reports; ``None``
    until every run has finished."""
    each = [final_scores(run) for run in runs]
    if any(scores is None for scores in each):
        return None
    if len(each) == 1:
        return each[0]
    shared = [key for key in each[0] if all(key in scores for scores in each)]
    return {key: float(np.mean([scores[key] for scores in each])) for key in shared}


@dataclasses.dataclass(frozen=True)
class SweepTrial:
    """One trial of a sweep as the summary records it."""

    name: str
    values: dict[str, Any]
    status: str
    error: str | None
    folder: Path
    scores: dict[str, Any] | None

    @property
    def model(self) -> Path:
        """The model the trial is judged by: a search's learned trigger; else (its
        normalisation statistics lie beside it) the checkpoint of the best validation return
        (``best_model.zip``) where the run validated, since the protocol chooses checkpoints on
        the validation set; else the final model."""
        for name in (LEARNED_FILE, BEST_MODEL_FILE):
            if (self.folder / name).is_file():
                return self.folder / name
        return self.folder / MODEL_FILE

    def record(self, results_dir: Path) -> dict[str, Any]:
        """The trial's entry in ``sweep_summary.json`` (folder relative to ``results_dir``)."""
        return {
            "name": self.name,
            "values": self.values,
            "status": self.status,
            "error": self.error,
            "folder": self.folder.relative_to(results_dir).as_posix(),
            "scores": self.scores,
        }


def trial_finished(folder: str | Path) -> bool:
    """Whether the trial in ``folder`` finished: ``agents.train`` writes its summary last,
    after the model, ``agents.search`` its learned trigger after its last generation and
    ``agents.oracle`` its record at its end."""
    folder = Path(folder)
    trained = (folder / MODEL_FILE).is_file() and (folder / TRAIN_SUMMARY_FILE).is_file()
    return trained or (folder / LEARNED_FILE).is_file() or (folder / ORACLE_FILE).is_file()


def trial_status(runs: Sequence[Path], error: str | None) -> str:
    """``failed`` if the trial raised, else ``finished`` if each of its ``runs`` (folders of a
    training, search or oracle run: one, or one per seed) finished, else ``incomplete``."""
    if error is not None:
        return "failed"
    return "finished" if all(trial_finished(run) for run in runs) else "incomplete"


def write_summary(results_dir: str | Path, sweep: dict[str, Any], trials: list[SweepTrial]) -> Path:
    """Write ``sweep_summary.json`` (whole or not at all): the sweep's description and every
    trial's record, with the count of trials in each status."""
    results_dir = Path(results_dir)
    counts = {status: sum(trial.status == status for trial in trials) for status in STATUSES}
    summary = {
        **sweep,
        "counts": counts,
        "trials": [trial.record(results_dir) for trial in trials],
    }
    return atomic_write_text(results_dir / SUMMARY_FILE, json.dumps(summary, indent=2) + "\n")


def read_summary(results_dir: str | Path, argument: str = "--sweep") -> dict[str, Any]:
    """The ``sweep_summary.json`` of the sweep whose results folder is ``results_dir``
    (``ValueError`` naming the command's ``argument`` if it holds none, or not a readable one)."""
    path = Path(results_dir) / SUMMARY_FILE
    if not path.is_file():
        raise ValueError(
            f"{argument}: {str(results_dir)!r} holds no {SUMMARY_FILE}; give the results_dir "
            f"of a sweep run with python -m agents.sweep"
        )
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ValueError(f"{argument}: {path} is not readable JSON ({error})") from None
    if not isinstance(summary, dict) or not isinstance(summary.get("trials"), list):
        raise ValueError(f"{argument}: {path} is not a sweep summary (no list of trials)")
    return summary


def read_sweep(results_dir: str | Path, argument: str = "--sweep") -> list[SweepTrial]:
    """Every trial of the sweep whose results folder is ``results_dir``, from its summary
    (errors name the command's ``argument``)."""
    results_dir = Path(results_dir)
    summary = read_summary(results_dir, argument)
    return [
        SweepTrial(
            name=entry["name"],
            values=entry["values"],
            status=entry["status"],
            error=entry["error"],
            folder=results_dir / entry["folder"],
            scores=entry["scores"],
        )
        for entry in summary["trials"]
    ]


def finished_trials(results_dir: str | Path, env_id: str) -> list[SweepTrial]:
    """The finished trials of a sweep of ``env_id`` (``ValueError`` if the sweep trained
    another id or has no finished trial)."""
    summary = read_summary(results_dir)
    if summary.get("env_id") != env_id:
        raise ValueError(
            f"--sweep: {str(results_dir)!r} trained {summary.get('env_id')!r}, not {env_id!r}"
        )
    finished = [trial for trial in read_sweep(results_dir) if trial.status == "finished"]
    if not finished:
        raise ValueError(f"--sweep: {str(results_dir)!r} has no finished trial")
    return finished


def sweep_models(results_dirs: list[str | Path], env_id: str) -> list[str]:
    """The model paths of the finished trials of every sweep in ``results_dirs``."""
    return [
        str(trial.model)
        for results_dir in results_dirs
        for trial in finished_trials(results_dir, env_id)
    ]


def one_line_error(error: BaseException) -> str:
    """A trial's error as ``Type: first line of its message``, the underlying exception's when
    Ray wraps it (in its ``cause``)."""
    cause = getattr(error, "cause", None) or error
    lines = str(cause).strip().splitlines()
    return f"{type(cause).__name__}: {lines[0]}" if lines else type(cause).__name__
