"""Train a trigger policy with Stable-Baselines3 from a YAML config.

``python -m agents.train --config configs/train/NAME.yaml [--timesteps N] [--seed S] [--out DIR]
[--resume]``

Writes to the output directory ``model.zip`` (a plain SB3 save, loadable by
``python -m baselines.evaluate ENV_ID --policy sb3:DIR/model.zip``) with
``model_vecnormalize.pkl`` beside it when observations are normalised, ``config.yaml`` (the
config after the command-line overrides and defaults), ``train_summary.json`` (wall time,
timesteps, steps per second and the last episodes' returns and metrics), and as configured
``checkpoints/``, ``tensorboard/`` and ``evaluations.json`` (the policy against the paper's
trigger during training). ``--resume`` continues from the newest checkpoint in
``checkpoints/`` up to ``total_timesteps``.
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import json
import time
from collections import deque
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch
import yaml
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback, CallbackList, CheckpointCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv, VecMonitor, VecNormalize

import etsc_envs
from agents.config import TrainConfig, load_config
from agents.evaluation import PaperComparisonCallback
from agents.imitation import imitate_paper_trigger
from agents.vector_adapter import make_sb3_vec_env, make_shared_policy_vec_env
from baselines.policies import normalization_path

MODEL_FILE = "model.zip"
CONFIG_FILE = "config.yaml"
SUMMARY_FILE = "train_summary.json"
EVALUATIONS_FILE = "evaluations.json"
CHECKPOINT_DIR = "checkpoints"
CHECKPOINT_PREFIX = "model"
TENSORBOARD_DIR = "tensorboard"
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
    config: TrainConfig, resume: bool = False, callbacks: Sequence[BaseCallback] = ()
) -> Path:
    """Train the configured model (from the newest checkpoint if ``resume``), write the output
    files and return the output folder. ``callbacks`` run after the run's own (episode
    metrics, checkpoints, evaluations), e.g. to report progress to a tuner."""
    torch.set_num_threads(config.torch_threads)
    out_dir = Path(config.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    checkpoint = latest_checkpoint(out_dir / CHECKPOINT_DIR) if resume else None
    imitation: dict[str, Any] | None = None
    if resume and checkpoint is None:
        raise ValueError(f"--resume: no checkpoint in {out_dir / CHECKPOINT_DIR}")
    env = make_training_env(config, checkpoint)
    tensorboard_log = str(out_dir / TENSORBOARD_DIR) if config.tensorboard else None
    if checkpoint is None:
        model = config.algorithm_class(
            config.policy,
            env,
            seed=config.seed,
            tensorboard_log=tensorboard_log,
            **config.hyperparameters,
        )
        if config.init_from is not None:
            model.set_parameters(config.init_from, device="cpu")
        if config.imitation_steps:
            imitation = imitate_paper_trigger(
                model,
                config.env_id,
                config.env_kwargs,
                config.imitation_steps,
                config.imitation_epochs,
            )
    else:
        model = config.algorithm_class.load(
            checkpoint, env=env, device="cpu", tensorboard_log=tensorboard_log
        )
    metrics_callback = EpisodeMetricsCallback()
    start = time.perf_counter()
    periodic = _periodic_callbacks(config, out_dir, env.num_envs)
    model.learn(
        total_timesteps=max(config.total_timesteps - model.num_timesteps, 0),
        callback=CallbackList([metrics_callback, *periodic, *callbacks]),
        progress_bar=_progress_bar_available(),
        reset_num_timesteps=checkpoint is None,
    )
    wall_time_s = time.perf_counter() - start
    model.save(out_dir / MODEL_FILE)
    normalization = model.get_vec_normalize_env()
    if normalization is not None:
        normalization.save(normalization_path(out_dir / MODEL_FILE))
    env.close()
    _write_config(config, out_dir / CONFIG_FILE)
    summary = _summary(config, model, metrics_callback, wall_time_s)
    summary["resumed_from"] = None if checkpoint is None else str(checkpoint)
    summary["imitation"] = imitation
    (out_dir / SUMMARY_FILE).write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    return out_dir


def latest_checkpoint(folder: Path) -> Path | None:
    """The checkpoint with the most timesteps in ``folder`` (``model_<N>_steps.zip``)."""
    checkpoints = sorted(
        folder.glob(f"{CHECKPOINT_PREFIX}_*_steps.zip"),
        key=lambda path: int(path.stem.split("_")[-2]),
    )
    return checkpoints[-1] if checkpoints else None


def _periodic_callbacks(config: TrainConfig, out_dir: Path, num_envs: int) -> list[BaseCallback]:
    """Checkpoints and evaluations against the paper trigger, as configured (``num_envs``:
    the training ``VecEnv``'s sub-environments, whose steps the intervals count)."""
    callbacks: list[BaseCallback] = []
    if config.checkpoint_every:
        callbacks.append(
            CheckpointCallback(
                save_freq=max(config.checkpoint_every // num_envs, 1),
                save_path=str(out_dir / CHECKPOINT_DIR),
                name_prefix=CHECKPOINT_PREFIX,
                save_vecnormalize=config.normalize_observations or config.normalize_rewards,
            )
        )
    if config.evaluation_every:
        callbacks.append(
            PaperComparisonCallback(
                config.env_id,
                {**config.env_kwargs, **config.evaluation_env_kwargs},
                config.evaluation_every,
                out_dir / EVALUATIONS_FILE,
            )
        )
    return callbacks


def make_training_env(config: TrainConfig, checkpoint: Path | None = None) -> VecEnv:
    """``config.n_envs`` environments of ``config.env_id`` as one SB3 ``VecEnv`` with episode
    statistics and, as configured, normalisation (restored from ``checkpoint``'s statistics
    when resuming): the id's native vector env through :class:`SB3VecEnvAdapter` when it has
    one (all etsc-envs ids do), else a ``DummyVecEnv`` of single envs; for a PettingZoo id,
    every agent of the shared loops' vector env
    (:class:`~agents.vector_adapter.SharedPolicyVecEnv`)."""
    if config.env_id in etsc_envs.PETTINGZOO_ENV_IDS:
        env: VecEnv = VecMonitor(
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
    normalized = VecNormalize.load(str(statistics), env)
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
    return checkpoint.with_name(f"{CHECKPOINT_PREFIX}_vecnormalize_{steps}_steps.pkl")


def _progress_bar_available() -> bool:
    """SB3's progress bar needs tqdm and rich; without them training runs without a bar."""
    return all(importlib.util.find_spec(name) is not None for name in ("tqdm", "rich"))


def _write_config(config: TrainConfig, path: Path) -> None:
    path.write_text(yaml.safe_dump(config.as_dict(), sort_keys=False), encoding="utf-8")


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
        "--resume", action="store_true", help="continue from the newest checkpoint of out_dir"
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
    }
    try:
        config = load_config(
            args.config, {key: value for key, value in overrides.items() if value is not None}
        )
    except (OSError, ValueError, yaml.YAMLError) as error:
        parser.error(str(error))
    try:
        out_dir = train(config, resume=args.resume)
    except ValueError as error:
        parser.error(str(error))
    for path in sorted(out_dir.iterdir()):
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
