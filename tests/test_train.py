"""Smoke test of ``python -m agents.train`` and of its config validation."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import gymnasium as gym
import pytest
import yaml

stable_baselines3 = pytest.importorskip("stable_baselines3")

from agents.config import config_from_dict  # noqa: E402
from agents.train import CONFIG_FILE, MODEL_FILE, SUMMARY_FILE, main  # noqa: E402

SHIPPED_CONFIG = Path(__file__).parents[1] / "configs" / "train" / "attitude_tracking_ppo.yaml"


def shipped_config() -> dict[str, Any]:
    """The shipped PPO config as a mapping."""
    return yaml.safe_load(SHIPPED_CONFIG.read_text(encoding="utf-8"))


def tiny_config(out_dir: Path) -> dict[str, Any]:
    """The shipped config shrunk to a run of a few seconds."""
    config = shipped_config()
    config["env_kwargs"]["horizon_s"] = 0.2
    config["hyperparameters"].update(n_steps=64, batch_size=64)
    config.update(total_timesteps=256, n_envs=1, out_dir=str(out_dir))
    return config


def test_train_writes_a_loadable_model(tmp_path: Path) -> None:
    config_path = tmp_path / "tiny.yaml"
    out_dir = tmp_path / "run"
    config_path.write_text(yaml.safe_dump(tiny_config(out_dir)), encoding="utf-8")

    assert main(["--config", str(config_path), "--seed", "3"]) == 0

    for name in (MODEL_FILE, CONFIG_FILE, SUMMARY_FILE):
        assert (out_dir / name).is_file(), name
    resolved = yaml.safe_load((out_dir / CONFIG_FILE).read_text(encoding="utf-8"))
    assert resolved["seed"] == 3
    summary = json.loads((out_dir / SUMMARY_FILE).read_text(encoding="utf-8"))
    assert summary["timesteps"] >= 256
    assert summary["recent_episodes"], "0.2-s episodes of 200 steps must finish within 256 steps"
    assert "E_v" in summary["recent_episodes"][-1]

    model = stable_baselines3.PPO.load(out_dir / MODEL_FILE, device="cpu")
    env = gym.make(resolved["env_id"], **resolved["env_kwargs"])
    observation, _ = env.reset(seed=0)
    action, _ = model.predict(observation, deterministic=True)
    assert env.action_space.contains(int(action))


def test_config_rejects_an_unknown_algorithm(tmp_path: Path) -> None:
    config = tiny_config(tmp_path) | {"algorithm": "SAC"}
    with pytest.raises(ValueError, match=r"'algorithm'.*PPO"):
        config_from_dict(config)


def test_config_rejects_an_unknown_key(tmp_path: Path) -> None:
    config = tiny_config(tmp_path) | {"learning_rate": 1.0e-3}
    with pytest.raises(ValueError, match="learning_rate"):
        config_from_dict(config)


def test_config_rejects_an_unknown_hyperparameter(tmp_path: Path) -> None:
    config = tiny_config(tmp_path)
    config["hyperparameters"]["n_step"] = 64
    with pytest.raises(ValueError, match="n_step"):
        config_from_dict(config)
