"""What one trial of a sweep runs, by the sweep's ``learner``: an ``agents.train`` run, an
``agents.search`` run (each continuing where an interrupted start of the same trial stopped)
or an ``agents.oracle`` run, each into the trial's folder.

Both the Ray path (:mod:`agents.sweep.trial`) and the worker-process path
(:mod:`agents.sweep.processes`) run a trial through :func:`run_trial`.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import yaml
from stable_baselines3.common.callbacks import BaseCallback

from agents.oracle.run import OracleConfig, run_oracle
from agents.search.cma_es import Evaluator, SearchConfig, run_search
from agents.sweep.config import SweepConfig
from agents.sweep.results import CONFIG_FILE, EVALUATIONS_FILE
from agents.train.training import CHECKPOINT_DIR, latest_checkpoint, train
from etsc_envs.core.files import atomic_write_text


def run_trial(
    sweep: SweepConfig,
    values: dict[str, Any],
    folder: Path,
    callbacks: Sequence[BaseCallback] = (),
) -> None:
    """Run the trial with the swept ``values`` into ``folder``.

    A training trial continues from its newest checkpoint where its config saves them (else
    it starts again, dropping an interrupted start's evaluations); ``callbacks`` join its
    training. A search trial replays its recorded generations and continues (its candidates
    are scored one after another in this process: the sweep runs trials in parallel)."""
    config = sweep.trial_config(values, folder)
    if isinstance(config, OracleConfig):  # a finished one is not run again
        run_oracle(config, folder)
        return
    if isinstance(config, SearchConfig):
        folder.mkdir(parents=True, exist_ok=True)
        mapping = sweep.trial_mapping(values, folder)
        atomic_write_text(folder / CONFIG_FILE, yaml.safe_dump(mapping, sort_keys=False))
        evaluator = Evaluator(processes=0, address=None)
        run_search(config, folder, evaluator, progress=lambda line: print(line, flush=True))
        return
    resume = latest_checkpoint(folder / CHECKPOINT_DIR) is not None
    if not resume:  # an interrupted start's evaluations are not this run's
        (folder / EVALUATIONS_FILE).unlink(missing_ok=True)
    train(config, resume=resume, callbacks=list(callbacks))
