"""rl-zoo3 trains every Gymnasium id with the suite's settings from ``configs/zoo/ppo.yml``.

Checked properties:

* the file has one entry per Gymnasium id, and each entry is its ``configs/train`` config in
  rl-zoo3's keys (the hyperparameters, the env kwargs and the normalisation, clip included);
* ``python -m rl_zoo3.train --algo ppo --env ID --gym-packages etsc_envs --conf-file
  configs/zoo/ppo.yml`` (the README's command) trains each id for two rollouts, on short
  episodes and four envs, and saves a model, the normalisation statistics and the settings it
  used, which are the file's.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

import etsc_envs

pytest.importorskip("stable_baselines3", reason="the train extra is not installed")
from agents.train.config import load_config

CLIENTS_EXTRA = "rl-zoo3: the clients extra is not installed (pip install -e '.[clients]')"

ROOT = Path(__file__).resolve().parents[1]
ZOO_FILE = ROOT / "configs" / "zoo" / "ppo.yml"
TRAIN_CONFIGS = {
    "etsc/AttitudeTracking-v0": "attitude_tracking_ppo.yaml",
    "etsc/OrbitAttitudeTracking-v0": "orbit_attitude_ppo.yaml",
    "etsc/ClusterContainmentCentral-v0": "cluster_central_ppo.yaml",
    "etsc/InnerFormation-v0": "inner_formation_ppo.yaml",
    "etsc/AsteroidOrbitKeeping-v0": "asteroid_ppo.yaml",
}
SHORT_HORIZON_S = {"etsc/AsteroidOrbitKeeping-v0": 50.0}
"""Test episodes: 1 s, except the asteroid's, which must hold one 50-s burst."""
ZOO_KEYS_PASSED_BY_RL_ZOO3 = ("device", "verbose")


def zoo_entries() -> dict:
    return yaml.safe_load(ZOO_FILE.read_text(encoding="utf-8"))


def test_the_zoo_file_is_the_train_configs_in_rl_zoo3_keys():
    entries = zoo_entries()
    assert set(entries) == set(etsc_envs.ENV_IDS) == set(TRAIN_CONFIGS)
    for env_id, name in TRAIN_CONFIGS.items():
        config = load_config(ROOT / "configs" / "train" / name)
        entry = dict(entries[env_id])
        assert config.env_id == env_id
        assert entry.pop("env_kwargs") == config.env_kwargs
        assert entry.pop("n_envs") == config.n_envs
        assert entry.pop("n_timesteps") == config.total_timesteps
        assert entry.pop("policy") == config.policy
        assert ast.literal_eval(entry.pop("normalize")) == {
            "norm_obs": config.normalize_observations,
            "norm_reward": config.normalize_rewards,
            "clip_obs": config.observation_clip,
        }
        hyperparameters = {
            key: value
            for key, value in config.hyperparameters.items()
            if key not in ZOO_KEYS_PASSED_BY_RL_ZOO3
        }
        assert entry == hyperparameters


@pytest.mark.parametrize("env_id", sorted(TRAIN_CONFIGS))
def test_rl_zoo3_trains_each_id_from_the_conf_file(env_id, tmp_path):
    pytest.importorskip("rl_zoo3", reason=CLIENTS_EXTRA)
    entry = zoo_entries()[env_id]
    env_kwargs = {**entry["env_kwargs"], "horizon_s": SHORT_HORIZON_S.get(env_id, 1.0)}
    command = [
        sys.executable,
        "-m",
        "rl_zoo3.train",
        "--algo",
        "ppo",
        "--env",
        env_id,
        "--gym-packages",
        "etsc_envs",
        "--conf-file",
        str(ZOO_FILE),
        "--device",
        "cpu",
        "-n",
        "2048",
        "--eval-freq",
        "-1",
        "-f",
        str(tmp_path / "logs"),
        "--env-kwargs",
        *(f"{key}:{value!r}" for key, value in env_kwargs.items()),
        "--hyperparams",
        "n_envs:4",
        "batch_size:256",
    ]
    result = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "Using 'default' hyperparameters" not in result.stdout
    (run,) = (tmp_path / "logs" / "ppo").iterdir()
    (settings_file,) = run.glob("*/config.yml")
    used = dict(yaml.unsafe_load(settings_file.read_text(encoding="utf-8")))
    assert used["gamma"] == entry["gamma"]
    assert used["n_steps"] == entry["n_steps"]
    assert used["normalize"] == entry["normalize"]
    assert used["env_kwargs"] == env_kwargs
    assert (settings_file.parent / "vecnormalize.pkl").is_file()
    assert len(list(run.glob("*.zip"))) == 1
    assert "total_timesteps      | 2048" in result.stdout
