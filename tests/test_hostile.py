"""Hostile input: every env keyword, reset option, pickled env and command line of issue 17.

Checked properties: bad input ends in one line naming the argument and what it allows
(``ValueError``/``TypeError`` from Python, exit status 2 from a command line), never a silent
reading of it nor a raw traceback; the same checks reach every parameter class field by field,
so a keyword added later is covered without a new test; an env pickled at any point continues
bit for bit; output paths are checked before the work starts.
"""

from __future__ import annotations

import dataclasses
import pickle
import zipfile
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import etsc_envs
from etsc_envs.asteroid.params import AsteroidParams
from etsc_envs.attitude_tracking.params import AttitudeTrackingParams
from etsc_envs.cluster.params import ClusterContainmentParams
from etsc_envs.inner_formation.params import InnerFormationParams
from etsc_envs.orbit_attitude.params import OrbitAttitudeParams
from tests.child_process import interruptible

GYM_IDS = sorted(etsc_envs.ENV_IDS)
PETTINGZOO_ID = "etsc/ClusterContainment-v0"
MODELS = Path(__file__).parents[1] / "models"
SHORT = {
    "etsc/AttitudeTracking-v0": {"horizon_s": 0.05},
    "etsc/InnerFormation-v0": {"horizon_s": 0.05},
    "etsc/OrbitAttitudeTracking-v0": {"horizon_s": 0.05},
    "etsc/ClusterContainmentCentral-v0": {"horizon_s": 0.5},
    "etsc/AsteroidOrbitKeeping-v0": {"horizon_s": 60.0},
}
PARAMS_CLASSES = [
    AttitudeTrackingParams,
    InnerFormationParams,
    OrbitAttitudeParams,
    ClusterContainmentParams,
    AsteroidParams,
]


def raw_env(env_id: str, **kwargs):
    """The env class itself, as a user constructing it directly would."""
    return gym.spec(env_id).make(**kwargs).unwrapped


def assert_one_line(error: pytest.ExceptionInfo, *names: str) -> None:
    message = str(error.value)
    assert "\n" not in message, message
    for name in names:
        assert name in message, message


def bits(env, value: int):
    return value if env.action_space.shape == () else np.full(env.action_space.shape, value)


# ----------------------------------------------------------------------- env keywords
@pytest.mark.parametrize("env_id", GYM_IDS)
def test_randomize_must_be_a_bool(env_id: str) -> None:
    with pytest.raises(ValueError) as error:
        gym.make(env_id, randomize="no")
    assert_one_line(error, "randomize")


def test_pettingzoo_randomize_must_be_a_bool() -> None:
    with pytest.raises(ValueError) as error:
        etsc_envs.make_parallel(PETTINGZOO_ID, randomize="no")
    assert_one_line(error, "randomize")


def _wrong_kind(annotation) -> object:
    """A value of the wrong kind for a field annotated ``annotation`` (a string such as
    ``"float | None"``: the parameter modules postpone the evaluation of annotations)."""
    names = {part.strip() for part in str(annotation).split("|")}
    if "bool" in names:
        return "no"
    if "int" in names or "float" in names or "tuple" in names:
        return "abc"
    if "str" in names:
        return 3
    return None


PARAMETER_FIELDS = [
    pytest.param(cls, field.name, id=f"{cls.__name__}.{field.name}")
    for cls in PARAMS_CLASSES
    for field in dataclasses.fields(cls)
    if _wrong_kind(field.type) is not None
]


@pytest.mark.parametrize(("params_class", "name"), PARAMETER_FIELDS)
def test_every_parameter_refuses_a_value_of_the_wrong_kind(params_class, name: str) -> None:
    field = next(f for f in dataclasses.fields(params_class) if f.name == name)
    with pytest.raises(ValueError) as error:
        params_class(**{name: _wrong_kind(field.type)})
    assert_one_line(error, name)


@pytest.mark.parametrize("env_id", GYM_IDS)
@pytest.mark.parametrize("keyword", ["transmission_penalty", "cost_scale"])
def test_reward_keywords_refuse_text(env_id: str, keyword: str) -> None:
    with pytest.raises(ValueError) as error:
        gym.make(env_id, **{keyword: "0.1"})
    assert_one_line(error, keyword)


def test_a_vector_parameter_refuses_text() -> None:
    with pytest.raises(ValueError) as error:
        gym.make("etsc/AttitudeTracking-v0", observer_epsilon="abc")
    assert_one_line(error, "observer_epsilon")


@pytest.mark.parametrize("env_id", GYM_IDS)
def test_params_must_be_the_envs_parameter_class(env_id: str) -> None:
    with pytest.raises(TypeError) as error:
        gym.make(env_id, params="x")
    assert_one_line(error, "params of", "Params, got 'x' (str)")


def test_horizon_must_be_a_whole_number_of_sampling_periods() -> None:
    with pytest.raises(ValueError) as error:
        gym.make("etsc/AttitudeTracking-v0", horizon_s=0.0015)
    assert_one_line(error, "horizon_s", "0.001")
    assert gym.make("etsc/AttitudeTracking-v0", horizon_s=0.003).unwrapped.n_steps == 3


def test_cluster_adjacency_weights_are_bounded() -> None:
    adjacency = np.array(ClusterContainmentParams().adjacency)
    adjacency[adjacency > 0] = 1e308
    with pytest.raises(ValueError) as error:
        gym.make("etsc/ClusterContainmentCentral-v0", adjacency=adjacency)
    assert_one_line(error, "adjacency")


def test_cluster_largest_accepted_weight_keeps_the_observation_finite() -> None:
    from etsc_envs.cluster.topology import MAX_WEIGHT

    adjacency = np.array(ClusterContainmentParams().adjacency)
    adjacency[adjacency > 0] = MAX_WEIGHT
    env = gym.make("etsc/ClusterContainmentCentral-v0", adjacency=adjacency, horizon_s=0.5)
    observation, _ = env.reset(seed=0)
    for _ in range(5):
        observation, *_ = env.step(np.ones(env.action_space.shape, dtype=np.int64))
        assert np.all(np.isfinite(observation))


def test_cluster_leaders_must_lie_in_the_mrp_unit_ball() -> None:
    leaders = np.array(ClusterContainmentParams().leader_attitudes)
    leaders[0] = [1.2, 0.0, 0.0]
    with pytest.raises(ValueError) as error:
        gym.make("etsc/ClusterContainmentCentral-v0", leader_attitudes=leaders)
    assert_one_line(error, "leader_attitudes")


@pytest.mark.parametrize("unit", [-1.0, 0.0, np.nan, "km"])
def test_asteroid_shape_length_unit_must_be_positive(unit) -> None:
    with pytest.raises(ValueError) as error:
        gym.make("etsc/AsteroidOrbitKeeping-v0", shape_length_unit_m=unit)
    assert_one_line(error, "shape_length_unit_m")


# ----------------------------------------------------------------------- reset and step
@pytest.mark.parametrize("env_id", GYM_IDS)
@pytest.mark.parametrize("options", [{"foo": 1}, "string"])
def test_reset_refuses_unknown_options(env_id: str, options) -> None:
    env = gym.make(env_id)
    with pytest.raises(ValueError) as error:
        env.reset(options=options)
    assert_one_line(error, "options")
    env.reset(options={})  # an empty mapping is no option at all


@pytest.mark.parametrize("options", [{"foo": 1}, "string"])
def test_vector_reset_refuses_unknown_options(options) -> None:
    vector = gym.make_vec(
        "etsc/AttitudeTracking-v0", num_envs=2, vectorization_mode="vector_entry_point"
    )
    with pytest.raises(ValueError) as error:
        vector.reset(options=options)
    assert_one_line(error, "options")


def test_pettingzoo_reset_refuses_a_non_mapping_and_warns_of_unknown_keys() -> None:
    parallel = etsc_envs.make_parallel(PETTINGZOO_ID)
    with pytest.raises(ValueError) as error:
        parallel.reset(options="string")
    assert_one_line(error, "options")
    # PettingZoo's API test resets with options={"options": 1}: named, not refused
    with pytest.warns(UserWarning, match=r"unknown key\(s\) \['foo'\]"):
        parallel.reset(options={"foo": 1})


@pytest.mark.parametrize("env_id", GYM_IDS)
def test_stepping_the_raw_env_before_reset_is_refused(env_id: str) -> None:
    env = raw_env(env_id)
    with pytest.raises(gym.error.ResetNeeded):
        env.step(bits(env, 0))


# ----------------------------------------------------------------------- pickling
def _run(env, steps: int, rng: np.random.Generator) -> list[tuple]:
    out = []
    for _ in range(steps):
        observation, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        out.append((observation.tobytes(), float(reward), terminated, truncated))
        if terminated or truncated:
            break
    return out


@pytest.mark.parametrize("env_id", GYM_IDS)
def test_a_pickled_env_continues_bit_for_bit(env_id: str) -> None:
    env = gym.make(env_id, randomize=True, **SHORT[env_id])
    env.reset(seed=11)
    env.action_space.seed(5)
    for _ in range(3):
        env.step(env.action_space.sample())
    clone = pickle.loads(pickle.dumps(env))
    env.action_space.seed(6)
    clone.action_space.seed(6)
    rng = np.random.default_rng(0)
    assert _run(clone, 10, rng) == _run(env, 10, rng)
    assert clone.unwrapped.episode_metrics() == env.unwrapped.episode_metrics()
    # the next episode too (the copied random generator)
    assert np.array_equal(clone.reset()[0], env.reset()[0])


@pytest.mark.parametrize("env_id", GYM_IDS)
def test_a_pickled_vector_env_continues_bit_for_bit(env_id: str) -> None:
    vector = gym.make_vec(
        env_id,
        num_envs=3,
        vectorization_mode="vector_entry_point",
        randomize=True,
        **SHORT[env_id],
    )
    vector.reset(seed=2)
    vector.action_space.seed(1)
    vector.step(vector.action_space.sample())
    clone = pickle.loads(pickle.dumps(vector))
    for _ in range(8):
        actions = vector.action_space.sample()
        expected = vector.step(actions)
        got = clone.step(actions)
        for a, b in zip(expected[:4], got[:4], strict=True):
            assert np.array_equal(a, b)
    # each sub-environment still lives in its row of the restored batch
    clone.unwrapped.envs[1].state[0] = 123.0
    assert clone.unwrapped.arrays.state[1, 0] == 123.0


def test_a_pickled_pettingzoo_env_continues_bit_for_bit() -> None:
    env = etsc_envs.make_parallel(PETTINGZOO_ID, horizon_s=0.5, randomize=True)
    env.reset(seed=4)
    actions = {agent: 1 for agent in env.agents}
    env.step(actions)
    clone = pickle.loads(pickle.dumps(env))
    for step in range(5):
        actions = {agent: (step + i) % 2 for i, agent in enumerate(env.agents)}
        expected, got = env.step(actions), clone.step(actions)
        for agent in env.possible_agents:
            assert np.array_equal(expected[0][agent], got[0][agent])
            assert expected[1][agent] == got[1][agent]


# ----------------------------------------------------------------------- command lines
def _error_line(capsys) -> str:
    lines = [line for line in capsys.readouterr().err.splitlines() if "error:" in line]
    assert len(lines) == 1, lines
    assert "Traceback" not in capsys.readouterr().err
    return lines[0]


def test_evaluate_refuses_a_folder_for_json_before_running(tmp_path: Path, capsys) -> None:
    from baselines.evaluate import main

    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/AttitudeTracking-v0", "--policy", "paper", "--json", str(tmp_path)])
    assert exit_info.value.code == 2
    assert "--json" in _error_line(capsys)


def test_evaluate_refuses_a_plot_folder_under_a_file(tmp_path: Path, capsys) -> None:
    from baselines.evaluate import main

    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/AttitudeTracking-v0", "--policy", "paper", "--plot", str(blocker / "plots")])
    assert exit_info.value.code == 2
    assert "--plot" in _error_line(capsys)


def test_benchmark_refuses_a_json_path_under_a_file(tmp_path: Path, capsys) -> None:
    from etsc_envs.benchmark import main

    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(SystemExit) as exit_info:
        main(["--steps", "1", "--json", str(blocker / "out.json")])
    assert exit_info.value.code == 2
    assert "--json" in _error_line(capsys)


def test_results_refuses_an_unknown_id(capsys) -> None:
    from agents.judge.results import main

    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/Nope-v0", "--model", str(MODELS / "AttitudeTracking-v0_ppo.zip")])
    assert exit_info.value.code == 2
    assert "etsc/Nope-v0" in _error_line(capsys)


def _broken_model(tmp_path: Path, how: str) -> Path:
    source = MODELS / "AttitudeTracking-v0_ppo.zip"
    target = tmp_path / "model.zip"
    if how == "truncated":
        target.write_bytes(source.read_bytes()[:2000])
    elif how == "garbage":
        target.write_bytes(b"not a zip at all")
    elif how == "no data":
        with zipfile.ZipFile(target, "w") as archive:
            archive.writestr("policy.pth", b"")
    elif how == "garbage statistics":
        target.write_bytes(source.read_bytes())
        (tmp_path / "model_vecnormalize.npz").write_bytes(b"PK\x03\x04garbage")
    return target


@pytest.mark.parametrize("how", ["truncated", "garbage", "no data", "garbage statistics"])
def test_evaluate_refuses_a_damaged_model_with_one_line(tmp_path: Path, capsys, how) -> None:
    from baselines.evaluate import main

    model = _broken_model(tmp_path, how)
    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/AttitudeTracking-v0", "--policy", f"sb3:{model}", "--env-arg=horizon_s=0.05"])
    assert exit_info.value.code == 2
    assert str(tmp_path) in _error_line(capsys)


@pytest.mark.parametrize("tool", ["results", "pareto"])
def test_results_and_pareto_refuse_a_damaged_model(tmp_path: Path, capsys, tool) -> None:
    from agents.judge.pareto import main as pareto_main
    from agents.judge.results import main as results_main

    model = _broken_model(tmp_path, "truncated")
    main = results_main if tool == "results" else pareto_main
    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/AttitudeTracking-v0", "--model", str(model), "--out", str(tmp_path / "o")])
    assert exit_info.value.code == 2
    assert "model.zip" in _error_line(capsys)


def test_a_model_of_another_env_names_both_spaces(capsys) -> None:
    from baselines.evaluate import main

    model = MODELS / "AttitudeTracking-v0_ppo.zip"
    with pytest.raises(SystemExit):
        main(["etsc/InnerFormation-v0", "--policy", f"sb3:{model}", "--env-arg=horizon_s=0.05"])
    line = _error_line(capsys)
    assert "(14,)" in line and "(18,)" in line and "etsc/InnerFormation-v0" in line, line


# ----------------------------------------------------------------------- training
def tiny_training_config(out_dir: Path, **changes) -> dict:
    """A PPO run of a few seconds on 50-step episodes of paper 002."""
    config = {
        "env_id": "etsc/AttitudeTracking-v0",
        "env_kwargs": {"horizon_s": 0.05, "cost_scale": 0.01},
        "algorithm": "PPO",
        "policy": "MlpPolicy",
        "hyperparameters": {"n_steps": 64, "batch_size": 64, "n_epochs": 1},
        "total_timesteps": 192,
        "n_envs": 1,
        "out_dir": str(out_dir),
        "normalize_observations": True,
        "tensorboard": False,
        "checkpoint_every": 64,
        "evaluation_every": 64,
        "evaluation_scenarios": 2,
        "evaluation_env_kwargs": {"horizon_s": 0.05},
    }
    config.update(changes)
    return config


def train_main(tmp_path: Path, config: dict, *extra: str) -> int:
    import yaml

    from agents.train.training import main

    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config), encoding="utf-8")
    return main(["--config", str(path), *extra])


def test_train_refuses_an_unknown_env_kwarg_and_leaves_no_out_dir(tmp_path: Path, capsys):
    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    config = tiny_training_config(out_dir)
    config["env_kwargs"]["transmision_penalty"] = 1.0
    with pytest.raises(SystemExit):
        train_main(tmp_path, config)
    line = _error_line(capsys)
    assert "env_kwargs" in line and "transmision_penalty" in line, line
    assert not out_dir.exists()


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"hyperparameters": {"n_steps": 0}}, "hyperparameters.n_steps"),
        ({"hyperparameters": {"gamma": "high"}}, "hyperparameters.gamma"),
        (
            {"hyperparameters": {"normalize_advantage": "yes"}},
            "hyperparameters.normalize_advantage",
        ),
    ],
)
def test_config_refuses_bad_hyperparameters(tmp_path: Path, change, key) -> None:
    pytest.importorskip("stable_baselines3")
    from agents.train.config import config_from_dict

    with pytest.raises(ValueError) as error:
        config_from_dict(tiny_training_config(tmp_path / "run", **change))
    assert_one_line(error, key)


def test_config_refuses_an_out_dir_under_a_file(tmp_path: Path) -> None:
    pytest.importorskip("stable_baselines3")
    from agents.train.config import config_from_dict

    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(ValueError) as error:
        config_from_dict(tiny_training_config(blocker / "run"))
    assert_one_line(error, "out_dir")


def test_train_refuses_init_from_a_model_of_another_env(tmp_path: Path, capsys) -> None:
    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    config = tiny_training_config(
        out_dir,
        env_id="etsc/InnerFormation-v0",
        init_from=str(MODELS / "AttitudeTracking-v0_ppo.zip"),
    )
    with pytest.raises(SystemExit):
        train_main(tmp_path, config)
    line = _error_line(capsys)
    assert "init_from" in line and "(14,)" in line and "(18,)" in line, line
    assert not out_dir.exists()


def _evaluations(out_dir: Path) -> list[dict]:
    import json

    return json.loads((out_dir / "evaluations.json").read_text(encoding="utf-8"))


def test_resume_keeps_the_evaluation_history(tmp_path: Path) -> None:
    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    config = tiny_training_config(out_dir)
    assert train_main(tmp_path, config) == 0
    before = _evaluations(out_dir)
    assert [entry["timesteps"] for entry in before] == [64, 128, 192]
    assert train_main(tmp_path, config, "--timesteps", "320", "--resume") == 0
    after = _evaluations(out_dir)
    assert after[: len(before)] == before
    assert [entry["timesteps"] for entry in after] == [64, 128, 192, 256, 320]
    # one instant per training step here, counted on across the resume
    assert [entry["env_steps"] for entry in after] == [64, 128, 192, 256, 320]
    wall_times = [entry["wall_time_s"] for entry in after]
    assert wall_times == sorted(wall_times) and wall_times[0] > 0


@pytest.mark.parametrize(
    "change",
    [
        {"seed": 7},
        {"env_kwargs": {"horizon_s": 0.05, "cost_scale": 0.01, "transmission_penalty": 3.0}},
        {"hyperparameters": {"n_steps": 64, "batch_size": 64, "n_epochs": 1, "learning_rate": 0.1}},
    ],
)
def test_resume_refuses_checkpoints_of_another_config(tmp_path: Path, capsys, change) -> None:
    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    assert train_main(tmp_path, tiny_training_config(out_dir)) == 0
    capsys.readouterr()
    with pytest.raises(SystemExit):
        train_main(tmp_path, tiny_training_config(out_dir, **change), "--resume")
    line = _error_line(capsys)
    assert "another config" in line and next(iter(change)) in line, line


def test_a_fresh_run_refuses_an_out_dir_holding_checkpoints(tmp_path: Path, capsys) -> None:
    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    assert train_main(tmp_path, tiny_training_config(out_dir)) == 0
    capsys.readouterr()
    with pytest.raises(SystemExit):
        train_main(tmp_path, tiny_training_config(out_dir, seed=3))
    assert "--resume" in _error_line(capsys)


@pytest.mark.parametrize("damage", ["truncated zip", "missing statistics"])
def test_resume_falls_back_past_a_torn_checkpoint(tmp_path: Path, capsys, damage) -> None:
    import json

    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    config = tiny_training_config(out_dir)
    assert train_main(tmp_path, config) == 0
    checkpoints = out_dir / "checkpoints"
    if damage == "truncated zip":
        newest = checkpoints / "model_192_steps.zip"
        newest.write_bytes(newest.read_bytes()[:1000])
    else:
        (checkpoints / "model_vecnormalize_192_steps.npz").unlink()
    assert train_main(tmp_path, config, "--timesteps", "256", "--resume") == 0
    assert "skipping model_192_steps.zip" in capsys.readouterr().err
    summary = json.loads((out_dir / "train_summary.json").read_text(encoding="utf-8"))
    assert summary["resumed_from"].endswith("model_128_steps.zip")
    assert [entry["timesteps"] for entry in _evaluations(out_dir)] == [64, 128, 192, 256]


def test_interrupted_training_resumes_with_its_whole_history(tmp_path: Path) -> None:
    """SIGINT mid-run: one line and status 130, no traceback; ``--resume`` then keeps every
    evaluation up to the checkpoint it continues from."""
    import signal
    import subprocess
    import sys
    import time

    import yaml

    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    config = tiny_training_config(out_dir, total_timesteps=1_000_000)
    config_path = tmp_path / "config.yaml"
    config_path.write_text(yaml.safe_dump(config), encoding="utf-8")
    command = [sys.executable, "-m", "agents.train", "--config", str(config_path)]
    root = Path(__file__).parents[1]
    log = tmp_path / "stderr.txt"
    with open(log, "w", encoding="utf-8") as stderr_file:  # a file: a pipe could fill and block
        process = subprocess.Popen(
            command,
            cwd=root,
            stdout=subprocess.DEVNULL,
            stderr=stderr_file,
            # a test run started in the background ignores SIGINT, and so would the child
            preexec_fn=interruptible,
        )
        evaluations = out_dir / "evaluations.json"
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline and process.poll() is None:
            if evaluations.is_file() and len(_evaluations(out_dir)) >= 4:
                break
            time.sleep(0.2)
        process.send_signal(signal.SIGINT)
        process.wait(timeout=120)
    stderr = log.read_text(encoding="utf-8")
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr, stderr
    assert "--resume" in stderr
    before = _evaluations(out_dir)
    assert len(before) >= 4

    newest = max(
        int(p.stem.split("_")[1]) for p in (out_dir / "checkpoints").glob("model_*_steps.zip")
    )
    resumed = subprocess.run(
        [*command, "--timesteps", str(newest + 128), "--resume"],
        cwd=root,
        capture_output=True,
        text=True,
        timeout=240,
    )
    assert resumed.returncode == 0, resumed.stderr
    after = _evaluations(out_dir)
    kept = [entry for entry in before if entry["timesteps"] <= newest]
    assert after[: len(kept)] == kept
    assert [entry["timesteps"] for entry in after] == list(range(64, newest + 129, 64))


@pytest.fixture
def python_sigint_handler():
    """Python's own SIGINT handler for the test (a test run started in the background
    ignores SIGINT)."""
    import signal

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_sigint_inside_interrupts_deferred_arrives_when_the_block_ends(python_sigint_handler):
    import signal

    from etsc_envs.core.files import interrupts_deferred

    finished = False
    with pytest.raises(KeyboardInterrupt), interrupts_deferred():
        signal.raise_signal(signal.SIGINT)
        finished = True
    assert finished
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with interrupts_deferred():  # no signal, nothing raised
        pass


def test_a_model_interrupted_while_being_written_is_written_whole(
    tmp_path: Path, python_sigint_handler
):
    """SIGINT in the middle of writing a model (where PyTorch's zip writer would turn it into
    a ``RuntimeError``) waits until the model and its statistics are on disk."""
    import signal

    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from agents.train.model_files import write_model
    from etsc_envs.sb3_models import normalization_path

    env = VecNormalize(DummyVecEnv([lambda: gym.make(GYM_IDS[0], **SHORT[GYM_IDS[0]])]))
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=64, device="cpu")
    save = model.save

    def interrupted_save(*args, **kwargs):
        signal.raise_signal(signal.SIGINT)
        save(*args, **kwargs)

    model.save = interrupted_save
    path = tmp_path / "model.zip"
    with pytest.raises(KeyboardInterrupt):
        write_model(model, path)
    assert normalization_path(path).is_file()
    restored = PPO.load(path, device="cpu")
    for name, tensor in model.policy.state_dict().items():
        assert np.array_equal(restored.policy.state_dict()[name].numpy(), tensor.numpy())


# ----------------------------------------------------------------------- output files (issue 41)
def _unwritable_folder(tmp_path: Path) -> Path:
    """A folder no file can be created in, whoever runs the test (``/proc`` refuses root too,
    where ``os.access`` says yes)."""
    return Path("/proc") if Path("/proc/self").is_dir() else tmp_path


@pytest.mark.parametrize("kind", ["file", "folder"])
def test_outputs_under_an_unwritable_place_are_refused_with_a_probe(tmp_path, kind) -> None:
    from etsc_envs.core.files import require_writable_file, require_writable_folder

    place = _unwritable_folder(tmp_path)
    if place == tmp_path:
        pytest.skip("no /proc on this system")
    check = require_writable_file if kind == "file" else require_writable_folder
    with pytest.raises(ValueError) as error:
        check(place / "out" / "x.json", "--json")
    assert_one_line(error, "--json", "cannot be written", "/proc")


def test_a_folder_where_a_file_is_wanted_and_the_reverse_are_refused(tmp_path) -> None:
    from etsc_envs.core.files import require_writable_file, require_writable_folder

    (tmp_path / "file.json").write_text("x")
    with pytest.raises(ValueError) as error:
        require_writable_file(tmp_path, "--json")
    assert_one_line(error, "--json must name a file")
    with pytest.raises(ValueError) as error:
        require_writable_folder(tmp_path / "file.json", "--plot")
    assert_one_line(error, "--plot must name a folder")
    with pytest.raises(ValueError) as error:
        require_writable_folder(tmp_path / "file.json" / "plots", "--plot")
    assert_one_line(error, "--plot", "is a file, not a folder")


def test_a_symlinked_output_is_written_through_the_link(tmp_path) -> None:
    from etsc_envs.core.files import atomic_write_text

    real = tmp_path / "real.json"
    real.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(real)
    atomic_write_text(link, "new")
    assert link.is_symlink() and real.read_text() == "new"


def test_a_fifo_output_is_written_in_place(tmp_path) -> None:
    import os
    import threading

    from etsc_envs.core.files import atomic_write_text, require_writable_file

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    require_writable_file(fifo, "--json")
    received: list[str] = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()))
    reader.start()
    atomic_write_text(fifo, "through the pipe")
    reader.join(timeout=10)
    assert received == ["through the pipe"] and fifo.is_fifo()


def test_dev_null_stays_a_device() -> None:
    from etsc_envs.core.files import atomic_write_text, require_writable_file

    null = Path("/dev/null")
    if not null.is_char_device():
        pytest.skip("no /dev/null")
    require_writable_file(null, "--json")
    atomic_write_text(null, "discarded")
    assert null.is_char_device()


def test_outputs_keep_the_umask_permissions(tmp_path) -> None:
    import os
    import stat

    from etsc_envs.core.files import atomic_write_text

    previous = os.umask(0o027)
    try:
        atomic_write_text(tmp_path / "new.json", "x")
    finally:
        os.umask(previous)
    assert stat.S_IMODE((tmp_path / "new.json").stat().st_mode) == 0o640
    existing = tmp_path / "existing.json"
    existing.write_text("x")
    existing.chmod(0o604)
    atomic_write_text(existing, "y")
    assert stat.S_IMODE(existing.stat().st_mode) == 0o604


@pytest.mark.parametrize(
    ("option", "where"),
    [("--json", "folder"), ("--plot", "file"), ("--json", "proc")],
)
def test_reproduce_checks_its_outputs_before_running(tmp_path, capsys, option, where) -> None:
    from baselines.reproduce import main

    (tmp_path / "file.json").write_text("x")
    value = {
        "folder": str(tmp_path),
        "file": str(tmp_path / "file.json"),
        "proc": "/proc/x.json",
    }[where]
    if where == "proc" and _unwritable_folder(tmp_path) == tmp_path:
        pytest.skip("no /proc on this system")
    with pytest.raises(SystemExit) as exit_info:
        main(["--paper", "002", option, value])
    assert exit_info.value.code == 2
    assert option in _error_line(capsys)


# ----------------------------------------------------------------------- model files carry data
class _Planted:
    """Unpickling this creates the file named by ``marker`` (what a crafted file could do)."""

    def __init__(self, marker: str) -> None:
        self.marker = marker

    def __reduce__(self):
        return (Path.touch, (Path(self.marker),))


def _copy_model(tmp_path: Path, name: str = "AttitudeTracking-v0_ppo") -> Path:
    target = tmp_path / "model.zip"
    target.write_bytes((MODELS / f"{name}.zip").read_bytes())
    statistics = MODELS / f"{name}_vecnormalize.npz"
    (tmp_path / "model_vecnormalize.npz").write_bytes(statistics.read_bytes())
    return target


def test_a_pickle_planted_beside_a_model_is_not_run(tmp_path: Path, capsys) -> None:
    from baselines.evaluate import main

    model = _copy_model(tmp_path)
    marker = tmp_path / "ran"
    (tmp_path / "model_vecnormalize.npz").unlink()
    (tmp_path / "model_vecnormalize.pkl").write_bytes(pickle.dumps(_Planted(str(marker))))
    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/AttitudeTracking-v0", "--policy", f"sb3:{model}", "--env-arg=horizon_s=0.05"])
    assert exit_info.value.code == 2
    line = _error_line(capsys)
    assert "model_vecnormalize.pkl" in line and "agents.train.convert_statistics" in line, line
    assert not marker.exists()


def test_a_pickle_planted_as_npz_statistics_is_not_run(tmp_path: Path, capsys) -> None:
    from baselines.evaluate import main

    model = _copy_model(tmp_path)
    marker = tmp_path / "ran"
    np.savez(
        tmp_path / "model_vecnormalize.npz",
        observation_mean=np.array([_Planted(str(marker))], dtype=object),
    )
    with pytest.raises(SystemExit):
        main(["etsc/AttitudeTracking-v0", "--policy", f"sb3:{model}", "--env-arg=horizon_s=0.05"])
    assert "model_vecnormalize.npz" in _error_line(capsys)
    assert not marker.exists()


def test_the_converter_refuses_a_planted_pickle_without_running_it(tmp_path: Path, capsys):
    from agents.train.convert_statistics import main

    marker = tmp_path / "ran"
    planted = tmp_path / "model_vecnormalize.pkl"
    planted.write_bytes(pickle.dumps(_Planted(str(marker))))
    assert main([str(planted)]) == 1
    err = capsys.readouterr().err
    assert "is not a pickled VecNormalize" in err and "pathlib" in err, err
    assert not marker.exists() and planted.exists()


def test_a_pickle_planted_in_a_models_data_record_is_not_run(tmp_path: Path, capsys) -> None:
    """SB3 keeps the objects it cannot write as JSON as cloudpickle blobs in the zip's
    ``data`` record; the loader reads the record as JSON and unpickles none of them."""
    import base64
    import json

    from baselines.evaluate import main

    source = _copy_model(tmp_path)
    marker = tmp_path / "ran"
    blob = base64.b64encode(pickle.dumps(_Planted(str(marker)))).decode()
    model = tmp_path / "planted.zip"
    with zipfile.ZipFile(source) as original, zipfile.ZipFile(model, "w") as planted:
        for item in original.infolist():
            data = original.read(item.filename)
            if item.filename == "data":
                record = json.loads(data)
                for key in ("observation_space", "clip_range", "lr_schedule", "_last_obs"):
                    record[key][":serialized:"] = blob
                record["extra"] = {":type:": "<class 'x'>", ":serialized:": blob}
                data = json.dumps(record).encode()
            planted.writestr(item, data)
    (tmp_path / "planted_vecnormalize.npz").write_bytes(
        (tmp_path / "model_vecnormalize.npz").read_bytes()
    )
    with pytest.raises(SystemExit):
        main(["etsc/AttitudeTracking-v0", "--policy", f"sb3:{model}", "--env-arg=horizon_s=0.05"])
    line = _error_line(capsys)
    assert "planted.zip" in line and "pickled ['extra']" in line, line
    assert not marker.exists()
    # without the unknown entry the model loads, and still nothing ran
    from etsc_envs.sb3_models import load_sb3

    with zipfile.ZipFile(model) as archive:
        record = json.loads(archive.read("data"))
    del record["extra"]
    again = tmp_path / "again.zip"
    with zipfile.ZipFile(model) as original, zipfile.ZipFile(again, "w") as copy:
        for item in original.infolist():
            data = original.read(item.filename)
            copy.writestr(item, json.dumps(record).encode() if item.filename == "data" else data)
    env = gym.make("etsc/AttitudeTracking-v0")
    load_sb3(again, observation_space=env.observation_space, action_space=env.action_space)
    assert not marker.exists()


def test_statistics_of_another_env_beside_a_model_are_named(tmp_path: Path, capsys) -> None:
    from baselines.evaluate import main

    model = _copy_model(tmp_path)
    (tmp_path / "model_vecnormalize.npz").write_bytes(
        (MODELS / "InnerFormation-v0_ppo_vecnormalize.npz").read_bytes()
    )
    with pytest.raises(SystemExit):
        main(["etsc/AttitudeTracking-v0", "--policy", f"sb3:{model}", "--env-arg=horizon_s=0.05"])
    line = _error_line(capsys)
    assert "model_vecnormalize.npz" in line and "(18,)" in line and "(14,)" in line, line


def test_the_converter_keeps_the_statistics_exactly(tmp_path: Path) -> None:
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from agents.train.convert_statistics import convert
    from etsc_envs.sb3_models import ObservationStatistics

    env_id = GYM_IDS[0]
    live = VecNormalize(DummyVecEnv([lambda: gym.make(env_id, **SHORT[env_id])]))
    live.reset()
    for _ in range(20):
        live.step(np.zeros((1, *live.action_space.shape), dtype=live.action_space.dtype))
    live.training = False
    legacy = tmp_path / "model_vecnormalize.pkl"
    legacy.write_bytes(pickle.dumps(live))
    converted = ObservationStatistics.read(convert(legacy))
    assert not legacy.exists()
    observations = np.random.default_rng(0).normal(size=(8, *live.observation_space.shape))
    observations = observations.astype(np.float32)
    assert np.array_equal(converted.normalize_obs(observations), live.normalize_obs(observations))


def test_shipped_models_carry_no_pickled_statistics() -> None:
    assert not list(MODELS.glob("*.pkl"))
    for statistics in MODELS.glob("*_vecnormalize.npz"):
        with np.load(statistics, allow_pickle=False) as archive:
            assert all(archive[name].dtype != object for name in archive.files)


# ----------------------------------------------------------------------- run folders
def test_a_finished_run_is_not_replaced_without_overwrite(tmp_path: Path, capsys) -> None:
    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    config = tiny_training_config(out_dir, total_timesteps=64, checkpoint_every=0)
    assert train_main(tmp_path, config) == 0
    model = (out_dir / "model.zip").read_bytes()
    capsys.readouterr()
    with pytest.raises(SystemExit):
        train_main(tmp_path, config)
    line = _error_line(capsys)
    assert "--resume" in line and "--overwrite" in line and "model.zip" in line, line
    assert (out_dir / "model.zip").read_bytes() == model
    assert train_main(tmp_path, {**config, "seed": 5}, "--overwrite") == 0
    assert (out_dir / "model.zip").read_bytes() != model


def test_a_second_process_cannot_train_into_a_running_runs_folder(tmp_path: Path, capsys):
    import filelock

    pytest.importorskip("stable_baselines3")
    out_dir = tmp_path / "run"
    out_dir.mkdir()
    # what a running agents.train holds
    with filelock.FileLock(out_dir / ".train.lock"), pytest.raises(SystemExit):
        train_main(tmp_path, tiny_training_config(out_dir))
    line = _error_line(capsys)
    assert "in use by another agents.train run" in line, line
    assert not (out_dir / "model.zip").exists()


# ----------------------------------------------------------------------- interrupts
def test_an_interrupted_evaluation_writes_its_finished_episodes(tmp_path, capsys, monkeypatch):
    """Ctrl-C during the fourth of six episodes (run one by one, as with --plot): the three
    finished episodes' records are written, marked partial, with one line and status 130."""
    import json

    import baselines.evaluate as evaluate_module

    plotted: list[Path] = []

    def plot_or_interrupt(trace, path, title):
        if len(plotted) == 3:
            raise KeyboardInterrupt
        plotted.append(path)

    monkeypatch.setattr(evaluate_module, "plot_episode", plot_or_interrupt)
    output = tmp_path / "partial.json"
    status = evaluate_module.main(
        [
            "etsc/AttitudeTracking-v0",
            "--policy",
            "paper",
            "--env-arg=horizon_s=0.05",
            "--episodes",
            "6",
            "--plot",
            str(tmp_path / "plots"),
            "--json",
            str(output),
        ]
    )
    err = capsys.readouterr().err
    assert status == 130
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1] == (
        f"interrupted: 4 of 6 episode(s) finished, their records written to {output}, "
        "marked partial"
    )
    written = json.loads(output.read_text(encoding="utf-8"))
    assert written["partial"] is True
    assert [record["seed"] for record in written["episodes"]] == [0, 1, 2, 3]


def test_an_interrupted_process_sweep_says_how_to_resume(tmp_path: Path) -> None:
    import signal
    import subprocess
    import sys
    import time

    import yaml

    from tests.sweep_fixtures import TINY, tiny_sweep

    pytest.importorskip("stable_baselines3")
    overrides = yaml.safe_load(TINY.read_text(encoding="utf-8"))["overrides"]
    config = tiny_sweep(tmp_path, overrides={**overrides, "total_timesteps": 10_000_000})
    code = (
        "import sys\n"
        "sys.modules['ray'] = None\n"
        "from agents.sweep.runner import main\n"
        f"raise SystemExit(main(['--config', {str(config)!r}, '--processes', '1']))\n"
    )
    log = tmp_path / "stderr.txt"
    with open(log, "w", encoding="utf-8") as stderr_file:
        process = subprocess.Popen(
            [sys.executable, "-c", code],
            cwd=Path(__file__).parents[1],
            stdout=subprocess.DEVNULL,
            stderr=stderr_file,
            preexec_fn=interruptible,
        )
        trials = tmp_path / "sweep" / "trials"
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline and not list(trials.glob("*/evaluations.json")):
            time.sleep(0.5)
        process.send_signal(signal.SIGINT)
        process.wait(timeout=120)
    stderr = log.read_text(encoding="utf-8")
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr, stderr
    assert "--processes 1 --resume" in stderr.strip().splitlines()[-1], stderr


# ----------------------------------------------------------------------- ranges (issue 41)
@pytest.mark.parametrize("env_id", GYM_IDS)
def test_the_smallest_accepted_cost_scale_keeps_rewards_finite(env_id: str) -> None:
    from etsc_envs.core.validation import MAX_TRANSMISSION_PENALTY, MIN_COST_SCALE

    with pytest.raises(ValueError) as error:
        gym.make(env_id, cost_scale=1e-320)
    assert_one_line(error, "cost_scale", "[1e-06")
    with pytest.raises(ValueError) as error:
        gym.make(env_id, transmission_penalty=1e308)
    assert_one_line(error, "transmission_penalty", "1e+12")
    env = gym.make(
        env_id,
        cost_scale=MIN_COST_SCALE,
        transmission_penalty=MAX_TRANSMISSION_PENALTY,
        **SHORT[env_id],
    )
    env.reset(seed=0)
    for _ in range(3):
        _, reward, terminated, truncated, _ = env.step(bits(env, 1))
        assert np.isfinite(reward)
        if terminated or truncated:
            break


@pytest.mark.parametrize("duration", [0.1, 0.3, 0.0])
def test_asteroid_burst_is_a_whole_number_of_steps(duration: float) -> None:
    with pytest.raises(ValueError) as error:
        gym.make("etsc/AsteroidOrbitKeeping-v0", burst_duration_s=duration)
    assert_one_line(error, "burst_duration_s")
    gym.make("etsc/AsteroidOrbitKeeping-v0", burst_duration_s=0.5)


def test_a_near_singular_inertia_is_refused() -> None:
    with pytest.raises(ValueError) as error:
        gym.make("etsc/AttitudeTracking-v0", nominal_inertia=np.diag([1.0, 1.0, 1e-17]))
    assert_one_line(error, "nominal_inertia", "well conditioned")


@pytest.mark.parametrize("maker", ["make_parallel", "make_aec"])
def test_make_parallel_refuses_the_max_cycles_the_module_refuses(maker: str) -> None:
    from etsc_envs import cluster_containment_v0

    for make in (getattr(etsc_envs, maker), None):
        with pytest.raises(ValueError) as error:
            if make is None:
                cluster_containment_v0.parallel_env(max_cycles=-1)
            else:
                make(PETTINGZOO_ID, max_cycles=-1)
        assert_one_line(error, "max_cycles", ">= 1", "-1")


def test_pettingzoo_actions_name_what_they_allow() -> None:
    from etsc_envs import cluster_containment_v0

    parallel = etsc_envs.make_parallel(PETTINGZOO_ID, horizon_s=0.5)
    parallel.reset(seed=0)
    with pytest.raises(ValueError) as error:
        parallel.step(None)
    assert_one_line(error, "actions must be a dict", "follower_0", "None")
    aec = cluster_containment_v0.env(horizon_s=0.5)
    aec.reset(seed=0)
    with pytest.raises(ValueError) as error:
        aec.step(2)
    assert_one_line(error, "action of follower_0", "0 (hold) or 1 (transmit)", "2")


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"gamma": 1.5}, "gamma"),
        ({"gamma": 0.0}, "gamma"),
        ({"gae_lambda": 1.2}, "gae_lambda"),
        ({"learning_rate": -1e-3}, "learning_rate"),
        ({"learning_rate": float("nan")}, "learning_rate"),
        ({"ent_coef": -0.1}, "ent_coef"),
    ],
)
def test_config_refuses_hyperparameters_out_of_range(tmp_path: Path, change, key) -> None:
    pytest.importorskip("stable_baselines3")
    from agents.train.config import config_from_dict

    hyperparameters = {"n_steps": 64, "batch_size": 64, "n_epochs": 1, **change}
    with pytest.raises(ValueError) as error:
        config_from_dict(tiny_training_config(tmp_path / "run", hyperparameters=hyperparameters))
    assert_one_line(error, f"hyperparameters.{key}")


EVALUATE_FINDINGS = [
    (["--env-arg", "initial_rate=[0,0"], "--env-arg initial_rate"),
    (["--policy-arg", "psi=abc"], "--policy-arg psi must be a finite number"),
    (["--policy-arg", "heartbeat=abc"], "--policy-arg heartbeat must be an integer >= 1"),
    (["--policy-arg", "foo=1"], "--policy-arg foo: paper on etsc/AttitudeTracking-v0 takes"),
    (["--scenarios", "paper", "--set-size", "-4"], "--set-size"),
    (["--windows", "10,20"], "windows_s: the first window must start inside"),
]


@pytest.mark.parametrize(("extra", "expected"), EVALUATE_FINDINGS)
def test_evaluate_names_the_argument_and_what_it_allows(capsys, extra, expected) -> None:
    from baselines.evaluate import main

    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/AttitudeTracking-v0", "--policy", "paper", "--env-arg=horizon_s=0.05", *extra])
    assert exit_info.value.code == 2
    assert expected in _error_line(capsys)


@pytest.mark.parametrize(
    ("policy", "argument", "expected"),
    [
        ("sb3:", None, "--policy sb3: needs the path of a model zip"),
        ("periodic", "every=nan", "--policy-arg every must be an integer >= 1"),
        ("always", "every=3", "always on etsc/AttitudeTracking-v0 takes no --policy-arg"),
    ],
)
def test_policy_specs_name_what_they_take(capsys, policy, argument, expected) -> None:
    from baselines.evaluate import main

    extra = [] if argument is None else ["--policy-arg", argument]
    with pytest.raises(SystemExit):
        main(["etsc/AttitudeTracking-v0", "--policy", policy, "--env-arg=horizon_s=0.05", *extra])
    assert expected in _error_line(capsys)


def test_pareto_refuses_a_reuse_file_that_is_not_json(tmp_path: Path, capsys) -> None:
    from agents.judge.pareto import main

    not_json = tmp_path / "notjson.zip"
    not_json.write_bytes(b"PK\x03\x04")
    with pytest.raises(SystemExit) as exit_info:
        main(["etsc/AttitudeTracking-v0", "--reuse", str(not_json), "--out", str(tmp_path / "o")])
    assert exit_info.value.code == 2
    assert "--reuse: takes the pareto.json of an earlier run" in _error_line(capsys)


# ----------------------------------------------------------------------- properties (hypothesis)
hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

ANY_VALUE = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.lists(st.floats(allow_nan=False, width=32), max_size=4),
)


@settings(max_examples=25, deadline=None)
@given(
    keyword=st.sampled_from(["cost_scale", "transmission_penalty", "horizon_s", "randomize"]),
    value=ANY_VALUE,
)
def test_property_a_keyword_value_is_refused_by_name_or_runs_finite(keyword, value) -> None:
    env_id = "etsc/AttitudeTracking-v0"
    kwargs = {"horizon_s": 0.05, keyword: value}
    try:
        env = gym.make(env_id, **kwargs)
    except (ValueError, TypeError) as error:
        message = str(error)
        assert "\n" not in message and keyword in message, message
        return
    observation, _ = env.reset(seed=0)
    for _ in range(min(env.unwrapped.n_steps, 5)):
        observation, reward, terminated, truncated, _ = env.step(1)
        assert np.isfinite(reward) and np.all(np.isfinite(observation))
        if terminated or truncated:
            break


@settings(max_examples=30, deadline=None)
@given(action=st.one_of(ANY_VALUE, st.integers(), st.dictionaries(st.text(max_size=3), ANY_VALUE)))
def test_property_a_pettingzoo_action_is_refused_with_one_line_or_taken(action) -> None:
    parallel = etsc_envs.make_parallel(PETTINGZOO_ID, horizon_s=0.5)
    parallel.reset(seed=0)
    try:
        parallel.step(action)
    except ValueError as error:
        assert "\n" not in str(error) and "action" in str(error)
    else:  # only a dict of 0/1 per agent is taken
        assert isinstance(action, dict)


@settings(
    max_examples=20,
    deadline=None,  # capsys is read out at the start of every input
    suppress_health_check=[hypothesis.HealthCheck.function_scoped_fixture],
)
@given(
    option=st.sampled_from(["--policy-arg", "--env-arg"]),
    key=st.sampled_from(["psi", "every", "heartbeat", "floor", "initial_rate", "x"]),
    value=st.text(
        alphabet=st.characters(min_codepoint=32, max_codepoint=126, blacklist_characters="\\"),
        max_size=6,
    ),
)
def test_property_a_command_line_value_is_refused_with_one_line_naming_it(
    option, key, value, capsys
) -> None:
    from baselines.evaluate import main

    capsys.readouterr()
    arguments = ["etsc/AttitudeTracking-v0", "--policy", "paper", "--env-arg=horizon_s=0.005"]
    try:
        status = main([*arguments, option, f"{key}={value}"])
    except SystemExit as exit_info:
        assert exit_info.code == 2
        line = _error_line(capsys)
        assert option in line or key in line, line
    else:
        assert status == 0


@pytest.mark.parametrize("mode", [3, 2.5, ["human"]])
def test_a_render_mode_that_is_not_a_string_is_refused_through_gym_make(mode) -> None:
    """gym.make tests the mode against the metadata and calls string methods on it before the
    env's constructor runs; the metadata's render_modes refuse it with one line."""
    import gymnasium as gym

    import etsc_envs

    with pytest.raises(ValueError, match="render_mode must be one of"):
        gym.make("etsc/AttitudeTracking-v0", render_mode=mode)
    with pytest.raises(ValueError, match="render_mode must be one of"):
        etsc_envs.make_parallel("etsc/ClusterContainment-v0", render_mode=mode)
