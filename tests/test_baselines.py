"""Reference trigger policies and the evaluation / reproduction commands of ``baselines``.

Checked properties:

* every trigger policy answers like Stable-Baselines3: one observation gives one action of the
  action space, a batch ``(n, obs_dim)`` gives ``(n,)`` actions; the paper's trigger transmits
  exactly when the eq. (27) statistic exceeds Ψ;
* ``PeriodicPolicy(every=K)`` transmits at steps 0, K, 2K, ... of an episode, restarts its
  counter on ``episode_start`` and rejects non-positive periods; ``SwitchedPeriodicPolicy``
  keeps period K before instant N and K2 after it (counted from the last transmission), is
  the plain clock when N = 0 or beyond the episode, restarts at an episode's start, and runs
  from the command line;
* ``evaluate`` returns the design page's JSON (``env``, ``policy``, ``episodes`` records with the
  required keys, ``mean``), whose ``return`` is the sum of the episode's rewards; the command
  line writes parseable JSON to stdout and turns bad input into argparse errors (exit code 2);
* ``--windows`` / ``windows_s`` split each episode by time: the windows' summed costs and
  transmissions add up to the episode's (a clock's are known exactly), the split episode is
  the batch run's, and bad edges are refused naming the argument;
* ``k=v`` arguments are read as YAML values; the reproduction report prints the paper's value
  beside ours;
* a Stable-Baselines3 model saved by any algorithm loads back through ``load_sb3`` (algorithm
  inferred from the zip) and runs through ``evaluate`` as ``sb3:PATH``.
"""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import etsc_envs  # noqa: F401  (registers the ids)
from baselines import evaluate as evaluate_module
from baselines import reproduce
from baselines.evaluate import evaluate
from baselines.reproductions.report import Scenario, claim, metric_row, render, stages
from etsc_envs.evaluation.arguments import parse_assignments
from etsc_envs.evaluation.episodes import run_episode, to_jsonable
from etsc_envs.papers import paper_of
from etsc_envs.sb3_models import infer_sb3_algorithm, load_sb3
from etsc_envs.triggers import (
    AlwaysPolicy,
    AttitudeTrackingTrigger,
    PeriodicPolicy,
    SwitchedPeriodicPolicy,
)

ENV_ID = "etsc/AttitudeTracking-v0"
RECORD_KEYS = {
    "steps",
    "sim_time_s",
    "wall_time_s",
    "return",
    "mean_cost",
    "transmissions",
    "transmission_rate",
    "mean_interevent_s",
    "min_interevent_s",
    "failure",
    "E_v",
    "E_q",
    "T_A_ms",
    "E_c",
}


# --------------------------------------------------------------------------- helpers
@pytest.fixture
def env() -> gym.Env:
    """A short paper-scenario environment (0.1 s, 100 sampling instants)."""
    environment = gym.make(ENV_ID, horizon_s=0.1)
    yield environment
    environment.close()


def make_trigger(kind: str, env: gym.Env, **kwargs):
    """One of the reference policies for ``env``."""
    if kind == "always":
        return AlwaysPolicy(env.observation_space, env.action_space, **kwargs)
    if kind == "periodic":
        return PeriodicPolicy(env.observation_space, env.action_space, **kwargs)
    names = env.unwrapped.observation_names
    return AttitudeTrackingTrigger(env.observation_space, env.action_space, names, **kwargs)


def observation_batch(env: gym.Env, n: int, seed: int = 0) -> np.ndarray:
    """``n`` observations of a random-action rollout, shape ``(n, obs_dim)``."""
    rng = np.random.default_rng(seed)
    obs, _ = env.reset(seed=seed)
    batch = []
    for _ in range(n):
        batch.append(obs)
        obs, *_ = env.step(int(rng.integers(2)))
    return np.array(batch)


def evaluate_cli(capsys, *args: str) -> dict:
    """``python -m baselines.evaluate ... --json -`` in-process, its stdout parsed."""
    assert evaluate_module.main([*args, "--json", "-"]) == 0
    return json.loads(capsys.readouterr().out)


def assert_exits_with_usage_error(capsys, main, argv: list[str], message: str) -> None:
    """``main(argv)`` stops through ``parser.error``: exit code 2 and ``message`` on stderr."""
    with pytest.raises(SystemExit) as stopped:
        main(argv)
    assert stopped.value.code == 2
    assert message in capsys.readouterr().err


# --------------------------------------------------------------------------- predict
@pytest.mark.parametrize("kind", ["always", "periodic", "paper"])
def test_predict_single_and_batch(env, kind):
    policy = make_trigger(kind, env)
    batch = observation_batch(env, 6)
    action, _ = policy.predict(batch[0])
    assert np.ndim(action) == 0
    assert env.action_space.contains(int(action))
    actions, _ = policy.predict(batch, episode_start=np.ones(6, dtype=bool))
    assert actions.shape == (6,)
    assert all(env.action_space.contains(int(a)) for a in actions)


def test_always_transmits_everything(env):
    actions, state = make_trigger("always", env).predict(observation_batch(env, 5))
    assert_array_equal(actions, np.ones(5))
    assert state is None


@pytest.mark.parametrize("psi", [0.1, 1.5])
def test_paper_trigger_compares_the_statistic_with_psi(env, psi):
    policy = make_trigger("paper", env, psi=psi)
    index = env.unwrapped.observation_index("trigger_statistic")
    batch = np.zeros((4, env.observation_space.shape[0]), dtype=np.float32)
    batch[:, index] = [0.0, 0.5 * psi, 0.99 * psi, 1.01 * psi]
    actions, _ = policy.predict(batch)
    assert_array_equal(actions, [0, 0, 0, 1])
    single, _ = policy.predict(batch[3])
    assert single == 1


@pytest.mark.parametrize("psi", [0.0, -1.0, float("nan")])
def test_paper_trigger_rejects_bad_psi(env, psi):
    with pytest.raises(ValueError, match="psi"):
        make_trigger("paper", env, psi=psi)


def test_paper_trigger_is_registered_for_the_env():
    assert paper_of(ENV_ID).trigger is AttitudeTrackingTrigger


# --------------------------------------------------------------------------- periodic
def test_periodic_transmits_every_k_instants(env):
    record, trace = run_episode(env, make_trigger("periodic", env, every=4), seed=0)
    assert record["steps"] == 100
    assert record["transmissions"] == 25
    assert_allclose(trace.transmission_times_s, 0.004 * np.arange(25), atol=1e-12)
    assert_allclose(record["min_interevent_s"], 0.004, rtol=1e-9)
    assert_allclose(record["mean_interevent_s"], 0.004, rtol=1e-9)
    assert_allclose(record["transmission_rate"], 0.25)
    # A second episode restarts the schedule (run_episode passes episode_start at the reset).
    second, _ = run_episode(env, make_trigger("periodic", env, every=4), seed=1)
    assert second["transmissions"] == 25


def test_periodic_counter_restarts_on_episode_start(env):
    policy = make_trigger("periodic", env, every=4)
    obs, _ = env.reset(seed=0)
    state = None
    decisions = []
    for _ in range(3):
        action, state = policy.predict(obs, state=state)
        decisions.append(int(action))
    assert decisions == [1, 0, 0]
    held, _ = policy.predict(obs, state=state, episode_start=np.zeros(1, dtype=bool))
    restarted, state = policy.predict(obs, state=state, episode_start=np.ones(1, dtype=bool))
    assert (held, restarted) == (0, 1)
    # Batched: only the environments whose episode starts restart their counters.
    batch = np.repeat(obs[None], 2, axis=0)
    _, counters = policy.predict(batch)
    _, counters = policy.predict(batch, state=counters)
    actions, _ = policy.predict(batch, state=counters, episode_start=np.array([True, False]))
    assert_array_equal(actions, [1, 0])


@pytest.mark.parametrize("every", [0, -4, 1.5])
def test_periodic_rejects_bad_period(env, every):
    with pytest.raises(ValueError, match="every"):
        make_trigger("periodic", env, every=every)


def switched_clock(env: gym.Env, **kwargs) -> SwitchedPeriodicPolicy:
    """A :class:`SwitchedPeriodicPolicy` for ``env``."""
    return SwitchedPeriodicPolicy(env.observation_space, env.action_space, **kwargs)


def decisions_of(policy, obs: np.ndarray, steps: int) -> list[int]:
    """``policy``'s decisions over ``steps`` instants of one episode (a fixed observation: the
    clocks do not read it)."""
    state, decisions = None, []
    for step in range(steps):
        start = np.array([step == 0])
        action, state = policy.predict(obs, state=state, episode_start=start)
        decisions.append(int(action))
    return decisions


def test_switched_clock_changes_its_period_at_switch_after(env):
    obs, _ = env.reset(seed=0)
    decisions = decisions_of(switched_clock(env, every=3, then_every=2, switch_after=7), obs, 13)
    # every 3 before instant 7 (0, 3, 6), then 2 instants after the last transmission (8, 10, 12)
    assert [step for step, sent in enumerate(decisions) if sent] == [0, 3, 6, 8, 10, 12]
    early = decisions_of(switched_clock(env, every=4, then_every=2, switch_after=100), obs, 40)
    late = decisions_of(switched_clock(env, every=4, then_every=3, switch_after=0), obs, 40)
    assert early == decisions_of(make_trigger("periodic", env, every=4), obs, 40)
    assert late == decisions_of(make_trigger("periodic", env, every=3), obs, 40)


def test_switched_clock_counts_in_an_episode_and_restarts(env):
    policy = switched_clock(env, every=10, then_every=5, switch_after=50)
    for seed in (0, 1):  # the second episode restarts both counters
        record, trace = run_episode(env, policy, seed=seed)
        assert record["transmissions"] == 5 + 10
        expected = np.concatenate([np.arange(0, 50, 10), np.arange(50, 100, 5)]) * 0.001
        assert_allclose(trace.transmission_times_s, expected, atol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"every": 0, "then_every": 2, "switch_after": 5}, "every"),
        ({"every": 2, "then_every": 1.5, "switch_after": 5}, "then_every"),
        ({"every": 2, "then_every": 2, "switch_after": -1}, "switch_after"),
        ({"every": True, "then_every": 2, "switch_after": 5}, "every"),
    ],
)
def test_switched_clock_rejects_bad_input(env, kwargs, name):
    with pytest.raises(ValueError, match=f"^{name} must be an integer"):
        switched_clock(env, **kwargs)


def test_evaluate_command_runs_a_switched_clock(capsys):
    arguments = ["every=10", "then_every=2", "switch_after=20"]
    policy = [word for argument in arguments for word in ("--policy-arg", argument)]
    short = ["--env-arg", "horizon_s=0.05"]
    result = evaluate_cli(capsys, ENV_ID, "--policy", "periodic", *policy, *short)
    assert result["episodes"][0]["transmissions"] == 2 + 15


# --------------------------------------------------------------------------- evaluate
def test_evaluate_returns_the_design_page_json():
    result = evaluate(ENV_ID, "paper", env_args={"horizon_s": 0.2}, episodes=2, seed=5)
    assert result["env"] == ENV_ID and result["policy"] == "paper"
    assert len(result["episodes"]) == 2
    for episode in result["episodes"]:
        assert set(episode) >= RECORD_KEYS
        assert episode["steps"] == 200 and episode["failure"] is None
        assert 0 < episode["transmissions"] < 200
        assert episode["wall_time_s"] > 0.0
        # The return is the sum of rewards with the default cost_scale 0.01 and penalty 0.1.
        expected = -episode["mean_cost"] * episode["steps"] / 0.01 - 0.1 * episode["transmissions"]
        assert_allclose(episode["return"], expected, rtol=1e-9)
    assert [e["seed"] for e in result["episodes"]] == [5, 6]
    assert_allclose(result["mean"]["E_v"], np.mean([e["E_v"] for e in result["episodes"]]))
    assert result["mean"]["failures"] == 0
    assert json.loads(json.dumps(to_jsonable(result))) == to_jsonable(result)


def test_evaluate_windows_split_each_episode_by_time():
    clock = {"policy_args": {"every": 10}, "env_args": {"horizon_s": 0.2}, "episodes": 2, "seed": 5}
    result = evaluate(ENV_ID, "periodic", **clock, windows_s=[0.0, 0.05, 0.2, 1.0])
    plain = evaluate(ENV_ID, "periodic", **clock)
    for episode, batch_episode in zip(result["episodes"], plain["episodes"], strict=True):
        # Splitting runs the episode one by one; it is the batch run's episode.
        assert episode["mean_cost"] == batch_episode["mean_cost"]
        split = episode["windows"]
        assert [(w["from_s"], w["to_s"]) for w in split] == [(0.0, 0.05), (0.05, 0.2), (0.2, 1.0)]
        # A clock every 10 ms sends at 0, 10, ..., 40 ms, then at 50, ..., 190 ms; nothing after
        # the 0.2-s horizon.
        assert [w["transmissions"] for w in split] == [5, 15, 0]
        assert split[2]["cost"] == 0.0
        assert_allclose(
            sum(w["cost"] for w in split), episode["mean_cost"] * episode["steps"], rtol=1e-12
        )
    # The first window's cost is the first 50 steps' summed info["cost"].
    env = gym.make(ENV_ID, horizon_s=0.2)
    env.reset(seed=5)
    first = sum(env.step(int(k % 10 == 0))[4]["cost"] for k in range(50))
    env.close()
    assert_allclose(result["episodes"][0]["windows"][0]["cost"], first, rtol=1e-12)
    means = result["windows"]
    assert_allclose(
        [w["cost"] for w in means],
        np.mean([[w["cost"] for w in e["windows"]] for e in result["episodes"]], axis=0),
    )
    assert json.loads(json.dumps(to_jsonable(result))) == to_jsonable(result)


@pytest.mark.parametrize("windows", [[1.0], [0.0, 0.0], [0.2, 0.1], [-1.0, 1.0], [0.0, np.inf]])
def test_evaluate_refuses_bad_windows(windows):
    with pytest.raises(ValueError, match=r"^windows_s must be"):
        evaluate(ENV_ID, "always", env_args={"horizon_s": 0.01}, windows_s=windows)


def test_evaluate_command_prints_the_windows(capsys):
    argv = [ENV_ID, "--policy", "always", "--env-arg", "horizon_s=0.01", "--windows", "0,0.004,1"]
    assert evaluate_module.main(argv) == 0
    out = capsys.readouterr().out
    assert "windows (means over the episodes):" in out
    assert "0-0.004 s  cost" in out and "transmissions 4" in out
    assert "0.004-1 s  cost" in out and "transmissions 6" in out


def test_evaluate_command_writes_json_to_stdout(capsys):
    result = evaluate_cli(
        capsys,
        ENV_ID,
        "--policy",
        "periodic",
        "--policy-arg",
        "every=10",
        "--env-arg",
        "horizon_s=0.05",
        "--episodes",
        "2",
    )
    assert result["env"] == ENV_ID and result["policy"] == "periodic"
    assert result["policy_args"] == {"every": 10}
    assert [e["transmissions"] for e in result["episodes"]] == [5, 5]
    assert set(result["episodes"][0]) >= RECORD_KEYS
    assert result["mean"]["transmissions"] == 5


def test_evaluate_command_writes_json_file(tmp_path, capsys):
    path = tmp_path / "out" / "always.json"
    argv = [ENV_ID, "--policy", "always", "--env-arg", "horizon_s=0.01", "--json", str(path)]
    assert evaluate_module.main(argv) == 0
    assert "transmissions" in capsys.readouterr().out  # the human summary
    assert json.loads(path.read_text())["episodes"][0]["transmissions"] == 10


SHORT = ["--env-arg", "horizon_s=0.01"]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--policy", "bogus", *SHORT], "policy must be one of paper"),
        (["--policy", "sb3:/nonexistent/model.zip", *SHORT], "not found"),
        (["--policy", "always", "--env-arg", "horizon_s"], "key=value"),
        (["--policy", "always", "--env-arg", "horizon=1"], "unknown argument"),
        (["--policy", "periodic", "--policy-arg", "every=0", *SHORT], "every"),
        (["--policy", "periodic", "--policy-arg", "then_every=2", *SHORT], "together"),
        (["--policy", "periodic", "--policy-arg", "phase=2", *SHORT], "then_every=K2"),
        (["--policy", "always", "--windows", "0.5,0.1", *SHORT], "argument --windows"),
        (["--policy", "always", "--windows", "0;1", *SHORT], "argument --windows"),
    ],
)
def test_evaluate_command_reports_bad_input(capsys, argv, message):
    assert_exits_with_usage_error(capsys, evaluate_module.main, [ENV_ID, *argv], message)


def test_evaluate_command_rejects_unknown_env_and_missing_policy(capsys):
    argv = ["etsc/NoSuchEnv-v0", "--policy", "always"]
    assert_exits_with_usage_error(capsys, evaluate_module.main, argv, "NoSuchEnv")
    assert_exits_with_usage_error(capsys, evaluate_module.main, [ENV_ID], "--policy")


def test_evaluate_function_errors():
    with pytest.raises(ValueError, match=r"^policy must be one of"):
        evaluate(ENV_ID, "bogus", env_args={"horizon_s": 0.01})
    with pytest.raises(ValueError, match="not found"):
        evaluate(ENV_ID, "sb3:/nonexistent/model.zip", env_args={"horizon_s": 0.01})
    with pytest.raises(ValueError, match="episodes"):
        evaluate(ENV_ID, "always", env_args={"horizon_s": 0.01}, episodes=0)


def test_reproduce_rejects_unknown_paper(capsys):
    assert_exits_with_usage_error(capsys, reproduce.main, ["--paper", "999"], "invalid choice")


# --------------------------------------------------------------------------- cli pieces
def test_parse_assignments_reads_yaml_values():
    parsed = parse_assignments(
        ["a=1", "b=true", "c=square", "d=0.5", "e=[1, 2]", "f=x=y", "g=3e-5"], "--env-arg"
    )
    expected = {"a": 1, "b": True, "c": "square", "d": 0.5, "e": [1, 2], "f": "x=y", "g": 3e-5}
    assert parsed == expected
    assert parse_assignments(None, "--env-arg") == {}


@pytest.mark.parametrize("pair", ["novalue", "=1"])
def test_parse_assignments_rejects_pairs_without_key_and_value(pair):
    with pytest.raises(ValueError, match="--env-arg"):
        parse_assignments([pair], "--env-arg")


def test_report_prints_paper_and_our_values():
    scenario = Scenario("event-triggered Psi=0.1", (("reference", "sinusoid"),), "paper")
    row = metric_row(scenario, {"E_v": 0.0122, "T_A_ms": 101.21}, {"E_v": 0.0125, "T_A_ms": None})
    assert_allclose(row["metrics"]["E_v"]["rel_diff"], 0.0125 / 0.0122 - 1.0)
    assert row["metrics"]["T_A_ms"]["rel_diff"] is None
    result = {
        "paper": "002",
        "title": "A tiny table",
        "env": ENV_ID,
        "tables": [{"name": "Table 1 - sinusoid", "rows": [row]}],
        "claims": [claim("a larger Psi transmits less", False, "47 vs 417")],
    }
    text = render(result)
    assert "Paper 002: A tiny table" in text and "Table 1 - sinusoid" in text
    lines = text.splitlines()
    first = next(i for i, line in enumerate(lines) if "event-triggered Psi=0.1" in line)
    e_v, t_a = lines[first].split(), lines[first + 1].split()
    assert e_v[-4:] == ["E_v", "0.0122", "0.0125", "+2.5%"]
    assert t_a == ["T_A_ms", "101.2", "-"]
    assert "[FAILS ] a larger Psi transmits less: 47 vs 417" in text


def test_report_fits_100_columns_however_long_its_labels_and_claims():
    scenario = Scenario("x" * 60, (), "paper")
    metrics = {f"metric_with_a_long_name_{i}": 1.0 + i for i in range(8)}
    row = metric_row(scenario, metrics, metrics)
    result = {
        "paper": "000",
        "title": "A long title " * 5,
        "env": ENV_ID,
        "tables": [{"name": "A table named at length " * 6, "rows": [row]}],
        "claims": [claim("a claim " * 20, True, "the evidence " * 20)],
        "figures": [f"figures/paper_000/figure_{i}.png" for i in range(12)],
    }
    lines = render(result).splitlines()
    assert max(len(line) for line in lines) <= 100
    assert sum("metric_with_a_long_name_" in line for line in lines) == 8
    assert sum(line.count("+0.0%") for line in lines) == 8


def test_each_finished_run_is_reported_on_standard_error_at_once(capsys):
    scenarios = [Scenario(label, (), "paper") for label in ("first", "second")]
    seen = [capsys.readouterr().err for _ in stages(scenarios, "paper 999")]
    seen.append(capsys.readouterr().err)
    assert seen[0] == ""  # nothing before the first run ends
    assert seen[1].startswith("paper 999: run 1/2 done (first)")
    assert seen[2].startswith("paper 999: run 2/2 done (second)")


# --------------------------------------------------------------------------- sb3
@pytest.mark.parametrize(
    ("algorithm_name", "kwargs"),
    [
        ("PPO", {"n_steps": 32, "batch_size": 32}),
        ("A2C", {"n_steps": 8}),
        ("DQN", {"learning_starts": 0, "buffer_size": 1000}),
    ],
)
def test_sb3_model_round_trip(tmp_path, algorithm_name, kwargs):
    sb3 = pytest.importorskip("stable_baselines3")
    algorithm = getattr(sb3, algorithm_name)
    env = gym.make(ENV_ID, horizon_s=0.05)
    model = algorithm("MlpPolicy", env, seed=0, device="cpu", **kwargs)
    model.learn(64)
    path = tmp_path / "model.zip"
    model.save(path)

    assert infer_sb3_algorithm(path) is algorithm
    loaded = load_sb3(path)
    assert isinstance(loaded, algorithm)
    batch = observation_batch(env, 8)
    expected = model.predict(batch, deterministic=True)[0]
    assert_array_equal(loaded.predict(batch, deterministic=True)[0], expected)

    result = evaluate(ENV_ID, f"sb3:{path}", env_args={"horizon_s": 0.05})
    episode = result["episodes"][0]
    assert episode["steps"] == 50 and episode["failure"] is None
    assert 0 <= episode["transmissions"] <= 50
    with pytest.raises(ValueError, match="policy-arg"):
        evaluate(ENV_ID, f"sb3:{path}", policy_args={"psi": 1}, env_args={"horizon_s": 0.05})


@pytest.mark.parametrize(
    ("env_id", "heartbeat"),
    [("etsc/AttitudeTracking-v0", 10), ("etsc/InnerFormation-v0", 25)],
)
def test_a_heartbeat_bounds_every_channel_gap_and_keeps_the_rule(env_id, heartbeat):
    """The paper's rule with a heartbeat transmits wherever the rule does, and no channel goes
    more than ``heartbeat`` instants without a transmission; the batch path equals the
    single-env path."""
    args = {"horizon_s": 0.3}
    thresholds = {"etsc/AttitudeTracking-v0": {"psi": 16.0}, "etsc/InnerFormation-v0": {}}
    policy_args = {**thresholds[env_id], "heartbeat": heartbeat}
    paired = evaluate(env_id, "paper", policy_args=policy_args, env_args=args, episodes=2)
    alone = evaluate(env_id, "paper", policy_args=thresholds[env_id], env_args=args, episodes=2)
    for with_beat, without in zip(paired["episodes"], alone["episodes"], strict=True):
        assert with_beat["transmissions"] > without["transmissions"]
    env = gym.make(env_id, **args)
    unwrapped = env.unwrapped
    rule = paper_of(env_id).trigger(
        env.observation_space, env.action_space, unwrapped.observation_names, **thresholds[env_id]
    )
    from etsc_envs.triggers.base import HeartbeatPolicy

    policy = HeartbeatPolicy(rule, heartbeat)
    obs, _ = env.reset(seed=0)
    state, sent_rows, done = None, [], False
    while not done:
        action, state = policy.predict(obs, state)
        fires, _ = rule.transmit(obs[None], None)
        assert np.all(np.asarray(action).reshape(-1) >= np.asarray(fires).reshape(-1))
        sent_rows.append(np.asarray(action).reshape(-1))
        obs, _, terminated, truncated, _ = env.step(action)
        done = terminated or truncated
    sent = np.array(sent_rows, dtype=bool)
    for channel in range(sent.shape[1]):
        instants = np.flatnonzero(sent[:, channel])
        assert instants[0] <= heartbeat and np.diff(instants).max() <= heartbeat
    assert paired["episodes"][0]["transmissions"] == sent.sum()
    with pytest.raises(ValueError, match="heartbeat must be an integer >= 1"):
        HeartbeatPolicy(rule, 0)
