"""Train a trigger policy with Stable-Baselines3 from a YAML config.

``python -m agents.train --config configs/train/NAME.yaml [--timesteps N] [--seed S] [--out DIR]
[--resume]``

Writes to the output directory ``model.zip`` (a plain SB3 save, loadable by
``python -m baselines.evaluate ENV_ID --policy sb3:DIR/model.zip``) with
``model_vecnormalize.npz`` beside it when observations are normalised and
``model_decisions.json`` when it takes self-triggered decisions (config key ``decisions``),
``config.yaml`` (the
config after the command-line overrides and defaults), ``train_summary.json`` (wall time,
timesteps, steps per second and the last episodes' returns and metrics), and as configured
``checkpoints/``, ``tensorboard/`` and ``evaluations.json`` (the policy against the paper's
trigger during training). ``--resume`` continues from the newest intact checkpoint in
``checkpoints/`` up to ``total_timesteps``, keeping the evaluation history up to that
checkpoint; it refuses checkpoints written under another config (``checkpoints/run.yaml``
records the config that wrote them; only :data:`RESUMABLE_CHANGES` may differ).

Every output file is written through a temporary file and a rename
(:mod:`etsc_envs.core.files`), so an interrupted run leaves whole files or none; a run that
fails before writing anything leaves no ``out_dir`` behind. Interrupted (Ctrl-C), the command
prints one line saying how to continue and exits with status 130.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import importlib.util
import json
import shutil
import sys
import time
import warnings
import zipfile
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import filelock
import gymnasium as gym
import numpy as np
import torch
import yaml
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import (
    BaseCallback,
    CallbackList,
    CheckpointCallback,
    ProgressBarCallback,
)
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.on_policy_algorithm import OnPolicyAlgorithm
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv, VecMonitor, VecNormalize

import etsc_envs
from agents.train.config import TrainConfig, load_config
from agents.train.elapsed_discount import (
    ElapsedReplayBuffer,
    ElapsedRolloutBuffer,
    ElapsedStepsCallback,
    MaskableElapsedRolloutBuffer,
)
from agents.train.model_files import write_model
from agents.train.validation_callback import PaperComparisonCallback
from agents.train.vector_adapter import make_sb3_vec_env, make_shared_policy_vec_env
from etsc_envs.core.files import atomic_write_text
from etsc_envs.decisions import DecisionSet, decision_set_path, make_decision_env
from etsc_envs.sb3_models import (
    ENV_ID_ATTRIBUTE,
    ObservationStatistics,
    legacy_normalization_path,
    normalization_path,
)

MODEL_FILE = "model.zip"
CONFIG_FILE = "config.yaml"
SUMMARY_FILE = "train_summary.json"
EVALUATIONS_FILE = "evaluations.json"
BEST_MODEL_FILE = "best_model.zip"
"""The model with the best mean return on the validation scenarios so far (checkpoint
choice follows the test protocol), its observation statistics beside it."""
CHECKPOINT_DIR = "checkpoints"
CHECKPOINT_PREFIX = "model"
LOCK_FILE = ".train.lock"
"""In ``out_dir``: the file a run holds an OS lock on while it trains there (the file stays;
the lock ends with the run or its process)."""
RUN_FILE = "run.yaml"
"""In ``checkpoints/``: the config of the run that writes the checkpoints there."""
TENSORBOARD_DIR = "tensorboard"
RESUMABLE_CHANGES = (
    "total_timesteps",
    "out_dir",
    "checkpoint_every",
    "evaluation_every",
    "tensorboard",
    "torch_threads",
)
"""Config keys a ``--resume`` may change; any other difference from the checkpoints' config
refuses the resume (the run would continue another experiment under this config's name)."""
ELAPSED_BUFFERS = {
    "PPO": ElapsedRolloutBuffer,
    "A2C": ElapsedRolloutBuffer,
    "MaskablePPO": MaskableElapsedRolloutBuffer,
}
"""Algorithm → the rollout buffer that discounts self-triggered decisions by elapsed instants."""
RECENT_EPISODES_KEPT = 5
"""How many of the last finished episodes ``train_summary.json`` reports."""


class EpisodeMetricsCallback(BaseCallback):
    """Keeps the return, length and ``info["episode_metrics"]`` of the last finished episodes."""

    def __init__(self, kept: int = RECENT_EPISODES_KEPT) -> None:
        super().__init__()
        self.recent_episodes: deque[dict[str, Any]] = deque(maxlen=kept)
        self.episodes_finished = 0

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            if "episode_metrics" in info:
                self.episodes_finished += 1
                self.recent_episodes.append(_episode_record(info))
        return True


def _episode_record(info: dict[str, Any]) -> dict[str, Any]:
    """Return and length from the Monitor wrapper, then the environment's episode metrics."""
    monitor = info.get("episode", {})
    record = {"return": monitor.get("r"), "length": monitor.get("l")}
    record.update(info["episode_metrics"])
    return {name: _plain(value) for name, value in record.items()}


def _plain(value: Any) -> Any:
    """NumPy scalars as Python numbers, so that the record is JSON-serialisable."""
    return value.item() if isinstance(value, np.generic) else value


def train(
    config: TrainConfig,
    resume: bool = False,
    callbacks: Sequence[BaseCallback] = (),
    overwrite: bool = False,
) -> Path:
    """Train the configured model (from the newest intact checkpoint if ``resume``), write the
    output files and return the output folder. ``callbacks`` run after the run's own (episode
    metrics, checkpoints, evaluations), e.g. to report progress to a tuner. A bad env kwarg,
    hyperparameter, ``init_from`` or checkpoint raises ``ValueError`` before ``out_dir`` is
    created.

    ``out_dir`` belongs to one run: a fresh run refuses a folder holding another run's model,
    summary or checkpoints unless ``overwrite`` (which removes that run's files first), and a
    lock file (:data:`LOCK_FILE`, held for the whole run) refuses a second process training
    into the same folder."""
    torch.set_num_threads(config.torch_threads)
    out_dir = Path(config.out_dir)
    created = not out_dir.exists()
    out_dir.mkdir(parents=True, exist_ok=True)
    try:
        with _run_lock(out_dir):
            checkpoint = resume_checkpoint(config) if resume else None
            if not resume:
                _clear_earlier_run(out_dir, overwrite)
            return _train(config, out_dir, checkpoint, callbacks)
    except BaseException:
        if created:
            _remove_empty_folders(out_dir, ignored=LOCK_FILE)
        raise


@contextlib.contextmanager
def _run_lock(out_dir: Path) -> Iterator[None]:
    """Hold ``out_dir``'s :data:`LOCK_FILE` for the block, or ``ValueError`` when another
    process holds it (the ``filelock`` package: an OS lock, released when the process ends)."""
    lock = filelock.FileLock(out_dir / LOCK_FILE, timeout=0)
    try:
        lock.acquire()
    except filelock.Timeout:
        raise ValueError(
            f"out_dir {str(out_dir)!r} is in use by another agents.train run (it holds "
            f"{LOCK_FILE}); wait for it to end or train into another out_dir"
        ) from None
    try:
        yield
    finally:
        lock.release()


def _earlier_run_files(out_dir: Path) -> list[Path]:
    """The files and folders of a run in ``out_dir`` (its model with the files beside it,
    config, summary, evaluations, checkpoints, TensorBoard logs)."""
    models = [out_dir / MODEL_FILE, out_dir / BEST_MODEL_FILE]
    beside = [
        path
        for model in models
        for path in (
            normalization_path(model),
            legacy_normalization_path(model),
            decision_set_path(model),
        )
    ]
    named = [
        out_dir / name
        for name in (
            CONFIG_FILE,
            SUMMARY_FILE,
            EVALUATIONS_FILE,
            CHECKPOINT_DIR,
            TENSORBOARD_DIR,
        )
    ]
    return [path for path in (*models, *beside, *named) if path.exists()]


def _clear_earlier_run(out_dir: Path, overwrite: bool) -> None:
    """Before a fresh run: ``ValueError`` if ``out_dir`` holds a finished run's model or
    summary, or an earlier run's checkpoints (a later resume would take the highest step
    count, whichever run wrote it), unless ``overwrite``, which removes that run's files."""
    earlier = [out_dir / MODEL_FILE, out_dir / SUMMARY_FILE]
    newest = latest_checkpoint(out_dir / CHECKPOINT_DIR)
    found = [path for path in earlier if path.is_file()] + ([newest] if newest else [])
    if not found:
        return
    if not overwrite:
        raise ValueError(
            f"out_dir {str(out_dir)!r} holds an earlier run ({found[0]}); continue it with "
            "--resume, replace it with --overwrite, or train into another out_dir"
        )
    for path in _earlier_run_files(out_dir):
        if path.is_dir():
            shutil.rmtree(path)
        else:
            path.unlink()


def _train(
    config: TrainConfig,
    out_dir: Path,
    checkpoint: Path | None,
    callbacks: Sequence[BaseCallback],
) -> Path:
    env = _checked(
        "env_kwargs", make_training_env, config, checkpoint, exceptions=(TypeError, ValueError)
    )
    model = _build_model(config, env, checkpoint, out_dir)
    decisions = decision_set(config, env)
    if checkpoint is None and config.checkpoint_every:
        _write_config(config, out_dir / CHECKPOINT_DIR / RUN_FILE)
    if decisions is not None and config.env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        env.env_method("follow_model", model)  # parameter sharing: teammates act as the model
    metrics_callback = EpisodeMetricsCallback()
    start = time.perf_counter()
    periodic = _periodic_callbacks(config, out_dir, env.num_envs, checkpoint, decisions)
    progress = [TrainingProgressBar()] if _progress_bar_available() else []
    remaining = max(config.total_timesteps - model.num_timesteps, 0)
    steps = whole_rollout_steps(remaining, model)
    if steps != remaining:
        print(
            f"training {steps} steps for total_timesteps {remaining}: {type(model).__name__} "
            f"collects whole rollouts of n_steps x n_envs = {model.n_steps} x {model.n_envs}",
            flush=True,
        )
    elapsed = [ElapsedStepsCallback()] if _discounts_elapsed_instants(config) else []
    try:
        model.learn(
            total_timesteps=steps,
            callback=CallbackList([*elapsed, metrics_callback, *periodic, *callbacks, *progress]),
            reset_num_timesteps=checkpoint is None,
        )
    finally:
        for bar in progress:  # an interrupted learn() skips the bar's own close
            if hasattr(bar, "pbar"):
                bar.pbar.close()
    wall_time_s = time.perf_counter() - start
    write_model(model, out_dir / MODEL_FILE, decisions)
    env.close()
    _write_config(config, out_dir / CONFIG_FILE)
    summary = _summary(config, model, metrics_callback, wall_time_s)
    summary["resumed_from"] = None if checkpoint is None else str(checkpoint)
    atomic_write_text(out_dir / SUMMARY_FILE, json.dumps(summary, indent=2) + "\n")
    return out_dir


def _checked(
    key: str,
    build: Callable[..., Any],
    *args: Any,
    exceptions: tuple[type[BaseException], ...],
) -> Any:
    """``build(*args)``, with the ``exceptions`` it raises turned into one ``ValueError`` line
    naming the config ``key``."""
    try:
        return build(*args)
    except exceptions as error:
        message = " ".join(str(error).split())
        raise ValueError(f"config key {key!r}: {message}") from None


def _build_model(
    config: TrainConfig, env: VecEnv, checkpoint: Path | None, out_dir: Path
) -> BaseAlgorithm:
    """A new model (with ``init_from``'s weights if configured), or the resumed checkpoint."""
    tensorboard_log = str(out_dir / TENSORBOARD_DIR) if config.tensorboard else None
    if checkpoint is not None:
        return config.algorithm_class.load(
            checkpoint, env=env, device="cpu", tensorboard_log=tensorboard_log
        )
    model = _checked(
        "hyperparameters",
        functools.partial(
            config.algorithm_class,
            config.policy,
            env,
            seed=config.seed,
            tensorboard_log=tensorboard_log,
            **config.hyperparameters,
            **_elapsed_discount_kwargs(config),
        ),
        exceptions=(AssertionError, TypeError, ValueError),
    )
    setattr(model, ENV_ID_ATTRIBUTE, config.env_id)
    if config.init_from is not None:  # checked to fit the env by the config
        model.set_parameters(config.init_from, device="cpu")
    return model


def _discounts_elapsed_instants(config: TrainConfig) -> bool:
    """Whether the run's rollout buffer discounts self-triggered decisions by elapsed instants
    (and needs :class:`ElapsedStepsCallback` to tell it them)."""
    return config.decisions is not None and config.algorithm in ELAPSED_BUFFERS


def _elapsed_discount_kwargs(config: TrainConfig) -> dict[str, Any]:
    """The algorithm's keyword arguments that discount self-triggered decisions by elapsed
    instants: an elapsed rollout buffer, or for DQN the replay buffer whose target is
    ``r + gamma ** n * max Q'`` (none for per-instant decisions)."""
    if _discounts_elapsed_instants(config):
        return {"rollout_buffer_class": ELAPSED_BUFFERS[config.algorithm]}
    if config.decisions is not None and config.algorithm == "DQN":
        gamma = config.hyperparameters.get("gamma", 0.99)
        return {
            "replay_buffer_class": ElapsedReplayBuffer,
            "replay_buffer_kwargs": {"gamma": gamma},
        }
    return {}


def training_decision_env(config: TrainConfig) -> gym.Env:
    """One env of ``config.env_id`` taking ``config.decisions``, discounting within an interval
    by the algorithm's ``gamma`` (for a PettingZoo id, one agent's decisions)."""
    return make_decision_env(
        config.env_id,
        config.env_kwargs,
        config.decisions,
        gamma=config.hyperparameters.get("gamma", 0.99),
    )


def decision_set(config: TrainConfig, env: VecEnv) -> DecisionSet | None:
    """The decision set of the training envs (``None`` without ``decisions``)."""
    return None if config.decisions is None else env.get_attr("decisions", [0])[0]


class AtomicCheckpointCallback(CheckpointCallback):
    """SB3's checkpoints (``model_<N>_steps.zip`` with ``model_vecnormalize_<N>_steps.npz``
    and, for self-triggered decisions, ``model_<N>_steps_decisions.json``), written through
    temporary files, the model last (:func:`~agents.train.model_files.write_model`)."""

    def __init__(self, *args: Any, decisions: DecisionSet | None = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.decisions = decisions

    def _on_step(self) -> bool:
        if self.n_calls % self.save_freq == 0:
            write_model(
                self.model,
                Path(self._checkpoint_path(extension="zip")),
                self.decisions,
                statistics_path=Path(self._checkpoint_path("vecnormalize_", extension="npz")),
            )
        return True


class TrainingProgressBar(ProgressBarCallback):
    """SB3's progress bar without the ``TqdmExperimentalWarning`` ("rich is experimental")
    that tqdm raises each time the bar opens: a warning on every training run that says
    nothing about the run."""

    def _on_training_start(self) -> None:
        from tqdm import TqdmExperimentalWarning

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TqdmExperimentalWarning)
            super()._on_training_start()


def whole_rollout_steps(timesteps: int, model: BaseAlgorithm) -> int:
    """The steps ``model.learn(timesteps)`` takes: an on-policy algorithm (PPO, A2C) collects
    whole rollouts of ``n_steps`` in each of its ``n_envs`` environments, so the budget rounds
    up to a multiple of ``n_steps * n_envs`` (off-policy algorithms stop at the budget)."""
    if not isinstance(model, OnPolicyAlgorithm):
        return timesteps
    rollout = model.n_steps * model.n_envs
    return -(-timesteps // rollout) * rollout


def latest_checkpoint(folder: Path) -> Path | None:
    """The checkpoint with the most timesteps in ``folder`` (``model_<N>_steps.zip``)."""
    checkpoints = checkpoints_newest_first(folder)
    return checkpoints[0] if checkpoints else None


def checkpoints_newest_first(folder: Path) -> list[Path]:
    """The checkpoints in ``folder`` (``model_<N>_steps.zip``), most timesteps first."""
    return sorted(
        (path for path in folder.glob(f"{CHECKPOINT_PREFIX}_*_steps.zip") if _steps(path)),
        key=_steps,
        reverse=True,
    )


def _steps(checkpoint: Path) -> int | None:
    """The ``N`` of ``model_<N>_steps.zip``, or ``None`` for another name."""
    middle = checkpoint.stem.removeprefix(f"{CHECKPOINT_PREFIX}_").removesuffix("_steps")
    return int(middle) if middle.isdigit() else None


def resume_checkpoint(config: TrainConfig) -> Path:
    """The newest intact checkpoint of ``config``'s run, or ``ValueError``: no checkpoint, a
    checkpoint folder written under another config (or of unknown config), or none intact.
    A torn checkpoint (unreadable zip, missing or unreadable statistics) is skipped with a
    note on standard error."""
    folder = Path(config.out_dir) / CHECKPOINT_DIR
    checkpoints = checkpoints_newest_first(folder)
    if not checkpoints:
        raise ValueError(f"--resume: no checkpoint in {folder}")
    _require_same_run(config, folder)
    normalized = config.normalize_observations or config.normalize_rewards
    for checkpoint in checkpoints:
        problem = _checkpoint_problem(checkpoint, normalized)
        if problem is None:
            return checkpoint
        print(f"--resume: skipping {checkpoint.name}: {problem}", file=sys.stderr)
    raise ValueError(f"--resume: no intact checkpoint in {folder} (all {len(checkpoints)} torn)")


def _require_same_run(config: TrainConfig, folder: Path) -> None:
    """``ValueError`` unless ``folder/run.yaml`` records ``config`` up to
    :data:`RESUMABLE_CHANGES`."""
    record = folder / RUN_FILE
    try:
        recorded = yaml.safe_load(record.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError):
        recorded = None
    if not isinstance(recorded, dict):
        raise ValueError(
            f"--resume: {record} is missing or unreadable, so the checkpoints in {folder} "
            "cannot be matched to this config; train afresh into another out_dir"
        )
    current = config.as_dict()
    differing = sorted(
        key
        for key in set(current) | set(recorded)
        if key not in RESUMABLE_CHANGES and current.get(key) != recorded.get(key)
    )
    if differing:
        changes = ", ".join(
            f"{key}: {recorded.get(key)!r} -> {current.get(key)!r}" for key in differing
        )
        raise ValueError(
            f"--resume: the checkpoints in {folder} belong to another config ({changes}); "
            "resume with the config that wrote them or train into another out_dir"
        )


def _checkpoint_problem(checkpoint: Path, normalized: bool) -> str | None:
    """Why ``checkpoint`` cannot be resumed from (``None`` if it can)."""
    try:
        with zipfile.ZipFile(checkpoint) as archive:
            damaged = archive.testzip()
            names = set(archive.namelist())
    except (OSError, zipfile.BadZipFile) as error:
        return f"unreadable zip ({error})"
    if damaged is not None or not {"data", "policy.pth"} <= names:
        return "damaged or incomplete zip"
    if not normalized:
        return None
    statistics = _checkpoint_statistics(checkpoint)
    if not statistics.is_file():
        return f"its statistics {statistics.name} are missing"
    try:
        ObservationStatistics.read(statistics)
    except ValueError:
        return f"its statistics {statistics.name} are unreadable"
    return None


def _remove_empty_folders(folder: Path, ignored: str | None = None) -> None:
    """Remove ``folder`` and its subfolders if no file is left in them (a file named
    ``ignored`` directly in ``folder`` does not count, and goes with it)."""
    if not folder.is_dir():
        return
    for child in folder.iterdir():
        _remove_empty_folders(child)
    if all(child.name == ignored and child.is_file() for child in folder.iterdir()):
        for child in folder.iterdir():
            child.unlink()
        folder.rmdir()


def _previous_evaluations(out_dir: Path, checkpoint: Path) -> list[dict[str, Any]]:
    """The evaluations an earlier run recorded up to ``checkpoint``'s timesteps (those after it
    are of training the resume repeats)."""
    try:
        history = json.loads((out_dir / EVALUATIONS_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    if not isinstance(history, list):
        return []
    steps = _steps(checkpoint)
    return [
        entry
        for entry in history
        if isinstance(entry, dict) and isinstance(entry.get("timesteps"), int)
        if entry["timesteps"] <= steps
    ]


def _periodic_callbacks(
    config: TrainConfig,
    out_dir: Path,
    num_envs: int,
    checkpoint: Path | None,
    decisions: DecisionSet | None = None,
) -> list[BaseCallback]:
    """Evaluations against the paper trigger and checkpoints, as configured (``num_envs``:
    the training ``VecEnv``'s sub-environments, whose steps the intervals count; a resume from
    ``checkpoint`` keeps the evaluations recorded up to it). At a step that has both, the
    evaluation is recorded first, so that every checkpoint on disk has its evaluation."""
    callbacks: list[BaseCallback] = []
    if config.evaluation_every:
        evaluation = PaperComparisonCallback(
            config.env_id,
            {**config.env_kwargs, **config.evaluation_env_kwargs},
            config.evaluation_every,
            out_dir / EVALUATIONS_FILE,
            config.evaluation_scenarios,
            out_dir / BEST_MODEL_FILE,
            decisions,
            starts_trained=config.init_from is not None,
        )
        if checkpoint is not None:
            evaluation.restore(_previous_evaluations(out_dir, checkpoint))
        callbacks.append(evaluation)
    if config.checkpoint_every:
        callbacks.append(
            AtomicCheckpointCallback(
                save_freq=max(config.checkpoint_every // num_envs, 1),
                save_path=str(out_dir / CHECKPOINT_DIR),
                name_prefix=CHECKPOINT_PREFIX,
                save_vecnormalize=config.normalize_observations or config.normalize_rewards,
                decisions=decisions,
            )
        )
    return callbacks


def make_training_env(config: TrainConfig, checkpoint: Path | None = None) -> VecEnv:
    """``config.n_envs`` environments of ``config.env_id`` as one SB3 ``VecEnv`` with episode
    statistics and, as configured, normalisation (restored from ``checkpoint``'s statistics
    when resuming): with ``decisions``, a ``DummyVecEnv`` of :func:`training_decision_env`; else
    the id's native vector env through :class:`SB3VecEnvAdapter` when it has
    one (all etsc-envs ids do), else a ``DummyVecEnv`` of single envs; for a PettingZoo id,
    every agent of the shared loops' vector env
    (:class:`~agents.train.vector_adapter.SharedPolicyVecEnv`)."""
    if config.decisions is not None:
        env: VecEnv = make_vec_env(
            functools.partial(training_decision_env, config),
            n_envs=config.n_envs,
            seed=config.seed,
            vec_env_cls=DummyVecEnv,
        )
    elif config.env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        env = VecMonitor(
            make_shared_policy_vec_env(config.env_id, config.n_envs, **config.env_kwargs)
        )
        env.seed(config.seed)
    elif gym.spec(config.env_id).vector_entry_point is not None:
        env = VecMonitor(make_sb3_vec_env(config.env_id, config.n_envs, **config.env_kwargs))
        env.seed(config.seed)
    else:
        env = make_vec_env(
            functools.partial(gym.make, config.env_id),
            n_envs=config.n_envs,
            seed=config.seed,
            env_kwargs=config.env_kwargs,
            vec_env_cls=DummyVecEnv,
        )
    if not (config.normalize_observations or config.normalize_rewards):
        return env
    statistics = _start_statistics(config, checkpoint)
    if statistics is None:
        return VecNormalize(
            env,
            norm_obs=config.normalize_observations,
            norm_reward=config.normalize_rewards,
            clip_obs=config.observation_clip,
            gamma=config.hyperparameters.get("gamma", 0.99),
        )
    normalized = ObservationStatistics.read(statistics).restore(env)
    normalized.training = True
    normalized.norm_obs = config.normalize_observations
    normalized.norm_reward = config.normalize_rewards
    normalized.clip_obs = config.observation_clip
    normalized.gamma = config.hyperparameters.get("gamma", 0.99)
    return normalized


def _start_statistics(config: TrainConfig, checkpoint: Path | None) -> Path | None:
    """The normalisation statistics training starts from: the resumed checkpoint's, else those
    saved beside ``init_from`` (if any), else none (fresh statistics)."""
    if checkpoint is not None:
        return _checkpoint_statistics(checkpoint)
    if config.init_from is None:
        return None
    model_path = Path(config.init_from)
    candidates = [normalization_path(model_path)]
    if model_path.stem.endswith("_steps"):
        candidates.append(_checkpoint_statistics(model_path))
    return next((candidate for candidate in candidates if candidate.is_file()), None)


def _checkpoint_statistics(checkpoint: Path) -> Path:
    """The statistics SB3's ``CheckpointCallback`` saved with ``model_<N>_steps.zip``."""
    steps = checkpoint.stem.split("_")[-2]
    return checkpoint.with_name(f"{CHECKPOINT_PREFIX}_vecnormalize_{steps}_steps.npz")


def _progress_bar_available() -> bool:
    """SB3's progress bar needs tqdm and rich; without them training runs without a bar."""
    return all(importlib.util.find_spec(name) is not None for name in ("tqdm", "rich"))


def _write_config(config: TrainConfig, path: Path) -> None:
    atomic_write_text(path, yaml.safe_dump(config.as_dict(), sort_keys=False))


def _summary(
    config: TrainConfig,
    model: BaseAlgorithm,
    metrics_callback: EpisodeMetricsCallback,
    wall_time_s: float,
) -> dict[str, Any]:
    return {
        "env_id": config.env_id,
        "algorithm": config.algorithm,
        "total_timesteps": config.total_timesteps,
        "timesteps": model.num_timesteps,
        "wall_time_s": wall_time_s,
        "steps_per_second": model.num_timesteps / wall_time_s,
        "episodes_finished": metrics_callback.episodes_finished,
        "recent_episodes": list(metrics_callback.recent_episodes),
    }


def build_parser() -> argparse.ArgumentParser:
    """The command line of :func:`main`."""
    parser = argparse.ArgumentParser(
        prog="python -m agents.train", description="Train a trigger policy with Stable-Baselines3."
    )
    parser.add_argument("--config", required=True, type=Path, help="YAML training config")
    parser.add_argument("--timesteps", type=int, help="override total_timesteps")
    parser.add_argument("--seed", type=int, help="override seed")
    parser.add_argument("--out", type=Path, help="override out_dir")
    parser.add_argument(
        "--init-from",
        type=Path,
        metavar="MODEL",
        help="override init_from (e.g. each seed's run of a curriculum's previous stage)",
    )
    runs = parser.add_mutually_exclusive_group()
    runs.add_argument(
        "--resume", action="store_true", help="continue from the newest checkpoint of out_dir"
    )
    runs.add_argument(
        "--overwrite",
        action="store_true",
        help="remove the earlier run in out_dir (model, checkpoints, logs) and train afresh",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line: load the config, apply the overrides, train, report the files."""
    parser = build_parser()
    args = parser.parse_args(argv)
    overrides = {
        "total_timesteps": args.timesteps,
        "seed": args.seed,
        "out_dir": None if args.out is None else str(args.out),
        "init_from": None if args.init_from is None else str(args.init_from),
    }
    try:
        config = load_config(
            args.config, {key: value for key, value in overrides.items() if value is not None}
        )
    except (OSError, ValueError, yaml.YAMLError) as error:
        parser.error(str(error))
    try:
        out_dir = train(config, resume=args.resume, overwrite=args.overwrite)
    except ValueError as error:
        parser.error(str(error))
    except KeyboardInterrupt:
        print(
            f"\ninterrupted; continue from the last checkpoint with: python -m agents.train "
            f"--config {args.config} --out {config.out_dir} --resume",
            file=sys.stderr,
        )
        return 130
    for path in sorted(out_dir.iterdir()):
        if path.name != LOCK_FILE:
            print(f"wrote {path}")
    return 0
