"""Train a trigger policy with Stable-Baselines3 from a YAML config.

``python -m agents.train --config configs/train/NAME.yaml [--timesteps N] [--seed S] [--out DIR]``

Writes to the output directory ``model.zip`` (a plain SB3 save, loadable by
``python -m baselines.evaluate ENV_ID --policy sb3:DIR/model.zip``), ``config.yaml`` (the config
after the command-line overrides and defaults) and ``train_summary.json`` (wall time, timesteps,
steps per second and the last episodes' returns and metrics).
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import json
import time
from collections import deque
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import yaml
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv, VecMonitor

from agents.config import TrainConfig, load_config
from agents.vector_adapter import make_sb3_vec_env

MODEL_FILE = "model.zip"
CONFIG_FILE = "config.yaml"
SUMMARY_FILE = "train_summary.json"
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


def train(config: TrainConfig) -> Path:
    """Train the configured model, write the three output files and return the output folder."""
    out_dir = Path(config.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    env = make_training_env(config)
    model = config.algorithm_class(config.policy, env, seed=config.seed, **config.hyperparameters)
    metrics_callback = EpisodeMetricsCallback()
    start = time.perf_counter()
    model.learn(
        total_timesteps=config.total_timesteps,
        callback=metrics_callback,
        progress_bar=_progress_bar_available(),
    )
    wall_time_s = time.perf_counter() - start
    env.close()
    model.save(out_dir / MODEL_FILE)
    _write_config(config, out_dir / CONFIG_FILE)
    summary = _summary(config, model, metrics_callback, wall_time_s)
    (out_dir / SUMMARY_FILE).write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    return out_dir


def make_training_env(config: TrainConfig) -> VecEnv:
    """``config.n_envs`` environments of ``config.env_id`` as one SB3 ``VecEnv`` with episode
    statistics: the id's native vector env through :class:`SB3VecEnvAdapter` when it has one
    (all etsc-envs ids do), else a ``DummyVecEnv`` of single envs."""
    if gym.spec(config.env_id).vector_entry_point is not None:
        env = make_sb3_vec_env(config.env_id, config.n_envs, **config.env_kwargs)
        env.seed(config.seed)
        return VecMonitor(env)
    return make_vec_env(
        functools.partial(gym.make, config.env_id),
        n_envs=config.n_envs,
        seed=config.seed,
        env_kwargs=config.env_kwargs,
        vec_env_cls=DummyVecEnv,
    )


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
    out_dir = train(config)
    for name in (MODEL_FILE, CONFIG_FILE, SUMMARY_FILE):
        print(f"wrote {out_dir / name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
