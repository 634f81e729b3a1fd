"""One trial of a sweep, as Ray Tune runs it: one ``agents.train`` run that reports its
progress to Tune (or, with ``trial_seeds``, one run per seed, reported together at the end),
or one ``agents.search`` run (:mod:`agents.sweep.learners`).

The trial's folder is ``results_dir/trials/<name>`` (:meth:`SweepConfig.trial_name`). A trial
that Tune restarts after an interruption does not train again if its training had finished
(an interruption can land between the saved model and Tune's record of the trial's end); else
it continues from the newest checkpoint in that folder when the training config saves
checkpoints, or starts again.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from ray import tune
from stable_baselines3.common.callbacks import BaseCallback

from agents.sweep.config import SweepConfig
from agents.sweep.learners import run_trial as run_learner
from agents.sweep.results import (
    evaluations_so_far,
    scores,
    trial_finished,
    trial_scores,
)


class TuneReportCallback(BaseCallback):
    """After every rollout but the last, report to Tune the training steps, the mean return of
    the recent training episodes and the training run's evaluations against the paper
    trigger (read from its ``evaluations.json``; see :func:`agents.sweep.results.scores`).

    The last rollout (``total_timesteps`` reached) reports nothing: a scheduler stops a trial
    that reports its full length, which would end it before its model is saved; the trial
    reports its final scores after training instead. Nor does a rollout whose scores lack the
    ``metric`` that the sweep's scheduler or search optimises (Tune refuses such a report),
    e.g. before the first evaluation."""

    def __init__(
        self, run_folder: str | Path, total_timesteps: int, metric: str | None = None
    ) -> None:
        super().__init__()
        self.run_folder = Path(run_folder)
        self.total_timesteps = total_timesteps
        self.metric = metric

    def _on_step(self) -> bool:
        return True

    def _on_rollout_end(self) -> None:
        if self.num_timesteps >= self.total_timesteps:
            return
        episodes = self.model.ep_info_buffer
        reward = float(np.mean([episode["r"] for episode in episodes])) if episodes else None
        reported = scores(self.num_timesteps, reward, evaluations_so_far(self.run_folder))
        if self.metric is None or self.metric in reported:
            tune.report(reported)


def run_trial(values: dict[str, Any], sweep: SweepConfig) -> None:
    """Tune's trainable: train the trial with the swept ``values`` into its folder (once per
    seed of ``trial_seeds``, each seed's run into its own subfolder), report as it goes (a
    trial of one run), and report the final scores once every run has saved its model."""
    name = sweep.trial_name(values, tune.get_context().get_trial_id())
    runs = sweep.trial_runs(values, sweep.trial_folder(name))
    for run_values, folder in runs:
        if trial_finished(folder):
            continue
        callbacks = []
        if sweep.learner == "train" and len(runs) == 1:
            timesteps = int(sweep.trial_mapping(run_values, folder)["total_timesteps"])
            callbacks.append(TuneReportCallback(folder, timesteps, sweep.metric))
        run_learner(sweep, run_values, folder, callbacks)
    tune.report(trial_scores([folder for _, folder in runs]))


def trial_dirname(sweep: SweepConfig, trial: Any) -> str:
    """Tune's folder name of a trial: the same readable name as its results folder."""
    return sweep.trial_name(trial.config, trial.trial_id)
