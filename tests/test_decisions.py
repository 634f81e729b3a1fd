"""Self-triggered decisions: the training wrapper, its deployed transmit/hold policy, the
shield, and a short training run that reloads through ``sb3:`` (short horizons)."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import etsc_envs  # noqa: F401  (registers the ids)
from baselines.evaluate import evaluate
from etsc_envs.decisions import DecisionSet, SelfTriggeredPolicy
from etsc_envs.decisions.wrappers import interval_env
from etsc_envs.evaluation.episodes import run_episode
from etsc_envs.evaluation.policy_specs import make_policy
from etsc_envs.papers import paper_of
from etsc_envs.sb3_models import load_sb3, takes_action_masks
from etsc_envs.triggers import PeriodicPolicy
from etsc_envs.triggers.asteroid import AsteroidShield
from etsc_envs.triggers.inner_formation import InnerFormationShield, default_error_time_thresholds
from tests.rule_sets import (
    BASE_CONFIG,
    caps_of,
    deployed_policy,
    factors_of,
    rule_block,
    rule_set,
    rule_wrapper,
)

ATTITUDE = "etsc/AttitudeTracking-v0"
FORMATION = "etsc/InnerFormation-v0"
ASTEROID = "etsc/AsteroidOrbitKeeping-v0"
HORIZON_S = 0.4
SEED = 3


class RecordedActions(gym.Wrapper):
    """Keeps every transmit/hold action the env is stepped with."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.actions: list[np.ndarray] = []

    def step(self, action):
        self.actions.append(np.asarray(action).copy())
        return self.env.step(action)


class ScriptedModel:
    """A stand-in for a trained model: an action that varies with the observation."""

    def __init__(self, n_actions: int, fixed: int | None = None) -> None:
        self.n_actions = n_actions
        self.fixed = fixed

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation)
        if self.fixed is not None:
            return np.full(len(obs), self.fixed), None
        digits = np.abs(obs).sum(axis=1) * 1e4
        return (digits.astype(np.int64) % self.n_actions), None


def recorded(env_id: str) -> RecordedActions:
    return RecordedActions(gym.make(env_id, horizon_s=HORIZON_S))


def wrapper_actions(env_id: str, model, **kwargs) -> tuple[list[np.ndarray], list[dict]]:
    """Transmit/hold actions of one seeded episode of the wrapper driven by ``model``, and the
    infos of its decisions."""
    base = recorded(env_id)
    wrapper = rule_wrapper(base, **kwargs)
    obs, _ = wrapper.reset(seed=SEED)
    infos, done = [], False
    while not done:
        action, _ = model.predict(obs[None])
        obs, _, terminated, truncated, info = wrapper.step(action[0])
        infos.append(info)
        done = terminated or truncated
    return base.actions, infos


def policy_actions(env_id: str, policy) -> list[np.ndarray]:
    """Transmit/hold actions of one seeded episode of ``policy`` on the plain env."""
    base = recorded(env_id)
    run_episode(base, policy, SEED)
    return base.actions


def paper_policy(env_id: str):
    env = gym.make(env_id, horizon_s=HORIZON_S)
    unwrapped = env.unwrapped
    return paper_of(env_id).trigger(
        env.observation_space, env.action_space, unwrapped.observation_names
    )


def deployed(env_id: str, model, **kwargs) -> SelfTriggeredPolicy:
    wrapper = rule_wrapper(gym.make(env_id, horizon_s=HORIZON_S), **kwargs)
    env = wrapper.env
    return deployed_policy(model, wrapper, env)


def assert_same(first: list[np.ndarray], second: list[np.ndarray]) -> None:
    assert len(first) == len(second)
    np.testing.assert_array_equal(np.array(first), np.array(second))


@pytest.mark.parametrize("env_id", [ATTITUDE, FORMATION])
def test_follow_the_paper_is_the_paper_trigger(env_id):
    decisions = rule_set(env_id, max_exponent=3)
    follow = len(decisions.hold_indices) + factors_of(decisions).index(1.0)
    actions, _ = wrapper_actions(env_id, ScriptedModel(0, fixed=follow), max_exponent=3)
    paper = policy_actions(env_id, paper_policy(env_id))
    assert np.array(paper).any()
    assert_same(actions, paper)


def test_hold_is_the_clock():
    env = gym.make(ATTITUDE, horizon_s=HORIZON_S)
    clock = PeriodicPolicy(env.observation_space, env.action_space, every=8)
    actions, infos = wrapper_actions(ATTITUDE, ScriptedModel(0, fixed=3), max_exponent=3)
    assert_same(actions, policy_actions(ATTITUDE, clock))
    assert {info["elapsed_steps"] for info in infos[:-1]} == {8}


@pytest.mark.parametrize(("env_id", "shield"), [(ATTITUDE, None), (FORMATION, 0.5)])
def test_deployed_policy_takes_the_training_decisions(env_id, shield):
    kwargs = {"max_exponent": 4, "shield_multiple": shield}
    model = ScriptedModel(rule_set(env_id, max_exponent=4).action_space.n)
    actions, infos = wrapper_actions(env_id, model, **kwargs)
    assert len({info["action"] for info in infos}) > 3
    assert_same(actions, policy_actions(env_id, deployed(env_id, model, **kwargs)))


def called_actions(env_id: str, policy, call, episodes: int = 2) -> list[np.ndarray]:
    """Transmit/hold actions of ``episodes`` seeded episodes in a row of ``policy`` on the
    plain env, each instant's action ``call(policy, obs, state, first)`` (``state``: the
    previous call's, ``None`` at an episode's first instant; ``first``: whether it is)."""
    env, actions = gym.make(env_id, horizon_s=HORIZON_S), []
    for episode in range(episodes):
        obs, _ = env.reset(seed=SEED + episode)
        state, first, done = None, True, False
        while not done:
            action, state = call(policy, obs, state, first)
            actions.append(np.asarray(action).copy())
            obs, _, terminated, truncated, _ = env.step(action)
            first, done = False, terminated or truncated
    return actions


@pytest.mark.parametrize(("env_id", "shield"), [(ATTITUDE, None), (FORMATION, 0.5)])
def test_calls_without_state_take_the_actions_of_calls_passing_it_back(env_id, shield):
    kwargs = {"max_exponent": 4, "shield_multiple": shield}
    model = ScriptedModel(rule_set(env_id, max_exponent=4).action_space.n)
    policy = deployed(env_id, model, **kwargs)
    stateful = called_actions(env_id, policy, lambda p, o, s, _: p.predict(o, state=s))
    stateless = called_actions(env_id, policy, lambda p, o, s, _: p.predict(o))
    assert_same(stateless, stateful)
    # Deciding afresh at every instant takes other actions: the state carried matters.
    afresh = called_actions(env_id, policy, lambda p, o, s, _: p.predict(o, episode_start=[1]))
    assert not np.array_equal(np.array(afresh), np.array(stateful))


def test_a_call_without_state_on_an_observation_that_does_not_follow_decides_afresh():
    hold_8 = rule_set(ATTITUDE, max_exponent=3).action("hold 8")
    policy = deployed(ATTITUDE, ScriptedModel(0, fixed=hold_8), max_exponent=3)
    env = gym.make(ATTITUDE, horizon_s=HORIZON_S)
    obs, _ = env.reset(seed=SEED)
    other = obs.copy()
    for _ in range(3):
        obs = env.step(policy.predict(obs)[0])[0]
    assert policy.predict(obs)[1].tolist() == [[hold_8, 4]]  # continues the hold
    assert policy.predict(other)[1].tolist() == [[hold_8, 1]]  # a reset's: starts one
    assert policy.predict(obs)[1].tolist() == [[hold_8, 1]]  # not one period on: starts one
    two_rows = np.stack([obs, obs])
    assert policy.predict(two_rows)[1].tolist() == [[hold_8, 1]] * 2  # other rows: starts


def decision_episode(env: gym.Env, model, **kwargs) -> list[tuple]:
    """Every decision's result of one seeded episode of the wrapper over ``env``."""
    wrapper = rule_wrapper(env, **kwargs)
    obs, _ = wrapper.reset(seed=SEED)
    results, done = [], False
    while not done:
        action, _ = model.predict(obs[None])
        result = wrapper.step(action[0])
        obs, done = result[0], result[2] or result[3]
        results.append(result)
    return results


@pytest.mark.parametrize(("env_id", "shield"), [(ATTITUDE, None), (FORMATION, 0.5)])
def test_compiled_holds_equal_the_per_instant_path(env_id, shield):
    """Under gym.make's own wrappers the holds run in compiled intervals; under any other
    wrapper (here the recorder) every instant is an env.step; both give the same episode."""
    kwargs = {"max_exponent": 5, "shield_multiple": shield}
    model = ScriptedModel(rule_set(env_id, max_exponent=5).action_space.n)
    plain, recorder = gym.make(env_id, horizon_s=HORIZON_S), recorded(env_id)
    assert interval_env(plain) is plain.unwrapped and interval_env(recorder) is None
    compiled = decision_episode(plain, model, **kwargs)
    stepwise = decision_episode(recorder, model, **kwargs)
    assert len(compiled) == len(stepwise) > 10
    assert len({info["action"] for *_, info in compiled}) > 3
    for got, expected in zip(compiled, stepwise, strict=True):
        np.testing.assert_array_equal(got[0], expected[0])
        np.testing.assert_equal(list(got[1:]), list(expected[1:]))


@pytest.mark.parametrize(("factors", "cap"), [((64.0,), 5), ((64.0,), 24), ((64.0, 64.0), [5, 24])])
def test_a_cap_ends_follow_the_paper_intervals(factors, cap):
    """With ``cap`` (one, or one per factor) a "follow the paper" interval lasts at most
    its factor's cap, in the compiled path and instant by instant alike, and the deployed
    policy takes the same transmit/hold actions."""
    kwargs = {"max_exponent": 3, "factors": factors, "cap": cap}
    decisions = rule_set(ATTITUDE, **kwargs)
    caps = tuple(cap) if isinstance(cap, list) else (cap,) * len(factors)
    assert caps_of(decisions) == caps
    for index, cap in enumerate(caps):
        follow = ScriptedModel(0, fixed=len(decisions.hold_indices) + index)
        compiled = decision_episode(gym.make(ATTITUDE, horizon_s=HORIZON_S), follow, **kwargs)
        actions, infos = wrapper_actions(ATTITUDE, follow, **kwargs)
        elapsed = [info["elapsed_steps"] for info in infos[:-1]]
        assert max(elapsed) == cap
        assert [result[4]["elapsed_steps"] for result in compiled[:-1]] == elapsed
        assert_same(actions, policy_actions(ATTITUDE, deployed(ATTITUDE, follow, **kwargs)))


@pytest.mark.parametrize(
    ("env_id", "factor", "heartbeat"), [(ATTITUDE, 16.0, 12), (ATTITUDE, 2.0, 40)]
)
def test_the_heartbeat_action_is_the_rule_paired_with_a_heartbeat(env_id, factor, heartbeat):
    """Always choosing "paper x f, heartbeat H" (``send_first``) takes the transmit/hold
    actions of :class:`HeartbeatPolicy` over the rule at f, in the compiled path, instant by
    instant and deployed alike; no gap between transmissions exceeds H instants."""
    from etsc_envs.triggers.base import HeartbeatPolicy

    kwargs = {"max_exponent": 3, "factors": (factor,), "cap": heartbeat}
    decisions = rule_set(env_id, **kwargs, send_first=True)
    assert (
        decisions.label(len(decisions.hold_indices)) == f"paper x{factor:g}, heartbeat {heartbeat}"
    )
    follow = ScriptedModel(0, fixed=len(decisions.hold_indices))
    kwargs["send_first"] = True
    actions, infos = wrapper_actions(env_id, follow, **kwargs)
    compiled = decision_episode(gym.make(env_id, horizon_s=HORIZON_S), follow, **kwargs)
    assert [result[4]["elapsed_steps"] for result in compiled] == [
        info["elapsed_steps"] for info in infos
    ]
    env = gym.make(env_id, horizon_s=HORIZON_S)
    rule = paper_of(env_id).trigger(
        env.observation_space,
        env.action_space,
        env.unwrapped.observation_names,
        **{name: factor * value for name, value in paper_of(env_id).rule.thresholds().items()},
    )
    paired = policy_actions(env_id, HeartbeatPolicy(rule, heartbeat))
    assert_same(actions, paired)
    assert_same(policy_actions(env_id, deployed(env_id, follow, **kwargs)), paired)
    sent = np.flatnonzero(np.array(actions).reshape(len(actions), -1).any(axis=1))
    assert sent[0] == 0 and np.diff(sent).max() <= heartbeat
    assert len(sent) > len(actions) / heartbeat  # the rule fires between beats too


def test_a_heartbeat_per_factor_pairs_each_factor_with_its_own():
    """With ``send_first`` and ``cap`` a list, always choosing a rule action takes the
    actions of :class:`HeartbeatPolicy` over the rule at its factor with its factor's heartbeat,
    and the labels name each pair; the set round-trips through its file."""
    from etsc_envs.triggers.base import HeartbeatPolicy

    kwargs = {"max_exponent": 3, "factors": (16.0, 2.0), "cap": [12, 40]}
    decisions = rule_set(ATTITUDE, **kwargs, send_first=True)
    labels = [decisions.label(len(decisions.hold_indices) + index) for index in range(2)]
    assert labels == ["paper x16, heartbeat 12", "paper x2, heartbeat 40"]
    env = gym.make(ATTITUDE, horizon_s=HORIZON_S)
    for index, (factor, heartbeat) in enumerate(
        zip(factors_of(decisions), caps_of(decisions), strict=True)
    ):
        follow = ScriptedModel(0, fixed=len(decisions.hold_indices) + index)
        actions, _ = wrapper_actions(ATTITUDE, follow, **kwargs, send_first=True)
        rule = paper_of(ATTITUDE).trigger(
            env.observation_space,
            env.action_space,
            env.unwrapped.observation_names,
            **{
                name: factor * value for name, value in paper_of(ATTITUDE).rule.thresholds().items()
            },
        )
        assert_same(actions, policy_actions(ATTITUDE, HeartbeatPolicy(rule, heartbeat)))


def test_caps_per_action_round_trip(tmp_path):
    decisions = rule_set(ATTITUDE, factors=(1.0, 2.0), cap=[12, 40], send_first=True)
    decisions.save(tmp_path / "model.zip")
    loaded = DecisionSet.load(tmp_path / "model.zip")
    assert loaded == decisions and caps_of(loaded) == (12, 40)


def test_a_time_limit_sees_every_instant_of_a_hold():
    env = gym.make(ATTITUDE, horizon_s=HORIZON_S, max_episode_steps=50)
    assert interval_env(env) is None
    wrapper = rule_wrapper(env, max_exponent=6)
    wrapper.reset(seed=SEED)
    _, _, terminated, truncated, info = wrapper.step(6)  # hold 64
    assert truncated and not terminated and info["elapsed_steps"] == 50
    assert "episode_metrics" not in info  # the time limit, not the env's horizon, cut it


@pytest.mark.parametrize(
    ("env_id", "make_kwargs"), [(FORMATION, {}), (ASTEROID, {"horizon_s": 3000.0})]
)
def test_shield_lets_no_forbidden_hold_through(env_id, make_kwargs):
    kwargs = {"max_exponent": 10, "shield_multiple": 0.5}
    n_actions = rule_set(env_id, max_exponent=10).action_space.n
    base = RecordedActions(gym.make(env_id, **{"horizon_s": HORIZON_S, **make_kwargs}))
    wrapper = rule_wrapper(base, **kwargs)
    wrapper.reset(seed=SEED)
    longest_hold, largest_factor = 10, n_actions - 1
    replaced, decisions, done = 0, 0, False
    while not done:
        mask = wrapper.action_masks()
        assert mask[0]
        given = (largest_factor, longest_hold)[decisions % 2]
        decisions += 1
        _, _, terminated, truncated, info = wrapper.step(given)
        assert mask[info["action"]]
        replaced += info["shielded"]
        done = terminated or truncated
    assert replaced > 0


def test_shield_forbids_holds_that_outrun_the_threshold():
    env = gym.make(FORMATION)
    names = env.unwrapped.observation_names
    shield = InnerFormationShield(names, 0.001, multiple=2.0, thresholds=np.full(3, 0.01))
    obs = np.zeros((2, len(names)))
    obs[1, names.index("velocity_estimate_mps_y")] = 1.0  # 1 m/s: 2 Π = 0.02 m in 20 ms
    allowed = shield.allowed_holds(obs, np.array([1, 16, 32]))
    np.testing.assert_array_equal(allowed, [[True, True, True], [True, True, False]])
    np.testing.assert_array_equal(shield.allowed_factors(np.array([1.0, 2.0, 4.0])), [1, 1, 0])


def test_asteroid_shield_forbids_holds_that_leave_the_shell():
    env = gym.make(ASTEROID)
    names = env.unwrapped.observation_names
    shield = AsteroidShield(names, 0.25, multiple=1.0)
    obs = np.zeros((3, len(names)))
    obs[:, names.index("radius_m")] = (200.0, 203.0, 197.0)
    obs[:, names.index("radial_velocity_mps")] = (0.0, 0.1, -0.1)  # 2 m in 20 s = 80 instants
    allowed = shield.allowed_holds(obs, np.array([1, 64, 128]))
    np.testing.assert_array_equal(
        allowed, [[True, True, True], [True, True, False], [True, True, False]]
    )
    np.testing.assert_array_equal(shield.allowed_factors(np.array([0.0625, 4.0])), [1, 1])


# the wrapper is what is checked: Gymnasium's advice to check the unwrapped env does not apply
@pytest.mark.filterwarnings("ignore:.*is different from the unwrapped version")
def test_wrapper_passes_gymnasium_check_env():
    env = rule_wrapper(gym.make(FORMATION, horizon_s=0.05), max_exponent=3)
    check_env(env, skip_render_check=True)


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"factors": (1.0, -2.0)}, r"factors\.pi must be a finite number > 0"),
        ({"cap": 0}, "cap must be an integer"),
        ({"gamma": 0.0}, "gamma"),
    ],
)
def test_bad_arguments_name_themselves(kwargs, argument):
    with pytest.raises(ValueError, match=argument):
        rule_wrapper(gym.make(FORMATION, horizon_s=0.05), **kwargs)


def test_factors_outside_the_trigger_range_name_themselves():
    env = gym.make("etsc/ClusterContainmentCentral-v0", horizon_s=0.05)
    with pytest.raises(ValueError, match=r"actions\[\d+\]: key 'factors\.c' must lie in"):
        rule_wrapper(env, factors=(1.0, 2.0))


def test_an_unreadable_decision_set_names_its_file(tmp_path):
    (tmp_path / "model_decisions.json").write_text("{not json")
    with pytest.raises(ValueError, match=r"model_decisions\.json"):
        DecisionSet.load(tmp_path / "model.zip")


def test_shield_only_where_the_paper_gives_one():
    with pytest.raises(ValueError, match="shield_multiple"):
        rule_set(ATTITUDE, shield_multiple=2.0)


@pytest.mark.parametrize("algorithm", ["MaskablePPO", "PPO"])
def test_short_training_saves_reloads_and_evaluates(tmp_path, algorithm):
    import sb3_contrib
    import stable_baselines3

    kwargs = {"max_exponent": 3, "shield_multiple": 2.0}
    wrapper = rule_wrapper(gym.make(FORMATION, horizon_s=0.1), **kwargs)
    module = sb3_contrib if algorithm == "MaskablePPO" else stable_baselines3
    model = getattr(module, algorithm)(
        "MlpPolicy", wrapper, n_steps=32, batch_size=32, n_epochs=1, device="cpu", seed=0
    )
    model.learn(total_timesteps=64)
    path = tmp_path / "model.zip"
    model.save(path)
    wrapper.decisions.save(path)

    env = gym.make(FORMATION, horizon_s=0.1)
    policy = make_policy(f"sb3:{path}", env, {}, FORMATION)
    assert isinstance(policy, SelfTriggeredPolicy)
    assert takes_action_masks(policy.model) == (algorithm == "MaskablePPO")
    env_args = {"horizon_s": 0.1}
    batch = evaluate(FORMATION, f"sb3:{path}", env_args=env_args, episodes=2, seed=SEED)
    for record in batch["episodes"]:
        single = evaluate(FORMATION, f"sb3:{path}", env_args=env_args, seed=record["seed"])
        assert record["transmissions"] == single["episodes"][0]["transmissions"] > 0
        assert record["mean_cost"] == pytest.approx(single["episodes"][0]["mean_cost"])


def test_agents_train_takes_decisions_and_saves_deployable_models(tmp_path):
    import yaml

    from agents.train.training import main

    out_dir = tmp_path / "run"
    config = {
        "env_id": FORMATION,
        "env_kwargs": {"horizon_s": 0.1},
        "algorithm": "MaskablePPO",
        "policy": "MlpPolicy",
        "hyperparameters": {"n_steps": 32, "batch_size": 32, "n_epochs": 1, "gamma": 0.999},
        "total_timesteps": 64,
        "out_dir": str(out_dir),
        "decisions": rule_block(FORMATION, max_exponent=3, shield_multiple=2.0),
        "evaluation_every": 32,
        "evaluation_scenarios": 2,
        "evaluation_env_kwargs": {"horizon_s": 0.1},
        "checkpoint_every": 32,
        "tensorboard": False,
    }
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config), encoding="utf-8")
    assert main(["--config", str(path)]) == 0
    for name in ("model", "best_model", "checkpoints/model_32_steps"):
        assert DecisionSet.load(out_dir / f"{name}.zip").shield_multiple == 2.0
    assert takes_action_masks(load_sb3(out_dir / "model.zip"))  # normalised MaskablePPO
    evaluations = json.loads((out_dir / "evaluations.json").read_text(encoding="utf-8"))
    # a decision lasts one instant or more: the instants simulated outrun the decisions
    assert [entry["timesteps"] for entry in evaluations] == [32, 64]
    assert all(entry["env_steps"] > entry["timesteps"] for entry in evaluations)
    result = evaluate(FORMATION, f"sb3:{out_dir / 'model.zip'}", env_args={"horizon_s": 0.1})
    assert result["episodes"][0]["transmissions"] > 0


def test_agents_train_runs_dqn_on_decisions_and_resumes(tmp_path):
    """DQN takes self-triggered decisions with the semi-Markov target (its replay buffer
    discounts by elapsed instants), saves a deployable model, and resumes from a checkpoint."""
    import yaml

    from agents.train.config import load_config
    from agents.train.elapsed_discount import ElapsedReplayBuffer
    from agents.train.training import _build_model, main, make_training_env

    hyperparameters = {"learning_starts": 8, "batch_size": 8, "buffer_size": 256, "gamma": 0.999}
    out_dir = train_short(
        tmp_path,
        env_id=FORMATION,
        env_kwargs={"horizon_s": 0.1},
        algorithm="DQN",
        hyperparameters=hyperparameters,
        decisions=rule_block(FORMATION, max_exponent=3),
        checkpoint_every=16,
    )
    path = tmp_path / "config.yaml"
    loaded = load_config(path)
    model = _build_model(loaded, make_training_env(loaded, None), None, out_dir)
    assert isinstance(model.replay_buffer, ElapsedReplayBuffer)
    assert model.replay_buffer.gamma == 0.999
    deployed = make_policy(f"sb3:{out_dir / 'model.zip'}", gym.make(FORMATION), {}, FORMATION)
    assert isinstance(deployed, SelfTriggeredPolicy)
    result = evaluate(FORMATION, f"sb3:{out_dir / 'model.zip'}", env_args={"horizon_s": 0.1})
    assert len(result["episodes"]) == 1
    config = yaml.safe_load(path.read_text(encoding="utf-8"))
    path.write_text(yaml.safe_dump({**config, "total_timesteps": 48}), encoding="utf-8")
    assert main(["--config", str(path), "--resume"]) == 0
    summary = json.loads((out_dir / "train_summary.json").read_text(encoding="utf-8"))
    assert summary["resumed_from"] is not None


HOLD_1 = {"actions": [{"kind": "hold", "instants": 1}]}
"""A config's decisions block of one action, "hold 1"."""
ERROR_TIME = {"kind": "trigger", "rule": "error_time"}
"""The error-time rule's action (paper 004's rule only)."""


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"algorithm": "MaskablePPO"}, "MaskablePPO needs the key 'decisions'"),
        (
            {"decisions": {"max_exponent": 3, "factors": [1.0]}},
            r"'decisions' must be the decision set's own form .* \['factors', 'max_exponent'\]",
        ),
        (
            {"decisions": {"actions": [{"kind": "hold", "instants": 0}]}},
            r"config key 'decisions': actions\[0\]: hold instants must be an integer",
        ),
        ({"decisions": {**HOLD_1, "shield_multiple": 2.0}, "env_id": ATTITUDE}, "shield_multiple"),
        (
            {"decisions": {"actions": [ERROR_TIME]}, "env_id": ATTITUDE},
            r"actions\[0\]: env_id must be one of .* for rule 'error_time'",
        ),
        (
            {"decisions": {"actions": [{"kind": "trigger", "keywords": {"b1": 1.0}}]}},
            r"config key 'decisions': actions\[0\]: .* got unknown \['keywords'\]",
        ),
        ({"decisions": HOLD_1, "start_from": {"steps": 64}}, "config key 'start_from' was removed"),
        ({"imitation_steps": 8}, r"unknown config key\(s\) \['imitation_steps'\]"),
    ],
)
def test_training_config_checks_the_decisions(tmp_path, changes, message):
    from agents.train.config import config_from_dict

    plain = {key: value for key, value in BASE_CONFIG.items() if key != "decisions"}
    config = plain | {"env_id": FORMATION, "env_kwargs": {"horizon_s": 0.1}}
    config["out_dir"] = str(tmp_path / "run")
    with pytest.raises(ValueError, match=message):
        config_from_dict({**config, **changes})


def train_short(tmp_path, **keys) -> Path:
    """``agents.train`` on a short self-triggered config, 32 steps of PPO from scratch (2 envs),
    with ``keys`` replaced; the run's folder."""
    import yaml

    from agents.train.training import main

    out_dir = tmp_path / "run"
    config = {
        "algorithm": "PPO",
        "policy": "MlpPolicy",
        "hyperparameters": {"n_steps": 32, "batch_size": 32, "n_epochs": 1, "gamma": 0.999},
        "total_timesteps": 32,
        "n_envs": 2,
        "out_dir": str(out_dir),
        "tensorboard": False,
        **keys,
    }
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config), encoding="utf-8")
    assert main(["--config", str(path)]) == 0
    return out_dir


def test_the_rule_with_a_heartbeat_trains_and_deploys(tmp_path):
    """A short run on a set with "paper x8, heartbeat 12" (a cap of 12 instants, sent first)
    completes, and its saved model deploys through ``sb3:`` with the heartbeat in its decision
    set: no gap between transmissions exceeds the longest hold or the heartbeat."""
    out_dir = train_short(
        tmp_path,
        env_id=ATTITUDE,
        env_kwargs={"horizon_s": 0.3},
        decisions=rule_block(ATTITUDE, max_exponent=3, factors=[8.0], cap=12, send_first=True),
    )
    decisions = DecisionSet.load(out_dir / "model.zip")
    triggers = [decisions.actions[i] for i in decisions.trigger_indices]
    assert caps_of(decisions) == (12,) and all(action.send_first for action in triggers)
    assert decisions.labels[-1] == "paper x8, heartbeat 12"
    deployed = RecordedActions(gym.make(ATTITUDE, horizon_s=0.1))
    env = gym.make(ATTITUDE, horizon_s=0.1)
    run_episode(deployed, make_policy(f"sb3:{out_dir / 'model.zip'}", env, {}, ATTITUDE), SEED)
    sent = np.flatnonzero(np.array(deployed.actions).reshape(len(deployed.actions), -1).any(1))
    assert len(deployed.actions) == 100 and sent[0] == 0 and np.diff(sent).max() <= 12


def test_the_error_time_rule_trains_and_deploys(tmp_path):
    """A short 004 run on a set whose only rule action is "error_time x2" saves a model whose
    deployed policy, through ``sb3:``, takes the error-time rule's actions at twice its default
    thresholds when its decision set holds that rule alone."""
    out_dir = train_short(
        tmp_path,
        env_id=FORMATION,
        env_kwargs={"horizon_s": 0.3},
        decisions=rule_block(FORMATION, holds=[], rule="error_time", factors=[2.0]),
    )
    loaded = DecisionSet.load(out_dir / "model.zip")
    assert {loaded.actions[i].rule for i in loaded.trigger_indices} == {"error_time"}
    env = gym.make(FORMATION, horizon_s=0.3)
    learned = RecordedActions(gym.make(FORMATION, horizon_s=0.3))
    run_episode(learned, make_policy(f"sb3:{out_dir / 'model.zip'}", env, {}, FORMATION), SEED)
    rule = RecordedActions(gym.make(FORMATION, horizon_s=0.3))
    doubled = {
        f"area{axis + 1}": 2 * area for axis, area in enumerate(default_error_time_thresholds())
    }
    run_episode(rule, make_policy("error_time", env, doubled, FORMATION), SEED)
    assert np.array(rule.actions).any()
    assert_same(learned.actions, rule.actions)


def test_the_decentralised_cluster_trains_and_deploys(tmp_path):
    """A PettingZoo id takes self-triggered decisions one follower at a time
    (:class:`etsc_envs.decisions.FollowerDecisionEnv`): a short run completes, its teammates
    act as the model, and the saved model deploys through ``sb3:`` on every follower of the
    PettingZoo env — with one action, "paper x1.5", as the rule at 1.5 c does."""
    cluster = "etsc/ClusterContainment-v0"
    out_dir = train_short(
        tmp_path,
        env_id=cluster,
        env_kwargs={"horizon_s": 2.0},
        decisions=rule_block(cluster, holds=[], factors=[1.5]),
    )
    assert DecisionSet.load(out_dir / "model.zip").env_id == cluster
    env_args = {"horizon_s": 20.0}
    learned = evaluate(cluster, f"sb3:{out_dir / 'model.zip'}", env_args=env_args, seed=SEED)
    rule = evaluate(cluster, "paper", policy_args={"c": 0.9}, env_args=env_args, seed=SEED)
    learned, rule = learned["episodes"][0], rule["episodes"][0]
    assert learned["transmissions"] == rule["transmissions"] > 0
    assert learned["mean_cost"] == rule["mean_cost"]
    for agent, record in rule["agents"].items():
        assert learned["agents"][agent]["transmissions"] == record["transmissions"]
