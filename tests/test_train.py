"""Smoke test of ``python -m agents.train`` and of its config validation."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import gymnasium as gym
import pytest
import yaml

stable_baselines3 = pytest.importorskip("stable_baselines3")

from agents.train.config import config_from_dict  # noqa: E402
from agents.train.training import (  # noqa: E402
    CONFIG_FILE,
    MODEL_FILE,
    SUMMARY_FILE,
    main,
    whole_rollout_steps,
)
from etsc_envs.decisions import DecisionSet, make_decision_env  # noqa: E402

CONFIG_DIR = Path(__file__).parents[1] / "configs" / "train"
SHIPPED_CONFIG = CONFIG_DIR / "attitude_tracking_ppo.yaml"

SHORT_EPISODES = {
    "etsc/AttitudeTracking-v0": {"horizon_s": 0.05},
    "etsc/InnerFormation-v0": {"horizon_s": 0.05},
    "etsc/OrbitAttitudeTracking-v0": {"horizon_s": 0.05},
    "etsc/ClusterContainmentCentral-v0": {"horizon_s": 0.5},
    "etsc/ClusterContainment-v0": {"horizon_s": 0.5},
    "etsc/AsteroidOrbitKeeping-v0": {"horizon_s": 60.0},
}
"""Env kwargs that make each id's training and evaluation episodes a few dozen steps long."""


def shipped_config(path: Path = SHIPPED_CONFIG) -> dict[str, Any]:
    """A shipped config as a mapping."""
    return yaml.safe_load(path.read_text(encoding="utf-8"))


def tiny_config(out_dir: Path, path: Path = SHIPPED_CONFIG) -> dict[str, Any]:
    """A shipped config shrunk to a run of a few seconds."""
    config = shipped_config(path)
    short = SHORT_EPISODES[config["env_id"]]
    config["env_kwargs"].update(short)
    config["hyperparameters"].update(n_steps=64, batch_size=64)
    config.update(
        total_timesteps=256,
        n_envs=1,
        out_dir=str(out_dir),
        checkpoint_every=0,
        evaluation_every=0,
        evaluation_env_kwargs=dict(short),
    )
    config["init_from"] = None  # a later stage's predecessor is not trained here
    return config


def write_config(config: dict[str, Any], folder: Path) -> Path:
    path = folder / "tiny.yaml"
    path.write_text(yaml.safe_dump(config), encoding="utf-8")
    return path


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
    assert summary["recent_episodes"], "50-step episodes must finish within 256 steps"
    assert "E_v" in summary["recent_episodes"][-1]

    model = stable_baselines3.PPO.load(out_dir / MODEL_FILE, device="cpu")
    env = gym.make(resolved["env_id"], **resolved["env_kwargs"])
    observation, _ = env.reset(seed=0)
    action, _ = model.predict(observation, deterministic=True)
    assert env.action_space.contains(int(action))


def test_training_raises_no_warning_of_its_own(tmp_path: Path) -> None:
    """A plain run warns of nothing (tqdm's "rich is experimental" included)."""
    import warnings

    config_path = write_config(tiny_config(tmp_path / "run"), tmp_path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["--config", str(config_path)]) == 0
    assert [str(warning.message) for warning in caught] == []


def test_a_budget_of_part_of_a_rollout_says_it_rounds_up(tmp_path: Path, capsys) -> None:
    config = tiny_config(tmp_path / "run")
    config["hyperparameters"].update(n_steps=64, batch_size=64)
    config.update(total_timesteps=300, n_envs=2)  # rollouts of 128 steps: 384 are taken
    assert main(["--config", str(write_config(config, tmp_path))]) == 0
    assert "training 384 steps for total_timesteps 300" in capsys.readouterr().out
    summary = json.loads((tmp_path / "run" / SUMMARY_FILE).read_text(encoding="utf-8"))
    assert summary["timesteps"] == 384
    model = stable_baselines3.DQN("MlpPolicy", "CartPole-v1", device="cpu")
    assert whole_rollout_steps(300, model) == 300


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


@pytest.mark.parametrize("config_path", sorted(CONFIG_DIR.glob("*.yaml")), ids=lambda p: p.stem)
def test_every_shipped_config_trains_saves_reloads_and_evaluates(
    config_path: Path, tmp_path: Path
) -> None:
    from baselines.evaluate import main as evaluate_main
    from etsc_envs.sb3_models import NormalizedModel, load_sb3, normalization_path

    out_dir = tmp_path / "run"
    config = tiny_config(out_dir, config_path) | {
        "n_envs": 2,
        "evaluation_every": 128,
        "evaluation_scenarios": 2,
    }
    assert main(["--config", str(write_config(config, tmp_path))]) == 0

    model_path = out_dir / MODEL_FILE
    assert normalization_path(model_path).is_file(), "observation statistics beside the model"
    assert any((out_dir / "tensorboard").rglob("events.out.tfevents.*"))
    evaluations = json.loads((out_dir / "evaluations.json").read_text(encoding="utf-8"))
    assert evaluations and {"learned", "paper", "timesteps"} <= set(evaluations[0])
    assert evaluations[0]["paper"]["transmissions"] >= 0
    assert isinstance(load_sb3(model_path), NormalizedModel)

    record_path = tmp_path / "evaluation.json"
    env_args = [
        f"--env-arg={key}={value}" for key, value in SHORT_EPISODES[config["env_id"]].items()
    ]
    assert (
        evaluate_main(
            [
                config["env_id"],
                "--policy",
                f"sb3:{model_path}",
                *env_args,
                "--json",
                str(record_path),
            ]
        )
        == 0
    )
    record = json.loads(record_path.read_text(encoding="utf-8"))
    assert record["episodes"][0]["steps"] > 0


def test_resume_continues_from_the_newest_checkpoint(tmp_path: Path) -> None:
    out_dir = tmp_path / "run"
    config = tiny_config(out_dir) | {"checkpoint_every": 64, "total_timesteps": 128}
    config_path = write_config(config, tmp_path)
    assert main(["--config", str(config_path)]) == 0
    checkpoints = sorted((out_dir / "checkpoints").glob("model_*_steps.zip"))
    assert checkpoints, "checkpoints were written"
    assert main(["--config", str(config_path), "--timesteps", "320", "--resume"]) == 0
    summary = json.loads((out_dir / SUMMARY_FILE).read_text(encoding="utf-8"))
    assert summary["resumed_from"].endswith("model_128_steps.zip")
    assert summary["timesteps"] >= 320
    assert summary["timesteps"] < 320 + 128, "resuming does not start the count again"


@pytest.mark.parametrize("given_on", ["config", "command line"])
def test_init_from_starts_from_an_earlier_models_weights_and_statistics(
    tmp_path: Path, given_on: str
) -> None:
    import numpy as np

    from etsc_envs.sb3_models import ObservationStatistics, normalization_path

    first = tmp_path / "first"
    assert main(["--config", str(write_config(tiny_config(first), tmp_path))]) == 0
    second = tmp_path / "second"
    config = tiny_config(second) | {"total_timesteps": 64}
    extra = ["--init-from", str(first / MODEL_FILE)]
    if given_on == "config":
        config["init_from"], extra = str(first / MODEL_FILE), []
    # Adam steps of about 1e-30 keep every weight within 1e-20 of the loaded one, where a fresh
    # initialisation differs by about 0.1 (a rate must be > 0)
    config["hyperparameters"]["learning_rate"] = 1.0e-30
    assert main(["--config", str(write_config(config, tmp_path)), *extra]) == 0
    before = stable_baselines3.PPO.load(first / MODEL_FILE, device="cpu").policy.state_dict()
    after = stable_baselines3.PPO.load(second / MODEL_FILE, device="cpu").policy.state_dict()
    for name, weights in before.items():
        assert np.allclose(weights.numpy(), after[name].numpy(), rtol=0.0, atol=1e-20), name
    first_statistics, second_statistics = (
        ObservationStatistics.read(normalization_path(run / MODEL_FILE)) for run in (first, second)
    )
    assert second_statistics.observation_count > first_statistics.observation_count, "continued"
    assert second_statistics.clip_obs == config.get("observation_clip", 10.0), "as configured"


def test_init_from_must_be_a_saved_model(tmp_path: Path) -> None:
    config = tiny_config(tmp_path / "run") | {"init_from": str(tmp_path / "missing.zip")}
    with pytest.raises(ValueError, match="init_from"):
        config_from_dict(config)


@pytest.mark.parametrize(
    "config_path", sorted(CONFIG_DIR.glob("*_self_triggered.yaml")), ids=lambda p: p.stem
)
def test_every_shipped_self_triggered_config_builds_its_decision_set(
    tmp_path: Path, config_path: Path
) -> None:
    """The config's ``decisions:`` block is a set for its id, trained from scratch: holds and
    trigger actions, no ``start_from``, the wrapper built with its env kwargs."""
    raw = shipped_config(config_path)
    assert "start_from" not in raw
    config = config_from_dict(raw | {"out_dir": str(tmp_path / "run")})
    assert config.decisions is not None
    decisions = DecisionSet.from_json(config.decisions)
    assert decisions.env_id == raw["env_id"]
    assert len(decisions.actions) == len(raw["decisions"]["actions"])
    assert decisions.hold_indices and decisions.trigger_indices
    assert decisions.shield_multiple == raw["decisions"].get("shield_multiple")
    env = make_decision_env(config.env_id, config.env_kwargs, decisions)
    try:
        assert env.action_space == decisions.action_space
    finally:
        env.close()


@pytest.mark.parametrize("block", [{"steps": 8}, None, {"decision": "best"}])
def test_a_start_from_key_is_refused_in_one_line(tmp_path: Path, block) -> None:
    config = tiny_config(tmp_path / "run") | {"start_from": block}
    with pytest.raises(ValueError, match="config key 'start_from' was removed") as caught:
        config_from_dict(config)
    assert "\n" not in str(caught.value)
    assert main_error(write_config(config, tmp_path)).count("start_from") == 1


def main_error(config_path: Path) -> str:
    """The error line ``python -m agents.train`` prints for ``config_path`` (it exits 2)."""
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), pytest.raises(SystemExit) as exited:
        main(["--config", str(config_path)])
    assert exited.value.code == 2
    return stderr.getvalue().strip().splitlines()[-1]


def test_resume_without_checkpoints_is_a_clear_error(tmp_path: Path) -> None:
    config_path = write_config(tiny_config(tmp_path / "run"), tmp_path)
    with pytest.raises(SystemExit):
        main(["--config", str(config_path), "--resume"])


def test_config_rejects_a_learner_that_would_never_train(tmp_path: Path) -> None:
    config = tiny_config(tmp_path, CONFIG_DIR / "attitude_tracking_self_triggered.yaml")
    config.update(algorithm="DQN", hyperparameters={"learning_starts": 256})
    with pytest.raises(ValueError, match=r"'hyperparameters.learning_starts' must be below total"):
        config_from_dict(config)
    config["hyperparameters"]["learning_starts"] = 255
    assert config_from_dict(config).total_timesteps == 256
    config["hyperparameters"] = [255]
    with pytest.raises(ValueError, match="'hyperparameters' must be a mapping"):
        config_from_dict(config)


def test_config_rejects_dqn_for_a_multibinary_action(tmp_path: Path) -> None:
    config = tiny_config(tmp_path, CONFIG_DIR / "inner_formation_ppo.yaml")
    config.update(algorithm="DQN", hyperparameters={})
    with pytest.raises(ValueError, match="DQN needs a Discrete action space"):
        config_from_dict(config)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("checkpoint_every", -1, "'checkpoint_every' must be an integer >= 0"),
        ("normalize_observations", "yes", "'normalize_observations' must be true or false"),
        ("evaluation_env_kwargs", [1], "'evaluation_env_kwargs' must be a mapping"),
        ("observation_clip", 0, "'observation_clip' must be a positive number"),
        ("torch_threads", 0, "'torch_threads' must be"),
    ],
)
def test_config_rejects_bad_training_options(tmp_path: Path, key, value, message) -> None:
    config = tiny_config(tmp_path) | {key: value}
    with pytest.raises(ValueError, match=message):
        config_from_dict(config)


def test_a_network_not_yet_trained_is_validated_but_never_kept(tmp_path: Path) -> None:
    """DQN updates its network only after ``learning_starts`` steps: validations before then
    record the untrained network (``"trained": false``, 0 updates) on the learning curve, and
    the checkpoint the run keeps is always a trained one."""
    import zipfile

    from agents.train.training import BEST_MODEL_FILE

    out_dir = tmp_path / "run"
    config = tiny_config(out_dir, CONFIG_DIR / "attitude_tracking_self_triggered.yaml")
    config.update(
        algorithm="DQN",
        hyperparameters={"learning_starts": 64, "batch_size": 16, "train_freq": 1, "device": "cpu"},
        total_timesteps=128,
        evaluation_every=32,
        evaluation_scenarios=1,
    )
    assert main(["--config", str(write_config(config, tmp_path))]) == 0
    evaluations = json.loads((out_dir / "evaluations.json").read_text(encoding="utf-8"))
    assert [entry["timesteps"] for entry in evaluations] == [32, 64, 96, 128]
    assert [entry["trained"] for entry in evaluations] == [False, False, True, True]
    assert [entry["updates"] > 0 for entry in evaluations] == [False, False, True, True]
    with zipfile.ZipFile(out_dir / BEST_MODEL_FILE) as saved:
        assert json.loads(saved.read("data"))["_n_updates"] > 0


def test_an_untrained_policy_that_validates_best_is_not_kept(tmp_path: Path) -> None:
    """However well a policy no gradient step has touched scores, the kept checkpoint is the
    best trained one; a run started from a trained model (``init_from``) may keep its start."""
    from types import SimpleNamespace

    from agents.train.validation_callback import PaperComparisonCallback

    def validated(returns: list[tuple[int, float]], starts_trained: bool) -> list[float]:
        callback = PaperComparisonCallback(
            "etsc/AttitudeTracking-v0",
            {},
            every=10**9,
            out_path=tmp_path / "evaluations.json",
            set_size=1,
            best_model_path=tmp_path / "best_model.zip",
            starts_trained=starts_trained,
        )
        kept: list[float] = []
        logger = SimpleNamespace(record=lambda *args, **kwargs: None)
        callback.paper = {"mean_cost": 1.0, "transmissions": 1}
        callback._current_policy = lambda: None
        callback._save_best = lambda: kept.append(callback.evaluations[-1]["learned"]["return"])
        for updates, value in returns:
            callback.model = SimpleNamespace(_n_updates=updates, logger=logger)
            record = {"mean_cost": 1.0, "transmissions": 1, "transmission_rate": 0.1}
            record |= {"return": value, "failure": None}
            callback._run = lambda policy, record=record: [record]
            callback._evaluate()
        return kept

    assert validated([(0, -1.0), (8, -5.0), (16, -3.0)], starts_trained=False) == [-5.0, -3.0]
    assert validated([(0, -1.0), (8, -5.0), (16, -3.0)], starts_trained=True) == [-1.0]
